//! Cheap single-DoF durations for planners (SPEC.md §5): no trajectory,
//! no synchronisation.

use crate::block::Block;
use crate::calculator::{DofCase, step1_dof};
use crate::candidates::Valid;
use crate::error::OtgError;
use crate::input::{ControlInterface, Input};
use crate::limits::DofLimits;
use crate::profile::Profile;

/// Time-optimal duration of a rest-to-rest motion over `distance` under
/// symmetric limits `v_max`, `a_max`, `j_max` (closed form; all > 0).
///
/// The profile accelerates to a peak velocity `v ≤ v_max` (with an
/// acceleration plateau iff `v > a_max²/j_max`), cruises, and mirrors.
pub fn rest_to_rest_duration(distance: f64, v_max: f64, a_max: f64, j_max: f64) -> f64 {
    let d = distance.abs();
    if d == 0.0 {
        return 0.0;
    }
    // Time and distance to reach velocity v from rest (and back to rest).
    let ramp = |v: f64| -> f64 {
        if v * j_max > a_max * a_max {
            v / a_max + a_max / j_max
        } else {
            2.0 * (v / j_max).sqrt()
        }
    };
    let t_v = ramp(v_max);
    let d_v = v_max * t_v; // accelerate + decelerate
    if d >= d_v {
        return 2.0 * t_v + (d - d_v) / v_max;
    }
    // No cruise: peak velocity below v_max.
    let v_tri = (d * d * j_max / 4.0).cbrt();
    if v_tri * j_max <= a_max * a_max {
        return 4.0 * (v_tri / j_max).sqrt();
    }
    let k = a_max * a_max / j_max;
    let v = (-k + (k * k + 4.0 * a_max * d).sqrt()) / 2.0;
    2.0 * (v / a_max + a_max / j_max)
}

/// Time-optimal duration of one DoF from `(p0, v0, a0)` to `(pf, vf, af)`
/// under `limits` (position interface, brake included), without building a
/// trajectory. The state may lie outside the limits; the target must not.
pub fn min_duration(
    p0: f64,
    v0: f64,
    a0: f64,
    pf: f64,
    vf: f64,
    af: f64,
    limits: &DofLimits,
) -> Result<f64, OtgError> {
    let mut inp = Input::<1>::new([limits.v_max], [limits.a_max], [limits.j_max]);
    inp.min_velocity = Some([limits.v_min]);
    inp.min_acceleration = Some([limits.a_min]);
    inp.current_position = [p0];
    inp.current_velocity = [v0];
    inp.current_acceleration = [a0];
    inp.target_position = [pf];
    inp.target_velocity = [vf];
    inp.target_acceleration = [af];
    inp.validate(false)?;
    let case = DofCase {
        p0,
        v0,
        a0,
        pf,
        vf,
        af,
    };
    let mut profile = Profile::default();
    let mut block = Block::default();
    if step1_dof(
        ControlInterface::Position,
        &case,
        limits,
        &mut profile,
        &mut block,
        &mut Valid::new(&Profile::default()),
    ) {
        Ok(block.t_min)
    } else {
        Err(OtgError::ExecutionTimeCalculation { dof: 0 })
    }
}

//! Execution-time model of the plan's motions (SPEC §4.3: "the plan's cost is
//! its execution time under the motion limits").
//!
//! Every primitive is executed as a rest-to-rest, jerk-limited, time-optimal
//! motion of one path parameter (SPEC §5), so its duration is the classic
//! closed form for a symmetric third-order profile.

use otg::{Input, Otg, Trajectory};

use super::plan::{MAX_DOFS, Step, StepLimit};
use crate::config::{HandConfig, LimitsConfig, MotionLimit};

/// Duration of the time-optimal rest-to-rest motion over `distance` under
/// one motion limit: the trajectory generator's closed form (SPEC §5), so
/// the planner's costs are the executor's durations.
pub fn rest_to_rest(distance: f64, lim: &MotionLimit) -> f64 {
    otg::rest_to_rest_duration(distance, lim.velocity, lim.acceleration, lim.jerk)
}

/// The durations the planner needs, for one configuration.
#[derive(Debug, Clone, Copy)]
pub struct DurationModel {
    /// Object rotation limits.
    pub object: MotionLimit,
    /// Fingertip translation limits.
    pub fingertip: MotionLimit,
    /// Rolling limits (fingertip angular velocity relative to the object).
    pub rolling: MotionLimit,
    /// Duration of a vertical lift or descent over the transfer height.
    pub vertical: f64,
    /// Duration of a handover (`load.handover_time`): each placement and
    /// each lift waits that long for the grip to pass.
    pub handover: f64,
    transfer_radius: f64,
    /// `transfer` tabulated over u = sin(angle/2) = √((1 − cos)/2), in
    /// which it is smooth (the cosine itself is flat near 0 and π).
    by_half_sine: [f64; TABLE + 1],
}

/// Intervals of the transfer-time table over u ∈ [0, 1].
const TABLE: usize = 1024;

impl DurationModel {
    /// From the configuration.
    pub fn new(config: &HandConfig) -> Self {
        let l = &config.limits;
        let r = config.model.object_radius + config.model.fingertip_radius;
        let transfer_radius = r + config.planner.transfer_height;
        let by_half_sine = std::array::from_fn(|i| {
            let u = i as f64 / TABLE as f64;
            rest_to_rest(2.0 * u.asin() * transfer_radius, &l.fingertip)
        });
        Self {
            object: l.object,
            fingertip: l.fingertip,
            rolling: l.rolling,
            vertical: rest_to_rest(config.planner.transfer_height, &l.fingertip),
            handover: config.load.handover_time,
            transfer_radius,
            by_half_sine,
        }
    }

    /// [`DurationModel::transfer`] from the cosine of the angle, interpolated in a
    /// table (within a few ms; used to rank candidates, not to cost plans).
    pub fn transfer_cos(&self, cos: f64) -> f64 {
        let x = (0.5 * (1.0 - cos.clamp(-1.0, 1.0))).sqrt() * TABLE as f64;
        let i = (x as usize).min(TABLE - 1);
        let f = x - i as f64;
        self.by_half_sine[i] * (1.0 - f) + self.by_half_sine[i + 1] * f
    }

    /// Rotating the object by `angle` rad.
    pub fn rotate(&self, angle: f64) -> f64 {
        rest_to_rest(angle, &self.object)
    }

    /// Moving a hovering fingertip along the transfer shell by `angle` rad
    /// (seen from O).
    pub fn transfer(&self, angle: f64) -> f64 {
        if angle < 1e-12 {
            return 0.0;
        }
        rest_to_rest(angle * self.transfer_radius, &self.fingertip)
    }

    /// Rolling a fingertip through a relative rotation of `angle` rad.
    pub fn roll(&self, angle: f64) -> f64 {
        rest_to_rest(angle, &self.rolling)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hand_computed_cases() {
        let obj = MotionLimit {
            velocity: 1.0,
            acceleration: 4.0,
            jerk: 40.0,
        };
        // Cruise phase: 2 (v/a + a/j) + (d − v (v/a + a/j)) / v.
        assert!((rest_to_rest(3.0, &obj) - 3.35).abs() < 1e-12);
        let tip = MotionLimit {
            velocity: 0.5,
            acceleration: 4.0,
            jerk: 40.0,
        };
        // Neither limit reached: 4 (d / 2j)^(1/3).
        assert!((rest_to_rest(0.03, &tip) - 4.0 * (0.03f64 / 80.0).cbrt()).abs() < 1e-12);
        // Acceleration limit reached, velocity not: d = vp (vp/a + a/j), vp = 0.45.
        assert!((rest_to_rest(0.095625, &tip) - 2.0 * (0.1125 + 0.1)).abs() < 1e-12);
    }

    #[test]
    fn table_matches_the_closed_form() {
        let t = DurationModel::new(&HandConfig::default());
        for i in 0..=1000 {
            let angle = std::f64::consts::PI * i as f64 / 1000.0;
            let exact = t.transfer(angle);
            // The table is coarse near cos = ±1 where acos is steep.
            assert!(
                (t.transfer_cos(angle.cos()) - exact).abs() < 0.03,
                "{angle}"
            );
        }
    }

    #[test]
    fn continuous_and_monotone() {
        let lim = MotionLimit {
            velocity: 1.0,
            acceleration: 4.0,
            jerk: 40.0,
        };
        // (The duration grows like the cube root of tiny distances, so start
        // where the step is finite.)
        let mut prev = rest_to_rest(0.009, &lim);
        for i in 10..5000 {
            let t = rest_to_rest(i as f64 * 1e-3, &lim);
            assert!(t > prev);
            assert!(t - prev < 0.02, "jump at {i}");
            prev = t;
        }
    }
}

/// A step's trajectory from rest, calculated with the plan off the
/// real-time thread: the executor adopts it at the step's start instead of
/// calculating it there, when its input is the one it would calculate
/// from (SPEC §5, §6.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepProfile {
    /// The generator's input at the step's start.
    pub input: Input<MAX_DOFS>,
    /// The trajectory calculated for it.
    pub trajectory: Trajectory<MAX_DOFS>,
}

/// The limit a step's path parameter runs under.
pub fn step_limit(limits: &LimitsConfig, kind: StepLimit) -> &MotionLimit {
    match kind {
        StepLimit::Object => &limits.object,
        StepLimit::Fingertip => &limits.fingertip,
        StepLimit::Rolling => &limits.rolling,
    }
}

/// The trajectory generator's input for `step` from rest at parameter 0
/// under `limits`: its path parameters to their lengths, time
/// synchronised.
pub fn step_input(step: &Step, limits: &LimitsConfig) -> Input<MAX_DOFS> {
    let d = step.dofs();
    let mut inp = Input::new([1.0; MAX_DOFS], [1.0; MAX_DOFS], [1.0; MAX_DOFS]);
    for i in 0..MAX_DOFS {
        let l = step_limit(limits, d.kind[i]);
        inp.max_velocity[i] = l.velocity;
        inp.max_acceleration[i] = l.acceleration;
        inp.max_jerk[i] = l.jerk;
        inp.target_position[i] = d.length[i];
        inp.enabled[i] = i < d.count && d.length[i] > 0.0;
    }
    inp
}

/// Each step's [`StepProfile`] under `limits` for control period `dt`
/// (`None` where the generator refuses the step's input: the executor
/// then calculates it itself, and meets the same refusal there).
pub fn step_profiles(steps: &[Step], limits: &LimitsConfig, dt: f64) -> Vec<Option<StepProfile>> {
    let Ok(mut otg) = Otg::<MAX_DOFS>::new(dt) else {
        return Vec::new();
    };
    steps
        .iter()
        .map(|step| {
            let input = step_input(step, limits);
            let mut trajectory = Trajectory::default();
            otg.calculate(&input, &mut trajectory).ok()?;
            Some(StepProfile { input, trajectory })
        })
        .collect()
}

/// A time `t` as the control loop runs it: whole periods `dt`, the last
/// one reached or passed (a motion ends on the first tick at or after its
/// end; a handover likewise).
pub fn on_ticks(t: f64, dt: f64) -> f64 {
    (t / dt - 1e-9).ceil().max(0.0) * dt
}

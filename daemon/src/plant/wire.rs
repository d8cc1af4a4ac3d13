//! Plant payloads ↔ maths types: a [`PlantMeasurement`] becomes a
//! [`Measurement`] only if it carries every required field with finite
//! numbers and unit quaternions; the setpoint becomes a [`PlantCommand`].

use gait::planner::Setpoint;
use gait::sim::{MeasuredFinger, Measurement};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use shm_schema::{
    PlantCommand, PlantFingerCommand, PlantFingerMode, PlantMeasurement, measurement_valid,
};

/// Largest deviation of a measured quaternion's norm from 1 accepted (and
/// renormalised): a plant's rounding, not a bug (as for goals, LAYOUT.md).
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Why a measurement is unusable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum BadMeasurement {
    /// A code or bit field is not one the schema defines.
    #[error("a code or bit field the schema does not define")]
    Codes,
    /// A field the daemon needs is not marked valid.
    #[error("a required field is missing (valid bits {0:#x})")]
    Missing(u32),
    /// A number is NaN or infinite.
    #[error("a non-finite number")]
    NonFinite,
    /// A quaternion's norm is not within tolerance of 1.
    #[error("a quaternion that is not of unit norm")]
    NonUnit,
}

fn quat(q: [f64; 4]) -> Result<UnitQuaternion<f64>, BadMeasurement> {
    if q.iter().any(|x| !x.is_finite()) {
        return Err(BadMeasurement::NonFinite);
    }
    let q = Quaternion::new(q[0], q[1], q[2], q[3]);
    if (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(BadMeasurement::NonUnit);
    }
    Ok(UnitQuaternion::new_normalize(q))
}

fn vec3(v: [f64; 3]) -> Result<Vector3<f64>, BadMeasurement> {
    if v.iter().any(|x| !x.is_finite()) {
        return Err(BadMeasurement::NonFinite);
    }
    Ok(Vector3::from(v))
}

fn finite(x: f64) -> Result<f64, BadMeasurement> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(BadMeasurement::NonFinite)
    }
}

/// The measurement `m` describes, reflecting the setpoint `age` ticks
/// before the last one written.
pub fn measurement(m: &PlantMeasurement, age: u32) -> Result<Measurement, BadMeasurement> {
    m.check().map_err(|_| BadMeasurement::Codes)?;
    let need = measurement_valid::REQUIRED;
    if m.valid & need != need {
        return Err(BadMeasurement::Missing(m.valid));
    }
    let forces = m.valid & measurement_valid::FORCE != 0;
    let mut fingers = [MeasuredFinger {
        center: Vector3::zeros(),
        orientation: UnitQuaternion::identity(),
        contact: false,
        normal_force: None,
        roll: None,
    }; 3];
    for (out, f) in fingers.iter_mut().zip(&m.fingers) {
        *out = MeasuredFinger {
            center: vec3(f.position)?,
            orientation: quat(f.orientation)?,
            contact: f.contact == 1,
            normal_force: if forces {
                Some(finite(f.normal_force)?)
            } else {
                None
            },
            roll: Some(finite(f.roll)?),
        };
    }
    Ok(Measurement {
        object: quat(m.object_q)?,
        fingers,
        center: if m.valid & measurement_valid::OBJECT_CENTER != 0 {
            Some(vec3(m.object_center)?)
        } else {
            None
        },
        age,
    })
}

fn q4(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// The per-finger part of a command: pose, velocities, the acceleration
/// feed-forward (`accel`), the mode and the intended grip.
pub fn finger_commands(
    sp: &Setpoint,
    accel: &[Vector3<f64>; 3],
    modes: &[PlantFingerMode; 3],
    grip: &[f64; 3],
) -> [PlantFingerCommand; 3] {
    std::array::from_fn(|k| {
        let f = &sp.state.fingers[k];
        PlantFingerCommand {
            mode: modes[k].code(),
            reserved: 0,
            position: f.center.into(),
            orientation: q4(&f.orientation),
            velocity: sp.finger_velocity[k].into(),
            angular_velocity: sp.finger_rate[k].into(),
            acceleration: accel[k].into(),
            roll: f.roll,
            grip_force: if modes[k] == PlantFingerMode::Free {
                0.0
            } else {
                grip[k].max(0.0)
            },
        }
    })
}

/// The object part of a command.
pub fn object_command(sp: &Setpoint, cmd: &mut PlantCommand) {
    cmd.object_q = q4(&sp.state.object);
    cmd.object_omega = sp.object_rate.into();
}

#[cfg(test)]
mod tests {
    use super::*;
    use gait::HandConfig;
    use gait::HandState;

    fn good() -> PlantMeasurement {
        let s = HandState::paper_start(&HandConfig::default());
        let mut m = PlantMeasurement {
            seq: 1,
            valid: measurement_valid::REQUIRED | measurement_valid::FORCE,
            object_q: [1.0, 0.0, 0.0, 0.0],
            ..PlantMeasurement::default()
        };
        for (w, f) in m.fingers.iter_mut().zip(&s.fingers) {
            w.position = f.center.into();
            w.orientation = q4(&f.orientation);
            w.contact = 1;
            w.normal_force = 2.0;
        }
        m
    }

    #[test]
    fn a_good_measurement_converts() {
        let m = measurement(&good(), 2).unwrap();
        assert_eq!(m.age, 2);
        assert!(
            m.fingers
                .iter()
                .all(|f| f.contact && f.normal_force == Some(2.0))
        );
        assert_eq!(m.fingers[0].roll, Some(0.0));
        assert_eq!(m.center, None, "no centre unless flagged");
    }

    #[test]
    fn a_measured_object_centre_is_taken_when_flagged_and_checked() {
        let mut w = good();
        w.valid |= measurement_valid::OBJECT_CENTER;
        w.object_center = [0.0003, -0.0001, -0.0012];
        let m = measurement(&w, 0).unwrap();
        assert_eq!(m.center, Some(Vector3::new(0.0003, -0.0001, -0.0012)));
        w.object_center[1] = f64::NAN;
        assert_eq!(measurement(&w, 0), Err(BadMeasurement::NonFinite));
        // Not flagged: a NaN there is not read.
        w.valid &= !measurement_valid::OBJECT_CENTER;
        assert_eq!(measurement(&w, 0).unwrap().center, None);
    }

    #[test]
    fn every_lie_is_named() {
        type Lie = fn(&mut PlantMeasurement);
        let cases: [(&str, Lie, BadMeasurement); 6] = [
            (
                "NaN",
                |m| m.fingers[1].position[2] = f64::NAN,
                BadMeasurement::NonFinite,
            ),
            (
                "infinite force",
                |m| m.fingers[2].normal_force = f64::INFINITY,
                BadMeasurement::NonFinite,
            ),
            (
                "non-unit object",
                |m| m.object_q = [0.9, 0.0, 0.0, 0.0],
                BadMeasurement::NonUnit,
            ),
            (
                "zero tip",
                |m| m.fingers[0].orientation = [0.0; 4],
                BadMeasurement::NonUnit,
            ),
            (
                "no roll",
                |m| m.valid &= !measurement_valid::ROLL,
                BadMeasurement::Missing(good().valid & !measurement_valid::ROLL),
            ),
            (
                "contact 7",
                |m| m.fingers[0].contact = 7,
                BadMeasurement::Codes,
            ),
        ];
        for (what, lie, want) in cases {
            let mut m = good();
            lie(&mut m);
            assert_eq!(measurement(&m, 0), Err(want), "{what}");
        }
        // Slightly off unit: renormalised.
        let mut m = good();
        m.object_q = [1.0005, 0.0, 0.0, 0.0];
        let q = measurement(&m, 0).unwrap().object;
        assert!((q.quaternion().norm() - 1.0).abs() < 1e-15);
    }
}

//! Plant payloads ↔ maths types: a [`PlantMeasurement`] becomes a
//! [`Measurement`] only if it carries every required field with finite
//! numbers and unit quaternions, and every optional field it flags valid
//! with finite numbers (velocities too, though the controller does not use
//! them); the setpoint becomes a [`PlantCommand`]. A chain hand's plant
//! is read by its joints ([`joint_measurement`]): the tips are where
//! they put them.

use super::joints::{JOINTS, JointLink};
use gait::planner::Setpoint;
use gait::sim::{MeasuredFinger, Measurement};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use shm_schema::{
    PlantCommand, PlantFingerCommand, PlantFingerMode, PlantMeasurement, measurement_valid,
};

/// Largest deviation of a measured quaternion's norm from 1 accepted (and
/// renormalised): a plant's rounding, not a bug (as for goals, LAYOUT.md).
pub const QUATERNION_NORM_TOLERANCE: f64 = 1e-3;

/// Why a measurement is unusable. A bad number or quaternion names the
/// finger whose field holds it (`None`: an object field).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum BadMeasurement {
    /// A code or bit field is not one the schema defines.
    #[error("a code or bit field the schema does not define")]
    Codes,
    /// A field the daemon needs is not marked valid.
    #[error("a required field is missing (valid bits {0:#x})")]
    Missing(u32),
    /// A number is NaN or infinite.
    #[error("a non-finite number (finger {finger:?})")]
    NonFinite {
        /// The finger whose field it is, if any.
        finger: Option<u8>,
    },
    /// A quaternion's norm is not within tolerance of 1.
    #[error("a quaternion that is not of unit norm (finger {finger:?})")]
    NonUnit {
        /// The finger whose orientation it is, if any.
        finger: Option<u8>,
    },
    /// A chain hand's finger measured with another number of joints than
    /// it has.
    #[error(
        "finger {finger} measured with {count} joints, the hand's have {}",
        JOINTS
    )]
    JointCount {
        /// The finger.
        finger: u8,
        /// The `joint_count` it sent.
        count: u32,
    },
}

impl BadMeasurement {
    const NON_FINITE: Self = Self::NonFinite { finger: None };

    /// The finger whose field is bad, if one is.
    pub fn finger(self) -> Option<u8> {
        match self {
            Self::NonFinite { finger } | Self::NonUnit { finger } => finger,
            Self::JointCount { finger, .. } => Some(finger),
            Self::Codes | Self::Missing(_) => None,
        }
    }

    /// The same fault, in a field of finger `k`.
    fn of_finger(self, k: usize) -> Self {
        let finger = u8::try_from(k).ok();
        match self {
            Self::NonFinite { .. } => Self::NonFinite { finger },
            Self::NonUnit { .. } => Self::NonUnit { finger },
            other => other,
        }
    }
}

/// A finger before its fields are read.
const UNREAD: MeasuredFinger = MeasuredFinger {
    center: Vector3::new(0.0, 0.0, 0.0),
    orientation: UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(1.0, 0.0, 0.0, 0.0)),
    contact: false,
    normal_force: None,
    roll: None,
};

fn quat(q: [f64; 4]) -> Result<UnitQuaternion<f64>, BadMeasurement> {
    if q.iter().any(|x| !x.is_finite()) {
        return Err(BadMeasurement::NON_FINITE);
    }
    let q = Quaternion::new(q[0], q[1], q[2], q[3]);
    if (q.norm() - 1.0).abs() > QUATERNION_NORM_TOLERANCE {
        return Err(BadMeasurement::NonUnit { finger: None });
    }
    Ok(UnitQuaternion::new_normalize(q))
}

fn vec3(v: [f64; 3]) -> Result<Vector3<f64>, BadMeasurement> {
    if v.iter().any(|x| !x.is_finite()) {
        return Err(BadMeasurement::NON_FINITE);
    }
    Ok(Vector3::from(v))
}

fn finite(x: f64) -> Result<f64, BadMeasurement> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(BadMeasurement::NON_FINITE)
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
    let tip_velocity = m.valid & measurement_valid::TIP_VELOCITY != 0;
    let mut fingers = [UNREAD; 3];
    for (k, (out, f)) in fingers.iter_mut().zip(&m.fingers).enumerate() {
        let convert = || -> Result<MeasuredFinger, BadMeasurement> {
            if tip_velocity {
                vec3(f.velocity)?;
                vec3(f.angular_velocity)?;
            }
            Ok(MeasuredFinger {
                center: vec3(f.position)?,
                orientation: quat(f.orientation)?,
                contact: f.contact == 1,
                normal_force: if forces {
                    Some(finite(f.normal_force)?)
                } else {
                    None
                },
                roll: Some(finite(f.roll)?),
            })
        };
        *out = convert().map_err(|e| e.of_finger(k))?;
    }
    if m.valid & measurement_valid::OBJECT_VELOCITY != 0 {
        vec3(m.object_omega)?;
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
        object_age: 0,
    })
}

/// A measurement's `object_age_us` in ticks of `period_ns`, to the nearest
/// (what [`measurement`] and [`joint_measurement`] leave at 0: the link
/// knows the period).
pub fn object_age_ticks(object_age_us: u32, period_ns: u64) -> u32 {
    let ns = u64::from(object_age_us) * 1000;
    u32::try_from((ns + period_ns / 2) / period_ns.max(1)).unwrap_or(u32::MAX)
}

/// The measurement of a chain hand's plant `m` (`link`'s hand), reflecting
/// the setpoint `age` ticks before the last one written: each finger's tip
/// where its measured joints put it (the tip fields are not read), and
/// those joints.
pub fn joint_measurement(
    m: &PlantMeasurement,
    age: u32,
    link: &JointLink,
) -> Result<(Measurement, [Vector3<f64>; 3]), BadMeasurement> {
    m.check().map_err(|_| BadMeasurement::Codes)?;
    let need = measurement_valid::REQUIRED_JOINTS;
    if m.valid & need != need {
        return Err(BadMeasurement::Missing(m.valid));
    }
    let flagged = |bit| m.valid & bit != 0;
    let mut joints = [Vector3::zeros(); 3];
    let mut fingers = [UNREAD; 3];
    for (k, f) in m.fingers.iter().enumerate() {
        if f.joint_count as usize != JOINTS {
            return Err(BadMeasurement::JointCount {
                finger: k as u8,
                count: f.joint_count,
            });
        }
        let convert = || -> Result<(Vector3<f64>, Option<f64>), BadMeasurement> {
            let q = vec3([
                f.joint_position[0],
                f.joint_position[1],
                f.joint_position[2],
            ])?;
            if flagged(measurement_valid::JOINT_VELOCITY) {
                vec3([
                    f.joint_velocity[0],
                    f.joint_velocity[1],
                    f.joint_velocity[2],
                ])?;
            }
            if flagged(measurement_valid::JOINT_TORQUE) {
                vec3([f.joint_torque[0], f.joint_torque[1], f.joint_torque[2]])?;
            }
            let force = if flagged(measurement_valid::FORCE) {
                Some(finite(f.normal_force)?)
            } else {
                None
            };
            Ok((q, force))
        };
        let (q, normal_force) = convert().map_err(|e| e.of_finger(k))?;
        let tip = link.tip(k, &q);
        joints[k] = q;
        fingers[k] = MeasuredFinger {
            center: tip.center,
            orientation: tip.orientation,
            contact: f.contact == 1,
            normal_force,
            roll: None,
        };
    }
    if flagged(measurement_valid::OBJECT_VELOCITY) {
        vec3(m.object_omega)?;
    }
    let measurement = Measurement {
        object: quat(m.object_q)?,
        fingers,
        center: if flagged(measurement_valid::OBJECT_CENTER) {
            Some(vec3(m.object_center)? - link.hand().object().centre)
        } else {
            None
        },
        age,
        object_age: 0,
    };
    Ok((measurement, joints))
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
            ..PlantFingerCommand::default()
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
        assert_eq!(object_age_ticks(0, 1_000_000), 0);
        assert_eq!(object_age_ticks(10_000, 1_000_000), 10);
        assert_eq!(object_age_ticks(10_499, 1_000_000), 10);
        assert_eq!(object_age_ticks(10_500, 2_000_000), 5);
        assert_eq!(object_age_ticks(u32::MAX, 1), u32::MAX);
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
        assert_eq!(measurement(&w, 0), Err(BadMeasurement::NON_FINITE));
        // Not flagged: a NaN there is not read.
        w.valid &= !measurement_valid::OBJECT_CENTER;
        assert_eq!(measurement(&w, 0).unwrap().center, None);
    }

    #[test]
    fn every_lie_is_named() {
        type Lie = fn(&mut PlantMeasurement);
        let (object, f0, f1, f2) = (None, Some(0), Some(1), Some(2));
        let cases: [(&str, Lie, BadMeasurement); 10] = [
            (
                "NaN",
                |m| m.fingers[1].position[2] = f64::NAN,
                BadMeasurement::NonFinite { finger: f1 },
            ),
            (
                "infinite force",
                |m| m.fingers[2].normal_force = f64::INFINITY,
                BadMeasurement::NonFinite { finger: f2 },
            ),
            (
                "NaN object velocity",
                |m| {
                    m.valid |= measurement_valid::OBJECT_VELOCITY;
                    m.object_omega[2] = f64::NAN;
                },
                BadMeasurement::NonFinite { finger: object },
            ),
            (
                "infinite tip velocity",
                |m| {
                    m.valid |= measurement_valid::TIP_VELOCITY;
                    m.fingers[0].velocity[1] = f64::NEG_INFINITY;
                },
                BadMeasurement::NonFinite { finger: f0 },
            ),
            (
                "NaN tip angular velocity",
                |m| {
                    m.valid |= measurement_valid::TIP_VELOCITY;
                    m.fingers[2].angular_velocity[0] = f64::NAN;
                },
                BadMeasurement::NonFinite { finger: f2 },
            ),
            (
                "non-unit object",
                |m| m.object_q = [0.9, 0.0, 0.0, 0.0],
                BadMeasurement::NonUnit { finger: object },
            ),
            (
                "zero tip",
                |m| m.fingers[0].orientation = [0.0; 4],
                BadMeasurement::NonUnit { finger: f0 },
            ),
            (
                "NaN tip orientation",
                |m| m.fingers[1].orientation[3] = f64::NAN,
                BadMeasurement::NonFinite { finger: f1 },
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
        // Velocities not flagged valid are not read, so not checked (as
        // every optional field); flagged and finite, they pass.
        let mut m = good();
        m.object_omega = [f64::NAN; 3];
        m.fingers[1].velocity = [f64::INFINITY; 3];
        assert!(measurement(&m, 0).is_ok());
        let mut m = good();
        m.valid |= measurement_valid::OBJECT_VELOCITY | measurement_valid::TIP_VELOCITY;
        m.object_omega = [0.1, -0.2, 0.3];
        m.fingers[1].angular_velocity = [1.0, 2.0, 3.0];
        assert!(measurement(&m, 0).is_ok());
        // Slightly off unit: renormalised.
        let mut m = good();
        m.object_q = [1.0005, 0.0, 0.0, 0.0];
        let q = measurement(&m, 0).unwrap().object;
        assert!((q.quaternion().norm() - 1.0).abs() < 1e-15);
    }

    /// A chain hand's plant, read by its joints: the tips where forward
    /// kinematics puts them (the tip fields, even NaN, are not read), and
    /// each lie about the joints named.
    #[test]
    fn a_joint_measurement_is_read_by_its_joints_and_its_lies_named() {
        let link = crate::plant::joints::tests::trifingerpro(true);
        let q = [0.3, 0.9, -1.8];
        let good = || {
            let mut m = PlantMeasurement {
                seq: 1,
                valid: measurement_valid::REQUIRED_JOINTS | measurement_valid::JOINT_VELOCITY,
                object_q: [1.0, 0.0, 0.0, 0.0],
                ..PlantMeasurement::default()
            };
            for f in &mut m.fingers {
                f.joint_count = 3;
                f.joint_position[..3].copy_from_slice(&q);
                f.contact = 1;
                f.position = [f64::NAN; 3];
            }
            m
        };
        let (m, joints) = joint_measurement(&good(), 1, &link).unwrap();
        for (k, (f, joints)) in m.fingers.iter().zip(&joints).enumerate() {
            let tip = link.hand().chain(k).forward(&Vector3::from(q)).tip_centre();
            assert!((f.center + link.hand().object().centre - tip).norm() < 1e-15);
            assert_eq!(*joints, Vector3::from(q));
            assert!(f.contact && f.roll.is_none());
        }
        type Lie = fn(&mut PlantMeasurement);
        let cases: [(&str, Lie, BadMeasurement); 4] = [
            (
                "two joints",
                |m| m.fingers[1].joint_count = 2,
                BadMeasurement::JointCount {
                    finger: 1,
                    count: 2,
                },
            ),
            (
                "NaN joint",
                |m| m.fingers[2].joint_position[1] = f64::NAN,
                BadMeasurement::NonFinite { finger: Some(2) },
            ),
            (
                "infinite joint velocity",
                |m| m.fingers[0].joint_velocity[2] = f64::INFINITY,
                BadMeasurement::NonFinite { finger: Some(0) },
            ),
            (
                "no joints",
                |m| m.valid &= !measurement_valid::JOINT_POSITION,
                BadMeasurement::Missing(
                    measurement_valid::REQUIRED_JOINTS & !measurement_valid::JOINT_POSITION
                        | measurement_valid::JOINT_VELOCITY,
                ),
            ),
        ];
        for (what, lie, want) in cases {
            let mut m = good();
            lie(&mut m);
            assert_eq!(
                joint_measurement(&m, 0, &link).map(|_| ()),
                Err(want),
                "{what}"
            );
        }
    }
}

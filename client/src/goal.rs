//! Describing a reorientation goal.

use crate::error::{Error, Result};
use shm_schema::{Command, GoalFrame, LimitKind, LimitOrder};

/// The unit quaternion [w, x, y, z] of a rotation by `angle` \[rad\] about
/// `axis` (any non-zero length).
pub fn quat_from_axis_angle(axis: [f64; 3], angle: f64) -> Result<[f64; 4]> {
    let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
    if !(n.is_finite() && n > 1e-12) {
        return Err(Error::Invalid("rotation axis must be finite and non-zero"));
    }
    if !angle.is_finite() {
        return Err(Error::Invalid("rotation angle must be finite"));
    }
    let (s, c) = (angle / 2.0).sin_cos();
    Ok([c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n])
}

/// A reorientation goal: target and optional motion-limit overrides (which
/// may only lower the daemon's configured limits).
#[derive(Debug, Clone, PartialEq)]
pub struct GoalSpec {
    /// Target quaternion [w, x, y, z].
    pub target: [f64; 4],
    /// Absolute orientation or rotation relative to the current one.
    pub frame: GoalFrame,
    /// Limit overrides.
    pub limits: Vec<(LimitKind, LimitOrder, f64)>,
}

impl GoalSpec {
    /// Reach the object orientation `q` [w, x, y, z] (object → hand frame).
    pub fn absolute(q: [f64; 4]) -> Self {
        Self {
            target: q,
            frame: GoalFrame::Absolute,
            limits: Vec::new(),
        }
    }

    /// Rotate the object by `q` [w, x, y, z] (hand frame) from where it is.
    pub fn relative(q: [f64; 4]) -> Self {
        Self {
            target: q,
            frame: GoalFrame::Relative,
            limits: Vec::new(),
        }
    }

    /// A goal given as axis and angle \[rad\].
    pub fn axis_angle(axis: [f64; 3], angle: f64, frame: GoalFrame) -> Result<Self> {
        if frame == GoalFrame::AxisAngle {
            return Self::turn(axis, angle);
        }
        Ok(Self {
            target: quat_from_axis_angle(axis, angle)?,
            frame,
            limits: Vec::new(),
        })
    }

    /// Turn the object by `angle` \[rad\] about the hand-frame `axis` from its
    /// current orientation — any angle: 2π is a full turn, not a no-op
    /// (frame [`GoalFrame::AxisAngle`]).
    pub fn turn(axis: [f64; 3], angle: f64) -> Result<Self> {
        let n = axis.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(n.is_finite() && n > 1e-12) {
            return Err(Error::Invalid("rotation axis must be finite and non-zero"));
        }
        if !(angle.is_finite() && angle.abs() <= shm_schema::MAX_AXIS_ANGLE) {
            return Err(Error::Invalid(
                "rotation angle must be finite and at most 64π",
            ));
        }
        Ok(Self {
            target: [angle, axis[0] / n, axis[1] / n, axis[2] / n],
            frame: GoalFrame::AxisAngle,
            limits: Vec::new(),
        })
    }

    /// Lowers one motion limit for this goal.
    pub fn limit(mut self, kind: LimitKind, order: LimitOrder, value: f64) -> Self {
        self.limits.push((kind, order, value));
        self
    }

    /// The wire command.
    pub fn to_command(&self, client_id: u64, goal_id: u64) -> Command {
        self.limits.iter().fold(
            Command::goal(client_id, goal_id, self.frame, self.target),
            |c, &(k, o, v)| c.with_limit(k, o, v),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_angle_makes_unit_quaternions() {
        let q = quat_from_axis_angle([0.0, 0.0, 2.0], std::f64::consts::PI).unwrap();
        assert!((q[0]).abs() < 1e-15 && (q[3] - 1.0).abs() < 1e-15);
        let q = quat_from_axis_angle([1.0, 1.0, 1.0], 0.7).unwrap();
        let n: f64 = q.iter().map(|x| x * x).sum();
        assert!((n - 1.0).abs() < 1e-15);
        assert!(quat_from_axis_angle([0.0; 3], 1.0).is_err());
        assert!(quat_from_axis_angle([1.0, 0.0, 0.0], f64::NAN).is_err());
    }

    #[test]
    fn spec_builds_a_valid_command() {
        let c = GoalSpec::axis_angle([1.0, 0.0, 0.0], 1.0, GoalFrame::Relative)
            .unwrap()
            .limit(LimitKind::Object, LimitOrder::Velocity, 0.5)
            .to_command(3, 4);
        assert!(c.validate().is_ok());
        assert_eq!(c.object_limits.velocity, 0.5);
    }
}

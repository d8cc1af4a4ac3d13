//! The rotation still to do (SPEC §4.1): what the search's progress is.
//!
//! The search reaches an orientation q_g (the object must end there, any
//! path) and tracks the hand-frame rotation R with q_g = R q as a unit
//! axis a and an angle φ ∈ [0, π]. Turning the object about a by t ≤ φ
//! leaves (a, φ − t); turning it about another axis e by t leaves
//! R Rot(e, t)⁻¹, in its shortest form.
//!
//! A goal that asks for a turn of a given size (a full turn is not a
//! no-op) is planned as consecutive orientations, each at most
//! [`super::alternatives::TURN_PIECE`] further about the turn's axis
//! (`Planner::plan_within`): shorter than half a turn, each one's shortest
//! rotation is the turn's own piece, so the object turns that far, that
//! way.

use nalgebra::{UnitQuaternion, Vector3};

use super::alternatives::TURN_PIECE;
use super::geometry::rotation;
use super::{PlanError, Target};

/// The rotation still to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Remaining {
    /// Unit axis a (hand frame).
    pub axis: Vector3<f64>,
    /// Angle φ ∈ [0, π] \[rad\].
    pub angle: f64,
}

/// Below this the goal is reached \[rad\].
pub const REACHED: f64 = 1e-12;

impl Remaining {
    /// The shortest rotation from `from` to `to`.
    pub fn orientation(from: &UnitQuaternion<f64>, to: &UnitQuaternion<f64>) -> Self {
        let (axis, angle) = rotation_to(from, to);
        Self { axis, angle }
    }

    /// Whether nothing is left.
    pub fn reached(&self) -> bool {
        self.angle <= REACHED
    }

    /// What is left after the object turns about its own axis by `t` ≤ φ.
    pub fn advanced(&self, t: f64) -> Self {
        let angle = if self.angle - t <= REACHED {
            0.0
        } else {
            self.angle - t
        };
        Self { angle, ..*self }
    }

    /// What is left after the object turns about the unit axis `e` by `t`
    /// (module docs).
    pub fn after(&self, e: &Vector3<f64>, t: f64) -> Self {
        if (e - self.axis).norm() < 1e-15 && t <= self.angle {
            return self.advanced(t);
        }
        let r = rotation(&self.axis, self.angle) * rotation(e, -t);
        match r.axis_angle() {
            Some((a, phi)) if phi > 0.0 => Self {
                axis: a.into_inner(),
                angle: phi,
            },
            _ => Self {
                axis: self.axis,
                angle: 0.0,
            },
        }
    }
}

/// Where a request's target leads from a start orientation, and the
/// orientations it is planned through (module docs): one for an
/// orientation goal, a turn's pieces of at most
/// [`super::alternatives::TURN_PIECE`] for a turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Course {
    /// The orientation the object ends at.
    pub goal: UnitQuaternion<f64>,
    /// The angle asked for: to the goal (shortest), or the turn's own.
    pub angle: f64,
    /// How many orientations are planned to in turn (≥ 1).
    pub pieces: usize,
    /// A turn's unit axis (`None`: an orientation goal).
    turn: Option<Vector3<f64>>,
    from: UnitQuaternion<f64>,
}

impl Course {
    /// The course of `target` from `from`; a goal that is not finite, a
    /// zero axis: [`PlanError::InvalidGoal`].
    pub fn new(from: &UnitQuaternion<f64>, target: &Target) -> Result<Self, PlanError> {
        let (goal, angle, turn) = match *target {
            Target::Orientation(q) => {
                let gq = q.quaternion();
                if !gq.coords.iter().all(|x| x.is_finite()) || gq.norm() < 1e-9 {
                    return Err(PlanError::InvalidGoal);
                }
                let goal = UnitQuaternion::new_normalize(*gq);
                (goal, from.angle_to(&goal), None)
            }
            Target::Turn { axis, angle } => {
                let n = axis.norm();
                if !(n.is_finite() && n > 1e-9 && angle.is_finite()) {
                    return Err(PlanError::InvalidGoal);
                }
                let (axis, angle) = if angle < 0.0 {
                    (-axis / n, -angle)
                } else {
                    (axis / n, angle)
                };
                (rotation(&axis, angle) * from, angle, Some(axis))
            }
        };
        let pieces = match turn {
            Some(_) => (angle / TURN_PIECE).ceil().max(1.0) as usize,
            None => 1,
        };
        Ok(Self {
            goal,
            angle,
            pieces,
            turn,
            from: *from,
        })
    }

    /// The orientation piece `k` (1 ..= `pieces`) ends at.
    pub fn piece(&self, k: usize) -> UnitQuaternion<f64> {
        self.along(self.angle * k as f64 / self.pieces as f64)
    }

    /// The orientation `turned` along the course: a turn's start turned
    /// that far about its axis; an orientation goal's goal.
    pub fn along(&self, turned: f64) -> UnitQuaternion<f64> {
        match self.turn {
            Some(axis) => rotation(&axis, turned) * self.from,
            None => self.goal,
        }
    }

    /// Whether the course is a turn (its pieces can be cut otherwise).
    pub fn is_turn(&self) -> bool {
        self.turn.is_some()
    }
}

/// Axis (unit) and angle in [0, π] of the hand-frame rotation taking `from`
/// to `to` (q_d = to · from⁻¹).
pub fn rotation_to(from: &UnitQuaternion<f64>, to: &UnitQuaternion<f64>) -> (Vector3<f64>, f64) {
    let d = to * from.inverse();
    match d.axis_angle() {
        Some((axis, angle)) if angle > 0.0 => (axis.into_inner(), angle),
        _ => (Vector3::z(), 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_detour_leaves_what_takes_the_object_to_the_goal() {
        let q0 = UnitQuaternion::from_euler_angles(0.3, -0.2, 1.1);
        let goal = UnitQuaternion::from_euler_angles(-1.0, 0.4, 0.2);
        let rem = Remaining::orientation(&q0, &goal);
        let e = Vector3::new(1.0, 2.0, -0.5).normalize();
        let after = rem.after(&e, 0.7);
        let q1 = rotation(&e, 0.7) * q0;
        let q2 = rotation(&after.axis, after.angle) * q1;
        assert!(q2.angle_to(&goal) < 1e-12);
        assert!(after.angle <= std::f64::consts::PI + 1e-12);
        // About its own axis it just counts down.
        assert_eq!(rem.after(&rem.axis, 0.1).angle, rem.angle - 0.1);
    }
}

//! The rotation still to do (SPEC §4.1): what the search's progress is.
//!
//! A goal is an orientation q_g (the object must end there, any path) or
//! a turn by an angle about an axis (it must also turn that far: a full
//! turn is not a no-op). Either way the search tracks the hand-frame
//! rotation R with q_g = R q, as a unit axis a and an angle φ ≥ 0 — φ ≤ π
//! for an orientation, any size for a turn. Turning the object about a by
//! t ≤ φ leaves (a, φ − t). Turning it about another axis e by t leaves
//! R Rot(e, t)⁻¹: for an orientation, its shortest form; for a turn, the
//! form among (a', φ' + 2πk), (−a', 2πk − φ') whose angle is nearest to
//! φ − t (a·e), what the turn had left less the detour's part along it —
//! so the turn keeps its size and sense through detours.

use nalgebra::{UnitQuaternion, Vector3};

use super::geometry::rotation;

/// The rotation still to do, and how to count full turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Remaining {
    /// Unit axis a (hand frame).
    pub axis: Vector3<f64>,
    /// Angle φ ≥ 0 \[rad\].
    pub angle: f64,
    /// For a turn: the axis it was asked about (its full turns keep this
    /// sense). `None`: an orientation goal (φ ≤ π, no full turns).
    pub turn: Option<Vector3<f64>>,
}

/// Below this the goal is reached \[rad\].
pub const REACHED: f64 = 1e-12;

impl Remaining {
    /// The shortest rotation from `from` to `to` (φ ≤ π).
    pub fn orientation(from: &UnitQuaternion<f64>, to: &UnitQuaternion<f64>) -> Self {
        let (axis, angle) = rotation_to(from, to);
        Self {
            axis,
            angle,
            turn: None,
        }
    }

    /// A turn by `angle` ≥ 0 about the unit `axis`.
    pub fn turn(axis: Vector3<f64>, angle: f64) -> Self {
        Self {
            axis,
            angle,
            turn: Some(axis),
        }
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
        let (a, phi) = match r.axis_angle() {
            Some((a, phi)) if phi > 0.0 => (a.into_inner(), phi),
            _ => (self.axis, 0.0),
        };
        let (axis, angle) = match self.turn {
            Some(_) => {
                let tau = std::f64::consts::TAU;
                let want = self.angle - t * self.axis.dot(e);
                // Nearest of φ' + 2πk (about a') and 2πk − φ' (about −a').
                let k1 = ((want - phi) / tau).round().max(0.0);
                let k2 = ((want + phi) / tau).round().max(1.0);
                let (x1, x2) = (phi + tau * k1, tau * k2 - phi);
                if (x1 - want).abs() <= (x2 - want).abs() {
                    (a, x1)
                } else {
                    (-a, x2)
                }
            }
            None => (a, phi),
        };
        Self {
            axis,
            angle,
            turn: self.turn,
        }
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
    }

    #[test]
    fn a_turn_keeps_its_full_turns_through_a_detour() {
        let k = Vector3::z();
        let rem = Remaining::turn(k, 2.0 * std::f64::consts::TAU + 0.5);
        let e = Vector3::x();
        let after = rem.after(&e, 0.3);
        // Still two full turns, in the sense of z.
        assert!(after.angle > 2.0 * std::f64::consts::TAU);
        assert!(after.angle < 2.0 * std::f64::consts::TAU + std::f64::consts::PI);
        assert!(after.axis.dot(&k) >= 0.0);
        // And it ends where the turn ends.
        let q0 = UnitQuaternion::identity();
        let goal = rotation(&k, rem.angle) * q0;
        let end = rotation(&after.axis, after.angle) * rotation(&e, 0.3) * q0;
        assert!(end.angle_to(&goal) < 1e-9);
        // About its own axis it just counts down.
        assert_eq!(rem.after(&k, 1.0).angle, rem.angle - 1.0);
        // A turn of more than half a turn keeps going the long way.
        let long = Remaining::turn(k, 300f64.to_radians());
        let after = long.after(&e, 0.5);
        assert!(
            after.angle > 250f64.to_radians(),
            "{}",
            after.angle.to_degrees()
        );
        let end = rotation(&after.axis, after.angle) * rotation(&e, 0.5);
        assert!(end.angle_to(&rotation(&k, long.angle)) < 1e-9);
    }
}

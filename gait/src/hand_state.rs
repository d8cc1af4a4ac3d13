//! The state of the hand and object (SPEC.md §1.1, §4.1).
//!
//! Only independent quantities are stored; contact points are derived:
//! a grasping finger's fingertip centre is p = (R + r) n with n the outward
//! object normal at the contact, the contact on the object (object frame) is
//! Q_oᵀ n, the contact on the fingertip (fingertip frame) is m = Q_fᵀ (−n)
//! (SPEC §2.3).

use nalgebra::{UnitQuaternion, Vector3};

/// Number of fingers of the hand.
pub const FINGERS: usize = 3;

/// Whether a finger touches the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FingerMode {
    /// In contact, part of the grasp (|p| = R + r).
    Grasping,
    /// Lifted, in its free-space shell.
    Free,
}

/// One finger: fingertip pose and accumulated roll.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerState {
    /// Grasping or free.
    pub mode: FingerMode,
    /// Fingertip sphere centre p, hand frame \[m\].
    pub center: Vector3<f64>,
    /// Fingertip orientation Q_f (fingertip frame → hand frame). The
    /// fingertip's pole axis (centre of its contactable hemisphere) is
    /// Q_f e_z.
    pub orientation: UnitQuaternion<f64>,
    /// Roll τ about the pole axis, τ̇ = ω_f · (Q_f e_z) (SPEC §1.1) \[rad\].
    pub roll: f64,
}

impl FingerState {
    /// The fingertip pole axis a_f = Q_f e_z, hand frame.
    pub fn pole_axis(&self) -> Vector3<f64> {
        self.orientation * Vector3::z()
    }

    /// The outward object normal at the contact (hand frame), for a
    /// grasping finger: the direction of the fingertip centre.
    pub fn contact_normal(&self) -> Vector3<f64> {
        self.center.normalize()
    }

    /// Contact point on the fingertip, fingertip frame, as a unit vector:
    /// m = Q_fᵀ (−n).
    pub fn fingertip_contact(&self) -> Vector3<f64> {
        self.orientation.inverse() * (-self.contact_normal())
    }
}

/// Object orientation plus the three fingers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandState {
    /// Object orientation q_o (object frame → hand frame).
    pub object: UnitQuaternion<f64>,
    /// Fingers f1, f2, f3 (index 0, 1, 2).
    pub fingers: [FingerState; FINGERS],
}

impl HandState {
    /// Indices of the grasping fingers, in order, and how many there are.
    pub fn grasping(&self) -> ([usize; FINGERS], usize) {
        let mut idx = [0; FINGERS];
        let mut n = 0;
        for (k, f) in self.fingers.iter().enumerate() {
            if f.mode == FingerMode::Grasping {
                idx[n] = k;
                n += 1;
            }
        }
        (idx, n)
    }

    /// The contact point on the object, object frame (unit vector), of a
    /// grasping finger.
    pub fn object_contact(&self, finger: usize) -> Vector3<f64> {
        self.object.inverse() * self.fingers[finger].contact_normal()
    }
}

impl HandState {
    /// The paper's initial grasp (paper §4, Fig. 4 frame 1): object at
    /// identity, the three fingers on the equator along their base directions
    /// d_k, each touching with its fingertip pole (m = e_z), roll 0.
    ///
    /// The fingertip frame is fixed by: pole axis Q_f e_z = −d_k (pointing
    /// into the object), Q_f e_x = hand z (up).
    pub fn paper_start(config: &crate::HandConfig) -> Self {
        let m = &config.model;
        let finger = |azimuth_deg: f64| {
            let phi = azimuth_deg.to_radians();
            let d = Vector3::new(phi.cos(), phi.sin(), 0.0);
            let z_f = -d;
            let x_f = Vector3::z();
            let y_f = z_f.cross(&x_f);
            let rot =
                nalgebra::Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[
                    x_f, y_f, z_f,
                ]));
            FingerState {
                mode: FingerMode::Grasping,
                center: d * (m.object_radius + m.fingertip_radius),
                orientation: UnitQuaternion::from_rotation_matrix(&rot),
                roll: 0.0,
            }
        };
        Self {
            object: UnitQuaternion::identity(),
            fingers: m.finger_azimuth_deg.map(finger),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_start_touches_with_the_poles() {
        let c = crate::HandConfig::default();
        let s = HandState::paper_start(&c);
        assert_eq!(s.grasping().1, 3);
        for f in &s.fingers {
            assert!((f.center.norm() - 0.6).abs() < 1e-15);
            assert!((f.fingertip_contact() - Vector3::z()).norm() < 1e-12);
            assert!((f.pole_axis() + f.contact_normal()).norm() < 1e-12);
        }
    }
}

//! Rigid frames: a rotation matrix and a translation.
//!
//! A [`Frame`] maps coordinates of a child frame into its parent:
//! $x_{parent} = R\,x_{child} + p$. URDF poses (`xyz`, `rpy`) become frames
//! with $R = R_z(\text{yaw})\,R_y(\text{pitch})\,R_x(\text{roll})$ (URDF's
//! fixed-axis roll–pitch–yaw). Matrices rather than quaternions: forward
//! kinematics composes a handful of them per tick and reads their columns
//! (joint axes) directly.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A rigid transform from a child frame to its parent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Rotation (child axes in parent coordinates, as columns).
    pub rotation: Matrix3<f64>,
    /// Origin of the child frame in parent coordinates \[m\].
    pub translation: Vector3<f64>,
}

impl Frame {
    /// The identity transform.
    pub const IDENTITY: Frame = Frame {
        rotation: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        translation: Vector3::new(0.0, 0.0, 0.0),
    };

    /// A frame from a URDF pose: translation `xyz` \[m\], fixed-axis `rpy` \[rad\].
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Frame {
        Frame {
            rotation: *Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]).matrix(),
            translation: Vector3::from(xyz),
        }
    }

    /// A pure rotation by `angle` \[rad\] about the unit `axis` (Rodrigues).
    #[inline]
    pub fn rotation_about(axis: &Unit<Vector3<f64>>, angle: f64) -> Matrix3<f64> {
        let (s, c) = angle.sin_cos();
        let a = axis.as_ref();
        let k = a.cross_matrix();
        Matrix3::identity() + k * s + k * k * (1.0 - c)
    }

    /// `self ∘ child`: the child's frame expressed in this frame's parent.
    #[inline]
    pub fn compose(&self, child: &Frame) -> Frame {
        Frame {
            rotation: self.rotation * child.rotation,
            translation: self.rotation * child.translation + self.translation,
        }
    }

    /// A point given in this frame, in the parent frame.
    #[inline]
    pub fn point(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * x + self.translation
    }

    /// The inverse transform (parent into child).
    pub fn inverse(&self) -> Frame {
        let rt = self.rotation.transpose();
        Frame {
            rotation: rt,
            translation: -(rt * self.translation),
        }
    }
}

impl Default for Frame {
    fn default() -> Self {
        Frame::IDENTITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpy_is_fixed_axis_xyz() {
        // URDF: roll about x, then pitch about the fixed y, then yaw about the fixed z.
        let (r, p, y) = (0.3, -0.7, 1.1);
        let f = Frame::from_xyz_rpy([0.0; 3], [r, p, y]);
        let rz = Frame::rotation_about(&Vector3::z_axis(), y);
        let ry = Frame::rotation_about(&Vector3::y_axis(), p);
        let rx = Frame::rotation_about(&Vector3::x_axis(), r);
        assert!((f.rotation - rz * ry * rx).norm() < 1e-14);
    }

    #[test]
    fn inverse_composes_to_identity() {
        let f = Frame::from_xyz_rpy([0.1, -0.2, 0.3], [0.4, 0.5, -0.6]);
        let i = f.compose(&f.inverse());
        assert!((i.rotation - Matrix3::identity()).norm() < 1e-14);
        assert!(i.translation.norm() < 1e-15);
    }
}

//! The tip patch (SPEC §14.1 "Tip patch"): where on the tip a contact may be.
//!
//! With the object's outward normal $n$ at the contact (hand frame) and the
//! tip rotation $R_k$, the contact point on the tip in tip coordinates is
//! the unit vector $u = R_k^\top(-n)$. It is valid when
//! $\angle(u, p) \le \alpha - \text{margin}$, $p$ the tip's pole.
//! TriFingerPro: the pole is $-z$ of the tip frame (the tip frame's z axis
//! runs up the lower link, so the pole points away from the link) and
//! $\alpha = 90°$: the hemisphere below the tip frame.

use nalgebra::{Matrix3, Unit, Vector3};

/// The contactable region of a tip: a cap of half-angle α around its pole.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipPatch {
    /// The pole p (unit, tip coordinates).
    pub pole: Unit<Vector3<f64>>,
    /// Half-angle α \[rad\].
    pub alpha: f64,
}

impl TipPatch {
    /// The contact point on the tip (unit, tip coordinates): $u = R^\top(-n)$.
    pub fn contact_point(tip_rotation: &Matrix3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
        -(tip_rotation.transpose() * n)
    }

    /// The angle between the contact point and the pole \[rad\].
    pub fn angle_from_pole(&self, tip_rotation: &Matrix3<f64>, n: &Vector3<f64>) -> f64 {
        let u = Self::contact_point(tip_rotation, n);
        // atan2 of |u × p| and u·p: accurate near 0 and π, unlike acos.
        u.cross(&self.pole).norm().atan2(u.dot(&self.pole))
    }

    /// $\alpha - \angle(u, p)$ \[rad\]: positive inside the patch.
    pub fn margin(&self, tip_rotation: &Matrix3<f64>, n: &Vector3<f64>) -> f64 {
        self.alpha - self.angle_from_pole(tip_rotation, n)
    }

    /// Whether the contact lies in the patch with `margin` \[rad\] to spare.
    pub fn contains(&self, tip_rotation: &Matrix3<f64>, n: &Vector3<f64>, margin: f64) -> bool {
        self.margin(tip_rotation, n) >= margin
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hemisphere_below_the_tip_frame() {
        let p = TipPatch {
            pole: -Vector3::z_axis(),
            alpha: std::f64::consts::FRAC_PI_2,
        };
        let id = Matrix3::identity();
        // Object below the tip (normal points up at the tip): contact at the pole.
        assert!((p.margin(&id, &Vector3::z()) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        // Object beside the tip: contact on the equator, margin 0.
        assert!(p.margin(&id, &Vector3::x()).abs() < 1e-15);
        // Object above: outside.
        assert!(p.margin(&id, &-Vector3::z()) < -1.5);
        // 32° from the pole.
        let a = 32f64.to_radians();
        let n = Vector3::new(a.sin(), 0.0, a.cos());
        assert!((p.angle_from_pole(&id, &n) - a).abs() < 1e-15);
        assert!(p.contains(&id, &n, 58f64.to_radians() - 1e-12));
        assert!(!p.contains(&id, &n, 58f64.to_radians() + 1e-12));
        // A tip turned +90° about x: its pole points along +y in the hand
        // frame, so the contact is at the pole when the object lies on +y
        // of the tip (n = −y at the tip).
        let r = crate::Frame::rotation_about(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
        assert!((p.margin(&r, &-Vector3::y()) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
        assert!((p.margin(&r, &Vector3::y()) + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }
}

//! Seeded random helpers shared by the kinematics and grasp tests (the
//! generator, unit vectors and angles from `test_support::random`).
#![allow(dead_code)]

use nalgebra::{Rotation3, Unit, UnitQuaternion, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;

// Each test binary uses some of these only.
#[allow(unused_imports)]
pub use test_support::random::{angle, rng, unit};

/// A random rotation: uniform axis, angle uniform in [0, π) (not Haar:
/// small angles come more often than uniformly on SO(3); see
/// `test_support::random::haar`).
pub fn rotation(rng: &mut ChaCha8Rng) -> UnitQuaternion<f64> {
    let axis = unit(rng);
    let angle = rng.random_range(0.0..std::f64::consts::PI);
    UnitQuaternion::from_scaled_axis(axis * angle)
}

/// A fingertip orientation (relative to the object) that touches the
/// object contact `n` with the fingertip contact `m` (both unit), with a
/// random twist about the contact normal.
pub fn touching(rng: &mut ChaCha8Rng, n: &Vector3<f64>, m: &Vector3<f64>) -> UnitQuaternion<f64> {
    // q m = −n: align, then twist about n.
    let align = UnitQuaternion::rotation_between(m, &(-n))
        .unwrap_or_else(|| UnitQuaternion::from_scaled_axis(any_perp(m) * std::f64::consts::PI));
    let twist = UnitQuaternion::from_scaled_axis(n * rng.random_range(-3.0..3.0));
    twist * align
}

fn any_perp(m: &Vector3<f64>) -> Vector3<f64> {
    let e = if m.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    m.cross(&e).normalize()
}

/// A random point of the closed upper hemisphere (z ≥ 0).
pub fn hemisphere_point(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    let v = unit(rng);
    Vector3::new(v.x, v.y, v.z.abs())
}

/// A unit vector perpendicular to `n`, uniform on that circle.
pub fn perpendicular(rng: &mut ChaCha8Rng, n: &Vector3<f64>) -> Vector3<f64> {
    loop {
        let v = unit(rng);
        let p = v - n * n.dot(&v);
        if p.norm() > 0.1 {
            return p.normalize();
        }
    }
}

/// `n` turned by `angle` towards a random perpendicular direction.
pub fn at_angle(rng: &mut ChaCha8Rng, n: &Vector3<f64>, angle: f64) -> Vector3<f64> {
    let axis = Unit::new_normalize(n.cross(&perpendicular(rng, n)));
    Rotation3::from_axis_angle(&axis, angle) * n
}

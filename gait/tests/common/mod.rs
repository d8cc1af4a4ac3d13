//! Seeded random geometry shared by the integration tests.
#![allow(dead_code)]

use nalgebra::{Rotation3, Unit, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A deterministic generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// Uniform unit vector (rejection from the cube).
pub fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
    loop {
        let v = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let n = v.norm();
        if n > 0.1 && n <= 1.0 {
            return v / n;
        }
    }
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

/// Angle between two vectors.
pub fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

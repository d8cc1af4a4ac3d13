//! Seeded random draws the tests of several crates share (feature
//! `random`): one generator, unit vectors, Haar-random rotations, and the
//! angle between two directions.
//!
//! Each draw is the one its tests were written with, so that a seed
//! still picks the same cases.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The tests' seeded generator.
pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// A unit vector uniform on the sphere: a point uniform in the unit ball,
/// normalised (points near the centre redrawn, whose direction rounding
/// would bias).
pub fn unit(rng: &mut impl Rng) -> Vector3<f64> {
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

/// A Haar-random rotation (uniform on SO(3)): a normalised 4-D Gaussian.
pub fn haar(rng: &mut impl Rng) -> UnitQuaternion<f64> {
    loop {
        let mut g = || {
            // Box–Muller.
            let u1: f64 = rng.random_range(1e-300..1.0);
            let u2: f64 = rng.random();
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        };
        let q = Quaternion::new(g(), g(), g(), g());
        if q.norm() > 1e-6 {
            return UnitQuaternion::new_normalize(q);
        }
    }
}

/// Angle between two unit vectors, accurate near 0 and π (where `acos` of
/// the dot product is not).
pub fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_unit_and_cover_every_octant() {
        let mut r = rng(1);
        let mut octants = [0usize; 8];
        for _ in 0..4000 {
            let v = unit(&mut r);
            assert!((v.norm() - 1.0).abs() < 1e-12);
            let k =
                usize::from(v.x > 0.0) | usize::from(v.y > 0.0) << 1 | usize::from(v.z > 0.0) << 2;
            octants[k] += 1;
        }
        // 500 expected in each: a draw that favoured a direction would not
        // stay within ±20 %.
        assert!(
            octants.iter().all(|&n| (400..600).contains(&n)),
            "{octants:?}"
        );
    }

    #[test]
    fn haar_rotations_turn_by_the_haar_angle_law() {
        // Under the Haar measure the rotation angle θ has density
        // (1 − cos θ)/π: its mean is π/2 + 2/π.
        let mut r = rng(2);
        let n = 20_000;
        let mean = (0..n).map(|_| haar(&mut r).angle()).sum::<f64>() / n as f64;
        let want = std::f64::consts::FRAC_PI_2 + 2.0 / std::f64::consts::PI;
        assert!((mean - want).abs() < 0.02, "mean angle {mean}, Haar {want}");
    }

    #[test]
    fn the_angle_is_exact_at_its_ends() {
        let x = Vector3::x();
        assert_eq!(angle(&x, &x), 0.0);
        assert_eq!(angle(&x, &-x), std::f64::consts::PI);
        let d: f64 = 1e-9;
        let tilted = Vector3::new(d.cos(), d.sin(), 0.0);
        assert!((angle(&x, &tilted) - d).abs() < 1e-20);
        assert!((angle(&x, &Vector3::y()) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }
}

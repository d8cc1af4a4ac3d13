//! Link capsules and clearance distances (SPEC §14.1 "Workspace": links
//! clear of the object and of the other fingers; capsules are enough).
//!
//! A capsule is the set of points within `radius` of the segment $\[a, b\]$.
//! The description encloses each URDF collision primitive in one: a sphere
//! is a capsule with $a = b$; a cylinder (axis along its local z, length
//! $L$, radius $\rho$) lies inside the capsule on its axis segment with
//! radius $\rho$ (the capsule adds hemispherical caps: conservative); a box
//! inside the capsule along its longest edge with the half-diagonal of the
//! other two as radius. Meshes are left out (listed in
//! [`crate::FingerDescription::ignored_meshes`]).
//!
//! Distances are signed surface gaps: negative means overlap.
//! Segment–segment closest points follow the standard clamped solution
//! (Ericson, *Real-Time Collision Detection*, §5.1.9).

use nalgebra::Vector3;

/// A capsule: points within `radius` of the segment from `a` to `b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// One end of the axis segment.
    pub a: Vector3<f64>,
    /// The other end.
    pub b: Vector3<f64>,
    /// Radius \[m\].
    pub radius: f64,
}

/// A capsule attached to a chain segment, in that segment's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkCapsule {
    /// 0: fixed to the base; i ≥ 1: moved by revolute joint i (1-based).
    pub segment: usize,
    /// The capsule in the segment's frame (the base frame, or joint i's frame).
    pub capsule: Capsule,
}

impl Capsule {
    /// A zero-size capsule (a point), used to fill fixed-size arrays.
    pub const POINT: Capsule = Capsule {
        a: Vector3::new(0.0, 0.0, 0.0),
        b: Vector3::new(0.0, 0.0, 0.0),
        radius: 0.0,
    };

    /// Gap between this capsule and a sphere (centre `c`, radius `rho`).
    pub fn sphere_gap(&self, c: &Vector3<f64>, rho: f64) -> f64 {
        (c - closest_on_segment(&self.a, &self.b, c)).norm() - self.radius - rho
    }

    /// Gap between two capsules.
    pub fn capsule_gap(&self, o: &Capsule) -> f64 {
        segment_distance(&self.a, &self.b, &o.a, &o.b) - self.radius - o.radius
    }
}

/// The point of segment \[a, b\] closest to `p`.
pub fn closest_on_segment(a: &Vector3<f64>, b: &Vector3<f64>, p: &Vector3<f64>) -> Vector3<f64> {
    let d = b - a;
    let dd = d.norm_squared();
    if dd <= 0.0 {
        return *a;
    }
    a + d * ((p - a).dot(&d) / dd).clamp(0.0, 1.0)
}

/// The distance between segments \[p1, q1\] and \[p2, q2\].
pub fn segment_distance(
    p1: &Vector3<f64>,
    q1: &Vector3<f64>,
    p2: &Vector3<f64>,
    q2: &Vector3<f64>,
) -> f64 {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t);
    if a <= f64::EPSILON && e <= f64::EPSILON {
        return r.norm();
    }
    if a <= f64::EPSILON {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= f64::EPSILON {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let s0 = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            } else {
                t = t0;
                s = s0;
            }
        }
    }
    ((p1 + d1 * s) - (p2 + d2 * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Independent: the distance from a point of segment 1 to segment 2 is
    /// convex along segment 1, so a ternary search finds its minimum.
    fn brute(p1: &Vector3<f64>, q1: &Vector3<f64>, p2: &Vector3<f64>, q2: &Vector3<f64>) -> f64 {
        let at = |s: f64| {
            let x = p1 + (q1 - p1) * s;
            (x - closest_on_segment(p2, q2, &x)).norm()
        };
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..200 {
            let (a, b) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if at(a) <= at(b) { hi = b } else { lo = a }
        }
        at(0.5 * (lo + hi))
    }

    #[test]
    fn segment_distance_matches_brute_force() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut v = || {
            Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        for _ in 0..300 {
            let (p1, q1, p2, q2) = (v(), v(), v(), v());
            let d = segment_distance(&p1, &q1, &p2, &q2);
            let b = brute(&p1, &q1, &p2, &q2);
            // The grid overestimates by at most half a step times the length.
            assert!(
                d <= b + 1e-12 && b - d < 2e-5 * (q1 - p1).norm().max(1.0),
                "{d} {b}"
            );
        }
        // Parallel and degenerate segments.
        let (o, x) = (Vector3::zeros(), Vector3::x());
        assert!(
            (segment_distance(&o, &x, &(o + Vector3::y()), &(x + Vector3::y())) - 1.0).abs()
                < 1e-15
        );
        assert!(
            (segment_distance(
                &o,
                &o,
                &Vector3::new(2.0, 1.0, 0.0),
                &Vector3::new(3.0, 1.0, 0.0)
            ) - 5f64.sqrt())
            .abs()
                < 1e-15
        );
    }

    #[test]
    fn gaps() {
        let c = Capsule {
            a: Vector3::zeros(),
            b: Vector3::new(0.0, 0.0, 1.0),
            radius: 0.1,
        };
        assert!((c.sphere_gap(&Vector3::new(1.0, 0.0, 0.5), 0.2) - 0.7).abs() < 1e-15);
        assert!((c.sphere_gap(&Vector3::new(0.0, 0.0, 2.0), 0.2) - 0.7).abs() < 1e-15);
        let d = Capsule {
            a: Vector3::new(0.5, -1.0, 0.5),
            b: Vector3::new(0.5, 1.0, 0.5),
            radius: 0.05,
        };
        assert!((c.capsule_gap(&d) - 0.35).abs() < 1e-15);
    }
}

//! Closed-form force-closure facts for a sphere (paper §3.1, SPEC.md §3.1).
//!
//! Every function takes contact points as outward normals of the object
//! sphere (hand frame); only directions matter, so the radius never enters
//! (a non-unit argument is fine: angles are computed scale-free with
//! `atan2(|a × b|, a · b)`). θ is the friction angle, μ = tan θ. Slacks are
//! signed angles in radians: positive inside, negative outside, zero on the
//! boundary. All functions are allocation-free and branch-light: they are
//! the fast path of the invariant check (SPEC §1.3 I1).

use core::f64::consts::{FRAC_PI_2, PI};

use nalgebra::{Rotation3, Unit, Vector3};

use super::contact::ContactFrame;

/// Angle between two vectors in \[0, π\], accurate at 0 and π.
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Direct definition of the force-closure region of a contact p (paper §3.1):
/// q lies in it when the chord from p to q is inside the friction cone at
/// p, i.e. angle(q − p, O − p) ≤ θ. `p`, `q` are unit normals. A zero chord
/// (q = p) is outside.
pub fn friction_region_contains(p: &Vector3<f64>, q: &Vector3<f64>, theta: f64) -> bool {
    let chord = q - p;
    if chord.norm() <= 1e-12 {
        return false;
    }
    angle_between(&chord, &(-p)) <= theta
}

/// Fact 1: the force-closure region of p is the cap of half angle 2θ around
/// the antipode −p, i.e. q is in it iff angle(q, −p) ≤ 2θ (inscribed angle
/// theorem). Same set as [`friction_region_contains`].
pub fn fact1_region_contains(p: &Vector3<f64>, q: &Vector3<f64>, theta: f64) -> bool {
    angle_between(q, &(-p)) <= 2.0 * theta
}

/// A spherical cap: unit directions within `half_angle` of `centre`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cap {
    /// Unit centre direction.
    pub centre: Vector3<f64>,
    /// Half angle \[rad\].
    pub half_angle: f64,
}

impl Cap {
    /// Whether direction `q` lies in the (closed) cap.
    pub fn contains(&self, q: &Vector3<f64>) -> bool {
        angle_between(q, &self.centre) <= self.half_angle
    }
}

/// Fact 2: a maximal independent force-closure region pair: the caps of
/// half angle θ around `axis` and `−axis`. Any contact in one cap and any in
/// the other form a two-soft-finger force-closure grasp (Fact 3 holds,
/// possibly on its boundary), and neither cap can be enlarged.
pub fn fact2_regions(axis: &Vector3<f64>, theta: f64) -> [Cap; 2] {
    let a = axis.normalize();
    [
        Cap {
            centre: a,
            half_angle: theta,
        },
        Cap {
            centre: -a,
            half_angle: theta,
        },
    ]
}

/// Fact 2 as a predicate: `p1` and `p2` lie in opposite caps of
/// [`fact2_regions`]`(axis, θ)` (in either order).
pub fn fact2_contains(
    axis: &Vector3<f64>,
    theta: f64,
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
) -> bool {
    let [a, b] = fact2_regions(axis, theta);
    (a.contains(p1) && b.contains(p2)) || (a.contains(p2) && b.contains(p1))
}

/// Separation angle π − 2θ + margin that Fact 3 asks two soft contacts for.
pub fn fact3_bound(theta: f64, margin: f64) -> f64 {
    PI - 2.0 * theta + margin
}

/// Fact 3 slack \[rad\]: angle(p1, p2) − (π − 2θ + margin). Two soft-finger
/// contacts are force-closure with angle margin `margin` iff it is > 0
/// (|p1 − p2| ≥ 2R cos θ is the paper's form, at margin 0).
pub fn fact3_slack(p1: &Vector3<f64>, p2: &Vector3<f64>, theta: f64, margin: f64) -> f64 {
    angle_between(p1, p2) - fact3_bound(theta, margin)
}

/// Fact 3 with the strict inequality (SPEC §3.1): two soft contacts are
/// force-closure with angle margin `margin` iff their separation exceeds
/// π − 2θ + margin.
pub fn fact3_force_closure(p1: &Vector3<f64>, p2: &Vector3<f64>, theta: f64, margin: f64) -> bool {
    fact3_slack(p1, p2, theta, margin) > 0.0
}

/// The shortest way for two contacts to satisfy Fact 3 with `margin`
/// (paper §3.1, Fig. 1): move both along GC(p1, p2), each towards the
/// other's antipode, by half the missing angle. Returns the new unit
/// normals; unchanged (normalised) inputs when Fact 3 already holds with
/// slack ≥ 0. For coincident points any great circle through them serves;
/// a deterministic one is picked.
pub fn fact3_shortest_fix(
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
    theta: f64,
    margin: f64,
) -> [Vector3<f64>; 2] {
    let a = p1.normalize();
    let b = p2.normalize();
    let slack = fact3_slack(&a, &b, theta, margin);
    if slack >= 0.0 {
        return [a, b];
    }
    let k = a.cross(&b);
    let axis = if k.norm() > 1e-12 {
        Unit::new_normalize(k)
    } else {
        Unit::new_unchecked(ContactFrame::new(&a).t1)
    };
    // b = rot(axis, α) a: turning a by −δ/2 and b by +δ/2 opens the angle.
    let half = -0.5 * slack;
    [
        Rotation3::from_axis_angle(&axis, -half) * a,
        Rotation3::from_axis_angle(&axis, half) * b,
    ]
}

/// Fact 4 slack \[rad\] of three hard contacts with friction angle θ:
/// min(π/2 − largest angle of the chordal triangle,
///     θ − asin(h)), h the distance from O to the triangle's plane on the
/// unit sphere. The second term is the tilt margin of the in-plane forces
/// aimed at the circumcentre (their angle to the normal is asin h), so both
/// terms are angles. Fact 4 holds iff the slack is > 0. A degenerate
/// triangle (two points coincide) gets −π/2.
pub fn fact4_slack(p1: &Vector3<f64>, p2: &Vector3<f64>, p3: &Vector3<f64>, theta: f64) -> f64 {
    let (a, b, c) = (p1.normalize(), p2.normalize(), p3.normalize());
    let normal = (b - a).cross(&(c - a));
    let area2 = normal.norm();
    // Also catches NaN (comparison false).
    if area2.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater) {
        return -FRAC_PI_2;
    }
    let h = (normal.dot(&a) / area2).abs().min(1.0);
    let va = angle_between(&(b - a), &(c - a));
    let vb = angle_between(&(a - b), &(c - b));
    let vc = PI - va - vb;
    let acute = FRAC_PI_2 - va.max(vb).max(vc);
    acute.min(theta - h.asin())
}

/// Fact 4 (sufficient): three hard contacts are force-closure if their
/// triangle is acute and O is closer to its plane than R sin θ.
pub fn fact4_force_closure(
    p1: &Vector3<f64>,
    p2: &Vector3<f64>,
    p3: &Vector3<f64>,
    theta: f64,
) -> bool {
    fact4_slack(p1, p2, p3, theta) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    const THETA: f64 = 20.0 * PI / 180.0;

    fn equator(deg: f64) -> Vector3<f64> {
        let a = deg.to_radians();
        Vector3::new(a.cos(), a.sin(), 0.0)
    }

    #[test]
    fn fact3_bound_is_140_degrees_at_20() {
        assert!((fact3_bound(THETA, 0.0).to_degrees() - 140.0).abs() < 1e-12);
        assert!(fact3_force_closure(
            &equator(0.0),
            &equator(141.0),
            THETA,
            0.0
        ));
        assert!(!fact3_force_closure(
            &equator(0.0),
            &equator(139.0),
            THETA,
            0.0
        ));
        assert!(!fact3_force_closure(
            &equator(0.0),
            &equator(141.0),
            THETA,
            2f64.to_radians()
        ));
    }

    #[test]
    fn paper_start_is_fact4_but_no_pair() {
        let p = [equator(0.0), equator(120.0), equator(240.0)];
        assert!(fact4_force_closure(&p[0], &p[1], &p[2], THETA));
        assert!(!fact3_force_closure(&p[0], &p[1], THETA, 0.0));
        // Equilateral on a great circle: slack is min(30°, θ).
        let s = fact4_slack(&p[0], &p[1], &p[2], THETA);
        assert!((s - THETA).abs() < 1e-12, "{s}");
    }

    #[test]
    fn shortest_fix_lands_on_the_margin_symmetrically() {
        let (a, b) = (equator(10.0), equator(100.0));
        let m = 2f64.to_radians();
        let [a2, b2] = fact3_shortest_fix(&a, &b, THETA, m);
        assert!(fact3_slack(&a2, &b2, THETA, m).abs() < 1e-12);
        let moved_a = angle_between(&a, &a2);
        let moved_b = angle_between(&b, &b2);
        assert!((moved_a - moved_b).abs() < 1e-12);
        assert!(a2.z.abs() < 1e-12 && b2.z.abs() < 1e-12);
        let [c, d] = fact3_shortest_fix(&a, &a, THETA, m);
        assert!(fact3_slack(&c, &d, THETA, m).abs() < 1e-12);
    }
}

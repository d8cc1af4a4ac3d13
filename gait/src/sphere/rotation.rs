//! Exact helpers on S² and SO(3): rotations about an axis (Rodrigues),
//! great-circle arcs, robust angles, and the inverse differential of the
//! exponential map used by the Runge–Kutta–Munthe-Kaas integrator
//! (SPEC §2.3: integrate on SO(3), never by adding to quaternion components).

use nalgebra::{Unit, UnitQuaternion, Vector3};

/// Rotates `v` about the unit axis `k` by `angle` (Rodrigues' formula).
pub fn rotate(k: &Vector3<f64>, angle: f64, v: &Vector3<f64>) -> Vector3<f64> {
    let (s, c) = angle.sin_cos();
    v * c + k.cross(v) * s + k * (k.dot(v) * (1.0 - c))
}

/// The rotation about the unit axis `k` by `angle`, as a unit quaternion.
pub fn axis_angle(k: &Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Unit::new_unchecked(*k), angle)
}

/// The angle between two non-zero vectors, in [0, π] (atan2 form: accurate
/// for nearly parallel and nearly opposite vectors alike).
pub fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

/// A unit vector perpendicular to the unit vector `n`, chosen
/// deterministically (used where a great circle is not unique, e.g. between
/// antipodal points — the paper's remark in §3.1 that any such circle does).
pub fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let e = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        Vector3::x()
    } else if n.y.abs() <= n.z.abs() {
        Vector3::y()
    } else {
        Vector3::z()
    };
    n.cross(&e).normalize()
}

/// The unit tangent at the unit vector `from` pointing along the great
/// circle towards `to` (any perpendicular if they are equal or opposite).
pub fn tangent_towards(from: &Vector3<f64>, to: &Vector3<f64>) -> Vector3<f64> {
    let t = to - from * from.dot(to);
    let norm = t.norm();
    if norm > 1e-300 && from.cross(to).norm() > 1e-15 {
        t / norm
    } else {
        any_perpendicular(from)
    }
}

/// Inverse differential of the exponential map of SO(3), left
/// trivialisation: for Q(t) = exp(Ω(t)) Q₀ with Q̇ = \[ω\]× Q, Ω̇ = dexp⁻¹_Ω(ω)
/// = ω − ½ Ω × ω + (1/θ²)(1 − (θ/2) cot(θ/2)) Ω × (Ω × ω), θ = |Ω|.
pub fn dexp_inv(omega_big: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    let th2 = omega_big.norm_squared();
    // Series of (1 − (θ/2)cot(θ/2))/θ² = 1/12 + θ²/720 + θ⁴/30240 + … for small θ.
    let c = if th2 < 1e-4 {
        1.0 / 12.0 + th2 / 720.0 + th2 * th2 / 30240.0
    } else {
        let th = th2.sqrt();
        let half = 0.5 * th;
        (1.0 - half * half.cos() / half.sin()) / th2
    };
    let ow = omega_big.cross(w);
    w - ow * 0.5 + omega_big.cross(&ow) * c
}

/// exp of the rotation vector `omega_big` as a unit quaternion.
pub fn exp(omega_big: &Vector3<f64>) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(*omega_big)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_matches_quaternion() {
        let k = Vector3::new(1.0, -2.0, 0.5).normalize();
        let v = Vector3::new(0.3, 0.1, -0.7);
        for a in [0.0, 0.1, 1.0, 3.0, -2.0] {
            assert!((rotate(&k, a, &v) - axis_angle(&k, a) * v).norm() < 1e-15);
        }
    }

    #[test]
    fn dexp_inv_inverts_the_differential_of_exp() {
        // d/dε exp(Ω + ε δ) exp(Ω)⁻¹ at ε = 0 is dexp_Ω(δ); check
        // dexp_inv(dexp(δ)) = δ by finite differences.
        let big = Vector3::new(0.4, -0.9, 0.3);
        let d = Vector3::new(0.2, 0.1, -0.5);
        let eps = 1e-6;
        let q1 = exp(&(big + d * eps));
        let q0 = exp(&(big - d * eps));
        let w = (q1 * q0.inverse()).scaled_axis() / (2.0 * eps);
        assert!((dexp_inv(&big, &w) - d).norm() < 1e-8);
        // Small-angle branch agrees with the closed form near the switch.
        let small: Vector3<f64> = Vector3::new(0.006, 0.004, -0.007);
        let w2 = Vector3::new(1.0, 2.0, 3.0);
        let th2 = small.norm_squared();
        let th = th2.sqrt();
        let c = (1.0 - 0.5 * th / (0.5 * th).tan()) / th2;
        let exact = w2 - small.cross(&w2) * 0.5 + small.cross(&small.cross(&w2)) * c;
        assert!((dexp_inv(&small, &w2) - exact).norm() < 1e-12);
    }
}

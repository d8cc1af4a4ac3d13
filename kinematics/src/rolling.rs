//! Rolling when the tip's orientation is not free (SPEC §14.2).
//!
//! Object: a sphere of radius R, centre O fixed, angular velocity
//! $\omega_o$. Contact normal $n$ (outward from the object, hand frame);
//! the tip centre is $c = O + (R + r) n$. No slip at the contact:
//! $$\omega_o \times (R n) = \dot c - r\,\omega_f \times n
//!   \iff \dot c = (R\omega_o + r\omega_f) \times n .$$
//! For a 3-joint finger with $J_v$ invertible, $\omega_f = A\dot c$ with
//! $A = J_\omega J_v^{-1}$, so
//! $$(I + r\lbrack n\rbrack_\times A)\,\dot c = R\,(\omega_o \times n),\qquad
//!   \dot c = (I + r\lbrack n\rbrack_\times A)^{-1} R\,(\omega_o \times n),\qquad
//!   \dot q = J_v^{-1}\dot c,$$
//! with $\lbrack n\rbrack_\times v = n \times v$. The object's angular velocity fixes
//! the finger's motion: the contact follows. The relative spin about the
//! normal is what the chain gives:
//! $$s = (\omega_o - \omega_f)\cdot n$$
//! (§14.2's sign; §2.3 writes the fingertip's spin relative to the object,
//! $(\omega_f - \omega_o)\cdot n = -s$).

use nalgebra::{Matrix3, Vector3};

use crate::chain::ChainState;

/// A grasping finger's motion under the rolling law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollingRates {
    /// $\dot c$: tip-centre velocity \[m/s\].
    pub c_dot: Vector3<f64>,
    /// $\dot q$: joint velocities \[rad/s\].
    pub q_dot: Vector3<f64>,
    /// $\omega_f = J_\omega \dot q$: tip angular velocity \[rad/s\].
    pub omega_f: Vector3<f64>,
    /// $s = (\omega_o - \omega_f)\cdot n$: relative spin \[rad/s\].
    pub spin: f64,
}

/// The rolling law of §14.2 for a 3-joint finger at state `s`: object
/// angular velocity `omega_o`, unit contact normal `n`, object radius
/// `object_radius` (R), tip radius `tip_radius` (r).
///
/// `None` where $J_v$ or $I + r\lbrack n\rbrack_\times A$ is singular.
pub fn rolling_rates(
    s: &ChainState<3>,
    omega_o: &Vector3<f64>,
    n: &Vector3<f64>,
    object_radius: f64,
    tip_radius: f64,
) -> Option<RollingRates> {
    let jv = s.jacobian_v();
    let jw = s.jacobian_w();
    let jv_inv = jv.try_inverse()?;
    let a = jw * jv_inv;
    let m = Matrix3::identity() + n.cross_matrix() * a * tip_radius;
    let c_dot = m.lu().solve(&(omega_o.cross(n) * object_radius))?;
    let q_dot = jv_inv * c_dot;
    let omega_f = jw * q_dot;
    Some(RollingRates {
        c_dot,
        q_dot,
        omega_f,
        spin: (omega_o - omega_f).dot(n),
    })
}

//! Montana's contact equations in chart coordinates (SPEC §2.2, paper
//! eq. (3), (4)).
//!
//! A contact is described by the chart coordinates of its point on the
//! fingertip, $\alpha_f = (u_f, v_f)$, and on the object,
//! $\alpha_o = (u_o, v_o)$, and by the contact angle $\psi$ between the two
//! Gauss frames ([`ChartContact`]). The fingertip moves relative to the
//! object with linear velocity $(v_x, v_y, v_z)$ and angular velocity
//! $(\omega_x, \omega_y, \omega_z)$, both in the fingertip contact frame
//! $C_f$ ([`ContactTwist`]; $v_z = 0$ while the contact holds). On a
//! sphere of radius $\rho$ ($\rho = r$ for the fingertip, $R$ for the
//! object), at latitude $u$ of its chart, the metric, curvature and torsion
//! forms are
//!
//! $$M = \begin{bmatrix} \rho & 0 \\\\ 0 & \rho \cos u \end{bmatrix}, \qquad
//! K = \begin{bmatrix} 1/\rho & 0 \\\\ 0 & 1/\rho \end{bmatrix}, \qquad
//! T = \begin{bmatrix} 0 & -\tan(u)/\rho \end{bmatrix}.$$
//!
//! Montana's equations ([`montana`]), with
//! $\tilde K_o = R_\psi K_o R_\psi$ the object's curvature seen in $C_f$:
//!
//! $$\dot\alpha_f = M_f^{-1} \left(K_f + \tilde K_o\right)^{-1}
//! \left( \begin{bmatrix} -\omega_y \\\\ \omega_x \end{bmatrix} -
//! \tilde K_o \begin{bmatrix} v_x \\\\ v_y \end{bmatrix} \right),$$
//!
//! $$\dot\alpha_o = M_o^{-1} R_\psi \left(K_f + \tilde K_o\right)^{-1}
//! \left( \begin{bmatrix} -\omega_y \\\\ \omega_x \end{bmatrix} +
//! K_f \begin{bmatrix} v_x \\\\ v_y \end{bmatrix} \right),$$
//!
//! $$\dot\psi = \omega_z + T_f M_f \dot\alpha_f + T_o M_o \dot\alpha_o,
//! \qquad
//! R_\psi = \begin{bmatrix} \cos\psi & -\sin\psi \\\\ -\sin\psi & -\cos\psi \end{bmatrix}.$$
//!
//! $R_\psi$ ([`r_psi`]) maps tangent coordinates in $C_f$ to coordinates in
//! $C_o$; it is a reflection, $R_\psi^2 = I$. Pure rolling is $v = 0$,
//! $\omega_z = 0$ (paper eq. (3)); for two spheres the contact points then
//! move by paper eq. (4) ([`rolling_finger_rates`],
//! [`rolling_object_rates`]),
//!
//! $$\dot\alpha_f = M_f^{-1} R_\psi M_o \dot\alpha_o
//! \quad\Longleftrightarrow\quad
//! \dot\alpha_o = M_o^{-1} R_\psi M_f \dot\alpha_f,$$
//!
//! which gives the paper's Theory 2: a great circle on one sphere rolls
//! onto a great circle on the other, and from $(0, 0, 0, 0, 0)$ moving the
//! fingertip contact to $(0, \Delta v)$ moves the object contact to
//! $(0, -\tfrac{r}{R} \Delta v)$.

use super::state::ContactGeometry;
use crate::sphere::{ChartPoint, curvature, metric, torsion};
use nalgebra::{Matrix2, Vector2, Vector3};

/// Contact coordinates (α_f, α_o, ψ) of SPEC §2.2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartContact {
    /// α_f = (u_f, v_f): contact point on the fingertip, fingertip chart.
    pub finger: ChartPoint,
    /// α_o = (u_o, v_o): contact point on the object, object chart.
    pub object: ChartPoint,
    /// Contact angle ψ between the two Gauss frames \[rad\]
    /// (x_o = cos ψ x_f − sin ψ y_f, see the module docs of [`crate::contact`]).
    pub psi: f64,
}

/// Relative motion of the fingertip with respect to the object, in the
/// fingertip contact frame C_f (Montana's (v, ω), SPEC §2.2).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactTwist {
    /// (v_x, v_y, v_z): slip velocity \[m/s\]; v_z must be 0 (contact kept)
    /// and is ignored.
    pub linear: Vector3<f64>,
    /// (ω_x, ω_y, ω_z): relative angular velocity \[rad/s\]; ω_z is the spin.
    pub angular: Vector3<f64>,
}

/// Rates of the contact coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartRates {
    /// α̇_f = (u̇_f, v̇_f).
    pub finger: Vector2<f64>,
    /// α̇_o = (u̇_o, v̇_o).
    pub object: Vector2<f64>,
    /// ψ̇.
    pub psi: f64,
}

/// $R_\psi = \begin{bmatrix} \cos\psi & -\sin\psi \\\\ -\sin\psi & -\cos\psi \end{bmatrix}$
/// (SPEC §2.2): maps tangent coordinates in $C_f$ to coordinates in $C_o$
/// (a reflection: $R_\psi^2 = I$).
pub fn r_psi(psi: f64) -> Matrix2<f64> {
    let (s, c) = psi.sin_cos();
    Matrix2::new(c, -s, -s, -c)
}

/// Montana's equations in the general form of the module docs (SPEC
/// §2.2): the rates $(\dot\alpha_f, \dot\alpha_o, \dot\psi)$ of contact `c`
/// under the relative motion `twist`. Singular only where a chart is
/// ($|u| = \pi/2$), never used there: the atlas keeps $|u| \le 60°$.
pub fn montana(geom: &ContactGeometry, c: &ChartContact, twist: &ContactTwist) -> ChartRates {
    let (rf, ro) = (geom.fingertip_radius, geom.object_radius);
    let (uf, uo) = (c.finger.u, c.object.u);
    let rp = r_psi(c.psi);
    let kf = curvature(rf);
    let ko_t = rp * curvature(ro) * rp;
    // K_f + K̃_o is symmetric positive definite for two convex bodies.
    let inv_k = (kf + ko_t).try_inverse().unwrap_or_else(Matrix2::zeros);
    let w = Vector2::new(-twist.angular.y, twist.angular.x);
    let v = Vector2::new(twist.linear.x, twist.linear.y);
    let mf = metric(rf, uf);
    let mo = metric(ro, uo);
    let mf_inv = Matrix2::new(1.0 / mf[(0, 0)], 0.0, 0.0, 1.0 / mf[(1, 1)]);
    let mo_inv = Matrix2::new(1.0 / mo[(0, 0)], 0.0, 0.0, 1.0 / mo[(1, 1)]);
    let af = mf_inv * inv_k * (w - ko_t * v);
    let ao = mo_inv * rp * inv_k * (w + kf * v);
    let psi = twist.angular.z + (torsion(rf, uf) * mf * af)[0] + (torsion(ro, uo) * mo * ao)[0];
    ChartRates {
        finger: af,
        object: ao,
        psi,
    }
}

/// Sphere–sphere pure rolling, paper eq. (4):
/// $\dot\alpha_f = M_f^{-1} R_\psi M_o \dot\alpha_o$.
pub fn rolling_finger_rates(
    geom: &ContactGeometry,
    c: &ChartContact,
    object_rate: &Vector2<f64>,
) -> Vector2<f64> {
    let mf = metric(geom.fingertip_radius, c.finger.u);
    let mo = metric(geom.object_radius, c.object.u);
    let t = r_psi(c.psi) * (mo * object_rate);
    Vector2::new(t.x / mf[(0, 0)], t.y / mf[(1, 1)])
}

/// The inverse of eq. (4) ($R_\psi$ is an involution):
/// $\dot\alpha_o = M_o^{-1} R_\psi M_f \dot\alpha_f$.
pub fn rolling_object_rates(
    geom: &ContactGeometry,
    c: &ChartContact,
    finger_rate: &Vector2<f64>,
) -> Vector2<f64> {
    let mf = metric(geom.fingertip_radius, c.finger.u);
    let mo = metric(geom.object_radius, c.object.u);
    let t = r_psi(c.psi) * (mf * finger_rate);
    Vector2::new(t.x / mo[(0, 0)], t.y / mo[(1, 1)])
}

/// $\dot\psi = T_f M_f \dot\alpha_f + T_o M_o \dot\alpha_o$: the contact
/// angle's rate for pure rolling ($\omega_z = 0$) given both coordinate
/// rates.
pub fn rolling_psi_rate(
    geom: &ContactGeometry,
    c: &ChartContact,
    finger_rate: &Vector2<f64>,
    object_rate: &Vector2<f64>,
) -> f64 {
    let (rf, ro) = (geom.fingertip_radius, geom.object_radius);
    (torsion(rf, c.finger.u) * metric(rf, c.finger.u) * finger_rate)[0]
        + (torsion(ro, c.object.u) * metric(ro, c.object.u) * object_rate)[0]
}

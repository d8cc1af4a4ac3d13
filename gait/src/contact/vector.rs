//! The coordinate-free vector form of the contact kinematics (SPEC §2.3),
//! extended with slip, and the map between hand-frame body rates and
//! Montana's contact-frame twist.
//!
//! Hand frame, object centre fixed at the origin. $n$ is the outward
//! object normal at the contact (a unit vector), $\omega_o$ and $\omega_f$
//! the angular velocities of object and fingertip, $Q_o$ and $Q_f$ their
//! orientations, $R$ and $r$ their radii; the fingertip centre is
//! $p_f = (R + r) n$, the contact point is $n_o = Q_o^\top n$ on the object
//! (object frame) and $m = Q_f^\top (-n)$ on the fingertip (fingertip
//! frame). For pure rolling (SPEC §2.3):
//!
//! $$\dot n = \frac{(R \omega_o + r \omega_f) \times n}{R + r}, \qquad
//! \dot n_o = \frac{r}{R + r} Q_o^\top \big( (\omega_f - \omega_o) \times n \big), \qquad
//! \dot m = \frac{R}{R + r} Q_f^\top \big( (\omega_f - \omega_o) \times n \big),$$
//!
//! with spin $s = (\omega_f - \omega_o) \cdot n$ (zero when rolling) and
//! roll rate $\dot\tau = \omega_f \cdot (Q_f e_z)$ about the fingertip's
//! pole axis ([`contact_rates`]).
//!
//! Derivation, with slip. Let $v_s = v_{fp} - v_{op}$ be the velocity of
//! the fingertip's material point at the contact relative to the object's
//! (tangent to the surface), where $v_{fp} = \dot p_f + \omega_f \times (-r n)$
//! and $v_{op} = \omega_o \times (R n)$. Then
//!
//! $$\dot n = \frac{(R \omega_o + r \omega_f) \times n + v_s}{R + r},$$
//!
//! $$\dot n_o = Q_o^\top \left( \dot n - \omega_o \times n \right)
//! = Q_o^\top \frac{r (\omega_f - \omega_o) \times n + v_s}{R + r},$$
//!
//! $$\dot m = -Q_f^\top \left( \dot n - \omega_f \times n \right)
//! = Q_f^\top \frac{R (\omega_f - \omega_o) \times n - v_s}{R + r}.$$
//!
//! With $v_s = 0$ these are SPEC §2.3 exactly (no sign error found).
//! Rolling without slip, both contact points move at the same speed,
//! $\frac{r R}{R + r} \left\lvert (\omega_f - \omega_o) \times n \right\rvert$:
//! equal arc lengths. Montana's twist is this relative motion seen in the
//! fingertip contact frame $C_f$: $\omega = C_f^\top (\omega_f - \omega_o)$,
//! $v = C_f^\top v_s$ ([`twist_from_body_rates`], [`body_rates_from_twist`]).

use super::montana::ContactTwist;
use super::state::{ContactGeometry, ContactState};
use crate::sphere::ChartId;
use nalgebra::Vector3;

/// Angular velocities of both bodies and the slip, hand frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BodyRates {
    /// ω_o: object angular velocity \[rad/s\].
    pub object: Vector3<f64>,
    /// ω_f: fingertip angular velocity \[rad/s\].
    pub fingertip: Vector3<f64>,
    /// v_s: velocity of the fingertip's material point at the contact
    /// relative to the object's \[m/s\]; its normal component is ignored.
    /// Zero for rolling (SPEC §1.2).
    pub slip: Vector3<f64>,
}

/// Rates of the contact (SPEC §2.3), hand frame unless stated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRates {
    /// ṅ: contact normal.
    pub normal: Vector3<f64>,
    /// ṗ_f = (R + r) ṅ: fingertip centre \[m/s\].
    pub center: Vector3<f64>,
    /// ṅ_o: contact point on the object, object frame.
    pub object_contact: Vector3<f64>,
    /// ṁ: contact point on the fingertip, fingertip frame.
    pub fingertip_contact: Vector3<f64>,
    /// Spin s = (ω_f − ω_o) · n \[rad/s\] (zero for pure rolling).
    pub spin: f64,
    /// τ̇ = ω_f · (Q_f e_z) \[rad/s\].
    pub roll: f64,
}

/// The tangential part of `v` at the unit normal `n`.
fn tangential(v: &Vector3<f64>, n: &Vector3<f64>) -> Vector3<f64> {
    v - n * n.dot(v)
}

/// Rates of the contact state under `rates` (SPEC §2.3, with slip).
pub fn contact_rates(geom: &ContactGeometry, s: &ContactState, rates: &BodyRates) -> ContactRates {
    let (big, small) = (geom.object_radius, geom.fingertip_radius);
    let d = geom.center_distance();
    let n = &s.normal;
    let rel = rates.fingertip - rates.object;
    let vs = tangential(&rates.slip, n);
    let normal = ((rates.object * big + rates.fingertip * small).cross(n) + vs) / d;
    let rel_n = rel.cross(n);
    ContactRates {
        normal,
        center: normal * d,
        object_contact: s.object.inverse() * ((rel_n * small + vs) / d),
        fingertip_contact: s.fingertip.inverse() * ((rel_n * big - vs) / d),
        spin: rel.dot(n),
        roll: rates.fingertip.dot(&s.pole_axis()),
    }
}

/// Montana's twist (v, ω) of the fingertip relative to the object in C_f
/// (fingertip Gauss frame of chart `finger_chart`), from hand-frame rates.
pub fn twist_from_body_rates(
    s: &ContactState,
    finger_chart: ChartId,
    rates: &BodyRates,
) -> ContactTwist {
    let cf = s.fingertip_frame(finger_chart);
    let vs = tangential(&rates.slip, &s.normal);
    ContactTwist {
        linear: cf.transpose() * vs,
        angular: cf.transpose() * (rates.fingertip - rates.object),
    }
}

/// Hand-frame rates realising Montana's twist `twist` (in $C_f$ of chart
/// `finger_chart`) while the object turns at `object_rate`:
/// $\omega_f = \omega_o + C_f \omega$, $v_s = C_f (v_x, v_y, 0)$.
pub fn body_rates_from_twist(
    s: &ContactState,
    finger_chart: ChartId,
    object_rate: &Vector3<f64>,
    twist: &ContactTwist,
) -> BodyRates {
    let cf = s.fingertip_frame(finger_chart);
    let v = Vector3::new(twist.linear.x, twist.linear.y, 0.0);
    BodyRates {
        object: *object_rate,
        fingertip: object_rate + cf * twist.angular,
        slip: cf * v,
    }
}

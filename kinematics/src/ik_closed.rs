//! Closed-form inverse kinematics of a TriFingerPro-like 3-joint finger
//! (SPEC §14.3: closed form for 3 joints).
//!
//! Structure required (checked by [`ClosedFormIk::new`]): joint 1's axis
//! $w_1$ is perpendicular to joint 2's $w_2$, and joint 3's axis is
//! parallel (or anti-parallel, $w_3 = \sigma w_2$) to $w_2$. TriFingerPro:
//! upper joint about the finger's y, middle and lower about its x.
//!
//! Product of exponentials at $q = 0$ (hand frame): joint points $p_i$,
//! axes $w_i$, tip centre $t_0$:
//! $$c(q) = p_1 + \mathrm{Rot}(w_1, q_1)\big[p_2 - p_1 + \mathrm{Rot}(w_2, q_2)
//!   \big(p_3 - p_2 + \mathrm{Rot}(w_2, \sigma q_3)(t_0 - p_3)\big)\big].$$
//! For a target $t$, let $d = t - p_1$ and $f = \mathrm{Rot}(w_1, -q_1)d$.
//! Rotations about $w_2$ keep $w_2$-components, so $f\cdot w_2 =
//! (t_0 - p_1)\cdot w_2 =: \kappa$ (TriFingerPro: the 86 mm sideways offset
//! of the tip, upstream's `TIP_X_OFFSET`), and rotation about $w_1$ keeps
//! $f\cdot w_1 = d\cdot w_1$ and the distance from the axis, so
//! $f = (d\cdot w_1)w_1 + \kappa w_2 + h\,(w_1\times w_2)$ with
//! $h = \pm\sqrt{|d_\perp|^2 - \kappa^2}$ — **two branches** (upstream's two
//! tangents); $q_1$ turns $f_\perp$ onto $d_\perp$ about $w_1$.
//! In the plane normal to $w_2$ the rest is a two-link arm of lengths
//! $L_2 = |P(p_3 - p_2)|$, $L_3 = |P(t_0 - p_3)|$ reaching
//! $D = P(f - (p_2 - p_1))$: $\cos\varphi = (|D|^2 - L_2^2 - L_3^2)/(2L_2L_3)$,
//! $\varphi = \pm\arccos$ — **two branches** (elbow) — and
//! $\sigma q_3 = \varphi - \theta_B$,
//! $q_2 = \angle D - \operatorname{atan2}(L_3\sin\varphi, L_2 + L_3\cos\varphi)$,
//! angles measured in the plane from $P(p_3 - p_2)$, $\theta_B$ the angle
//! of $P(t_0 - p_3)$.
//!
//! Of the four branches (each angle taken modulo 2π) those inside the
//! limits with margin are kept, and the one nearest a reference
//! configuration (the current joints) is returned.

use nalgebra::Vector3;

use crate::chain::Chain;

/// Why a target has no admissible solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IkError {
    /// No joint angles put the tip centre there.
    Unreachable,
    /// Solutions exist, none inside the joint limits with margin.
    OutsideLimits,
}

/// The chain does not have the structure of [`ClosedFormIk`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotClosedForm;

/// Closed-form IK for one 3-joint chain (precomputed at q = 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedFormIk {
    p1: Vector3<f64>,
    w1: Vector3<f64>,
    w2: Vector3<f64>,
    w12: Vector3<f64>,
    sigma: f64,
    p21: Vector3<f64>,
    kappa: f64,
    eu: Vector3<f64>,
    ev: Vector3<f64>,
    l2: f64,
    l3: f64,
    theta_b: f64,
    lower: Vector3<f64>,
    upper: Vector3<f64>,
}

/// Up to four raw solutions (angles in (−π, π]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Branches {
    /// The solutions; the first `len` are valid.
    pub q: [Vector3<f64>; 4],
    /// How many.
    pub len: usize,
}

impl ClosedFormIk {
    /// Precomputes the solver for `chain`, or says its structure differs.
    pub fn new(chain: &Chain<3>) -> Result<Self, NotClosedForm> {
        let s = chain.forward(&Vector3::zeros());
        let (w1, w2, w3) = (s.axes[0], s.axes[1], s.axes[2]);
        let (p1, p2, p3) = (
            s.joints[0].translation,
            s.joints[1].translation,
            s.joints[2].translation,
        );
        let t0 = s.tip.translation;
        if w1.dot(&w2).abs() > 1e-9 || w2.cross(&w3).norm() > 1e-9 {
            return Err(NotClosedForm);
        }
        let plane = |x: Vector3<f64>| x - w2 * x.dot(&w2);
        let a = plane(p3 - p2);
        let b = plane(t0 - p3);
        let (l2, l3) = (a.norm(), b.norm());
        if l2 < 1e-9 || l3 < 1e-9 {
            return Err(NotClosedForm);
        }
        let eu = a / l2;
        let ev = w2.cross(&eu);
        Ok(ClosedFormIk {
            p1,
            w1,
            w2,
            w12: w1.cross(&w2),
            sigma: w3.dot(&w2).signum(),
            p21: p2 - p1,
            kappa: (t0 - p1).dot(&w2),
            eu,
            ev,
            l2,
            l3,
            theta_b: b.dot(&ev).atan2(b.dot(&eu)),
            lower: chain.lower(),
            upper: chain.upper(),
        })
    }

    /// Every solution for tip centre `target` (hand frame), limits ignored.
    pub fn branches(&self, target: &Vector3<f64>) -> Branches {
        let mut out = Branches {
            q: [Vector3::zeros(); 4],
            len: 0,
        };
        let d = target - self.p1;
        let dw = d.dot(&self.w1);
        let d_perp = d - self.w1 * dw;
        let h2 = d_perp.norm_squared() - self.kappa * self.kappa;
        if h2 < 0.0 {
            return out;
        }
        for h in [h2.sqrt(), -h2.sqrt()] {
            let f = self.w1 * dw + self.w2 * self.kappa + self.w12 * h;
            let f_perp = f - self.w1 * dw;
            let q1 = self
                .w1
                .dot(&f_perp.cross(&d_perp))
                .atan2(f_perp.dot(&d_perp));
            let g = f - self.p21;
            let (du, dv) = (g.dot(&self.eu), g.dot(&self.ev));
            let dd = du * du + dv * dv;
            let cos_phi = (dd - self.l2 * self.l2 - self.l3 * self.l3) / (2.0 * self.l2 * self.l3);
            if !(-1.0..=1.0).contains(&cos_phi) {
                continue;
            }
            let phi0 = cos_phi.acos();
            for phi in [phi0, -phi0] {
                let q3 = self.sigma * wrap(phi - self.theta_b);
                let inner = (self.l3 * phi.sin()).atan2(self.l2 + self.l3 * phi.cos());
                let q2 = wrap(dv.atan2(du) - inner);
                out.q[out.len] = Vector3::new(q1, q2, q3);
                out.len += 1;
            }
        }
        out
    }

    /// The admissible solution nearest `reference` for tip centre `target`.
    pub fn solve(
        &self,
        target: &Vector3<f64>,
        reference: &Vector3<f64>,
    ) -> Result<Vector3<f64>, IkError> {
        let b = self.branches(target);
        if b.len == 0 {
            return Err(IkError::Unreachable);
        }
        let mut best: Option<(f64, Vector3<f64>)> = None;
        for q in &b.q[..b.len] {
            let Some(q) = self.admissible(q, reference) else {
                continue;
            };
            let dist = (q - reference).norm_squared();
            if best.is_none_or(|(bd, _)| dist < bd) {
                best = Some((dist, q));
            }
        }
        best.map(|(_, q)| q).ok_or(IkError::OutsideLimits)
    }

    /// Per joint, the 2π-shift of `q` inside the limits nearest `reference`.
    fn admissible(&self, q: &Vector3<f64>, reference: &Vector3<f64>) -> Option<Vector3<f64>> {
        let mut out = *q;
        for i in 0..3 {
            let tau = std::f64::consts::TAU;
            // The shifts q + 2πk inside [lo, hi]; the one nearest the reference.
            let k_lo = ((self.lower[i] - q[i]) / tau).ceil();
            let k_hi = ((self.upper[i] - q[i]) / tau).floor();
            if k_lo > k_hi {
                return None;
            }
            let k_ref = ((reference[i] - q[i]) / tau).round().clamp(k_lo, k_hi);
            out[i] = q[i] + tau * k_ref;
        }
        Some(out)
    }
}

/// An angle in (−π, π].
fn wrap(a: f64) -> f64 {
    let t = std::f64::consts::TAU;
    let w = a - t * (a / t).round();
    if w <= -std::f64::consts::PI { w + t } else { w }
}

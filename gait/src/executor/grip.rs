//! Grip forces for the grasping fingers, in closed form, every tick
//! (SPEC §3.3: "closed form allowed for 2 antipodal-ish or 3 contacts on
//! the sphere if it is checked against the SOCP"; the check is
//! `gait/tests/grip_vs_socp.rs`).
//!
//! Contacts at p_i = R n_i push along the inward normal −n_i. The external
//! force E (weight m g plus a disturbance) acts through O; the contacts must
//! also supply the torque T = I α that accelerates the object (a solid
//! sphere, I = (2/5) m R²) — in a two-finger grasp its component along the
//! grasp line only torsional friction can give. Each contact
//! force is a squeeze part (internal: zero net force and torque) plus a
//! load part (the least-norm forces that balance E):
//! - two soft contacts: the squeeze is ±F along the chord u = (p₂ − p₁)/|·|;
//!   the load part splits −E equally and balances the torque of E about
//!   the chord's midpoint c with a force pair ⊥ d = (p₂ − p₁)/2
//!   (d × Δ = (c × E)⊥) and the torsional moments τ = ±R (c × E)·u / 2|d|
//!   about the normals (the soft-finger torsion resists the torque about
//!   the grasp line);
//! - three hard contacts: the squeeze is λ times the sum of the unit chords
//!   to the other two contacts (equal weights), the load part is the
//!   least-norm solution of G f = (−E, 0) (6 × 9 grasp map);
//! - three contacts of which a pair is force-closure on its own (the middle
//!   of a substitution): the pair holds, the third presses with the
//!   minimum grip and the pair balances that push too.
//!
//! Each contact's friction cone, |f_t|² (+ (τ μ/μ_t)²) ≤ μ_g² f_n² with
//! μ_g = tan(θ − margin), is a quadratic inequality in the squeeze
//! magnitude, so the least squeeze is the largest root over contacts and
//! over load scenarios (E = m g, and m g ± d along ±x, ±y, ±z for the
//! disturbance d). Reported normal forces are those of the weight-only
//! scenario at that squeeze. Nothing allocates.

use nalgebra::{Matrix6, SMatrix, Vector3, Vector6};

use crate::HandConfig;
use crate::state::{FingerMode, HandState};

/// Grip forces for one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Grip {
    /// Normal force per finger (0 for free fingers) \[N\].
    pub normal: [f64; 3],
    /// Full contact force on the object per finger, weight-only load \[N\].
    pub force: [Vector3<f64>; 3],
    /// Torsional moment about the inward normal per finger [N·m].
    pub torsion: [f64; 3],
    /// Whether the squeeze had to be capped at the maximum grip (the grasp
    /// is too close to its friction limit for the load).
    pub capped: bool,
}

/// Squeeze patterns tried for three hard contacts: weights of the chord
/// pairs (0–1, 0–2, 1–2); the one with the least largest normal force wins.
const SQUEEZE_PATTERNS: [[f64; 3]; 7] = [
    [1.0, 1.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [2.0, 1.0, 1.0],
    [1.0, 2.0, 1.0],
    [1.0, 1.0, 2.0],
];

fn max3(v: &[f64; 3]) -> f64 {
    v[0].max(v[1]).max(v[2])
}

/// The closed-form grip model of one configuration.
#[derive(Debug, Clone, Copy)]
pub struct GripModel {
    radius: f64,
    mu: f64,
    torsion_scale: f64,
    weight: Vector3<f64>,
    disturbance: f64,
    min_grip: f64,
    max_grip: f64,
    cos_fc: f64,
}

impl GripModel {
    /// From a validated configuration.
    pub fn new(c: &HandConfig) -> Self {
        let m = &c.model;
        let theta = m.friction_angle_deg.to_radians();
        let margin = m.fc_margin_deg.to_radians();
        let mu = (theta - 0.5 * margin).tan();
        let g = c.load.gravity;
        Self {
            radius: m.object_radius,
            mu,
            // μ/μ_t, the weight of torsion in the soft-finger cone.
            torsion_scale: c.mu() / c.mu_torsion(),
            weight: Vector3::new(g[0], g[1], g[2]) * c.load.object_mass,
            disturbance: c.load.disturbance_force,
            min_grip: c.load.min_grip,
            max_grip: c.load.max_grip,
            cos_fc: (std::f64::consts::PI - 2.0 * theta + margin).cos(),
        }
    }

    /// External force of scenario `s` (0: weight only; 1..=6: plus the
    /// disturbance along ±x, ±y, ±z).
    fn load(&self, s: usize) -> Vector3<f64> {
        if s == 0 {
            return self.weight;
        }
        let mut d = Vector3::zeros();
        d[(s - 1) / 2] = if s % 2 == 1 { 1.0 } else { -1.0 };
        self.weight + d * self.disturbance
    }

    fn scenarios(&self) -> usize {
        if self.disturbance > 0.0 { 7 } else { 1 }
    }

    /// Grip forces of the grasping fingers of `state`, when the object must
    /// also be given the torque `torque` [N·m] (I α: accelerating it).
    pub fn grip(&self, state: &HandState, torque: &Vector3<f64>) -> Grip {
        let mut idx = [0usize; 3];
        let mut n = [Vector3::zeros(); 3];
        let mut k = 0;
        for (i, f) in state.fingers.iter().enumerate() {
            if f.mode == FingerMode::Grasping {
                idx[k] = i;
                n[k] = f.center.normalize();
                k += 1;
            }
        }
        match k {
            2 => self.pair(idx[0], idx[1], &n[0], &n[1], None, torque),
            3 => {
                // The three contacts together, or a pair that holds on its
                // own with the third pressing lightly (the middle of a
                // substitution): whichever needs the least largest force.
                let mut best = self.triple(idx, &n, torque);
                for (a, b, c) in [(0, 1, 2), (0, 2, 1), (1, 2, 0)] {
                    if n[a].dot(&n[b]) <= self.cos_fc {
                        let third = (idx[c], n[c]);
                        let g = self.pair(idx[a], idx[b], &n[a], &n[b], Some(third), torque);
                        if (best.capped && !g.capped)
                            || (g.capped == best.capped && max3(&g.normal) < max3(&best.normal))
                        {
                            best = g;
                        }
                    }
                }
                best
            }
            _ => Grip::default(),
        }
    }

    /// Least squeeze F ≥ 0 with |A F + B|² + s² ≤ μ² (a F + b)², a F + b ≥
    /// `floor`; `None` if no F works.
    fn least(
        &self,
        a: f64,
        b: f64,
        aa: &Vector3<f64>,
        bb: &Vector3<f64>,
        s: f64,
        floor: f64,
    ) -> Option<f64> {
        if a <= 0.0 {
            return None;
        }
        let mu2 = self.mu * self.mu;
        let qa = aa.norm_squared() - mu2 * a * a;
        let qb = 2.0 * (aa.dot(bb) - mu2 * a * b);
        let qc = bb.norm_squared() + s * s - mu2 * b * b;
        let mut f = ((floor - b) / a).max(0.0);
        let disc = qb * qb - 4.0 * qa * qc;
        if qa < 0.0 {
            if disc > 0.0 {
                // Opens downward: feasible beyond the larger root.
                let r = (-qb - disc.sqrt()) / (2.0 * qa);
                f = f.max(r);
            }
            Some(f)
        } else {
            // The squeeze direction itself lies outside the cone.
            None
        }
    }

    fn pair(
        &self,
        i1: usize,
        i2: usize,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        third: Option<(usize, Vector3<f64>)>,
        torque: &Vector3<f64>,
    ) -> Grip {
        let r = self.radius;
        let (p1, p2) = (n1 * r, n2 * r);
        let c = (p1 + p2) * 0.5;
        let d = (p2 - p1) * 0.5;
        let dn = d.norm();
        let u = d / dn;
        // The third finger's preload is part of the load the pair holds.
        let preload = third.map_or(Vector3::zeros(), |(_, n3)| -n3 * self.min_grip);
        let parts = |e: &Vector3<f64>| {
            // Contacts supply −E and the torque: d × Δ + τ = c × E + T.
            let t = c.cross(e) + torque;
            let t_perp = t - u * t.dot(&u);
            let delta = t_perp.cross(&d) / (dn * dn);
            let g1 = -e * 0.5 - delta * 0.5;
            let g2 = -e * 0.5 + delta * 0.5;
            let tau = t.dot(&u) * r / (2.0 * dn);
            (g1, g2, tau)
        };
        let mut squeeze: f64 = 0.0;
        let mut capped = false;
        for s in 0..self.scenarios() {
            let e = self.load(s) + preload;
            let (g1, g2, tau) = parts(&e);
            for (dir, g, n) in [(u, g1, n1), (-u, g2, n2)] {
                let a = dir.dot(&-n);
                let b = g.dot(&-n);
                let aa = dir + n * a;
                let bb = g + n * b;
                match self.least(a, b, &aa, &bb, tau * self.torsion_scale, self.min_grip) {
                    Some(f) => squeeze = squeeze.max(f),
                    None => capped = true,
                }
            }
        }
        if capped || squeeze > self.max_grip {
            capped = true;
            squeeze = squeeze.min(self.max_grip);
        }
        let e = self.load(0) + preload;
        let (g1, g2, tau) = parts(&e);
        let mut out = Grip {
            capped,
            ..Grip::default()
        };
        out.force[i1] = u * squeeze + g1;
        out.force[i2] = -u * squeeze + g2;
        out.torsion[i1] = tau;
        out.torsion[i2] = -tau;
        out.normal[i1] = out.force[i1].dot(&-n1).max(0.0);
        out.normal[i2] = out.force[i2].dot(&-n2).max(0.0);
        if let Some((i3, n3)) = third {
            out.force[i3] = -n3 * self.min_grip;
            out.normal[i3] = self.min_grip;
        }
        out
    }

    fn triple(&self, idx: [usize; 3], n: &[Vector3<f64>; 3], torque: &Vector3<f64>) -> Grip {
        let r = self.radius;
        let p = [n[0] * r, n[1] * r, n[2] * r];
        // Grasp map of three hard contacts: force and torque about O.
        let mut g = SMatrix::<f64, 6, 9>::zeros();
        for i in 0..3 {
            for a in 0..3 {
                let mut e = Vector3::zeros();
                e[a] = 1.0;
                let m = p[i].cross(&e);
                g[(a, 3 * i + a)] = 1.0;
                for row in 0..3 {
                    g[(3 + row, 3 * i + a)] = m[row];
                }
            }
        }
        let ggt: Matrix6<f64> = g * g.transpose();
        let Some(inv) = ggt.try_inverse() else {
            return Grip {
                capped: true,
                ..Grip::default()
            };
        };
        let load_parts = |e: &Vector3<f64>| {
            let w = Vector6::new(-e.x, -e.y, -e.z, torque.x, torque.y, torque.z);
            let f = g.transpose() * (inv * w);
            let v: [Vector3<f64>; 3] =
                std::array::from_fn(|i| Vector3::new(f[3 * i], f[3 * i + 1], f[3 * i + 2]));
            v
        };
        // The least-norm load part of every scenario, once (it does not
        // depend on the squeeze pattern).
        let mut loads = [[Vector3::zeros(); 3]; 7];
        for (s, l) in loads.iter_mut().enumerate().take(self.scenarios()) {
            *l = load_parts(&self.load(s));
        }
        let weight_load = loads[0];
        // Unit chords u_ij from contact i towards j.
        let u = |i: usize, j: usize| (p[j] - p[i]).normalize();
        // Squeeze patterns: weights of the three chord pairs (01, 02, 12).
        let mut best: Option<(f64, f64, [Vector3<f64>; 3])> = None;
        let mut capped = false;
        for w in SQUEEZE_PATTERNS {
            let chords = [
                u(0, 1) * w[0] + u(0, 2) * w[1],
                u(1, 0) * w[0] + u(1, 2) * w[2],
                u(2, 0) * w[1] + u(2, 1) * w[2],
            ];
            let mut lambda: f64 = 0.0;
            let mut feasible = true;
            for gl in &loads[..self.scenarios()] {
                for i in 0..3 {
                    let a = chords[i].dot(&-n[i]);
                    let b = gl[i].dot(&-n[i]);
                    let aa = chords[i] + n[i] * a;
                    let bb = gl[i] + n[i] * b;
                    match self.least(a, b, &aa, &bb, 0.0, self.min_grip) {
                        Some(l) => lambda = lambda.max(l),
                        None => feasible = false,
                    }
                }
            }
            if !feasible {
                continue;
            }
            let max_normal = (0..3)
                .map(|i| (chords[i] * lambda + weight_load[i]).dot(&-n[i]))
                .fold(0.0, f64::max);
            if best.is_none_or(|(m, _, _)| max_normal < m) {
                best = Some((max_normal, lambda, chords));
            }
        }
        let (max_normal, mut lambda, chords) = match best {
            Some(b) => b,
            None => {
                capped = true;
                let c = [u(0, 1) + u(0, 2), u(1, 0) + u(1, 2), u(2, 0) + u(2, 1)];
                (f64::INFINITY, self.max_grip, c)
            }
        };
        let gl = weight_load;
        let mut out = Grip::default();
        if max_normal > self.max_grip {
            capped = true;
            if max_normal.is_finite() {
                lambda *= self.max_grip / max_normal;
            }
        }
        out.capped = capped;
        for i in 0..3 {
            out.force[idx[i]] = chords[i] * lambda + gl[i];
            out.normal[idx[i]] = out.force[idx[i]].dot(&-n[i]).max(0.0);
        }
        out
    }
}

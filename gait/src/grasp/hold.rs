//! Holding the object against its load, in closed form (SPEC §1.3 I1',
//! §3.3): grip forces for two soft or three hard
//! contacts that balance the weight, the torque that accelerates the
//! object and *every* disturbance of the configured size, and the largest
//! normal force this needs.
//!
//! # Load model
//! The contacts must supply the force −E and the torque T about O, for
//! every load scenario (E, T) of
//!
//! ```text
//! E = m g + d_f,   T = I α − d_τ,   |d_f| ≤ F_d,  |d_τ| ≤ T_d,
//! ```
//!
//! with m g the weight (`[load] object_mass`, `gravity`), F_d, T_d the
//! disturbance (`[load] disturbance_force`, `disturbance_torque`), I = (2/5)
//! m R² the solid sphere's inertia and α its angular acceleration: known
//! each tick ([`Accel::Known`]), or any value along the rotation axis k up
//! to the acceleration limit while planning ([`Accel::About`]).
//!
//! Grip forces are a *squeeze* (internal forces, zero net wrench) of
//! magnitude F plus a *load part* (the least-norm forces that balance (E,
//! T)); the squeeze is the same in every scenario (the commanded grip), the
//! load part follows the load. A contact's force must lie in its cone,
//! the coupled soft-finger cone of SPEC §1.2 (elliptic, what MuJoCo's
//! `cone="elliptic"` enforces):
//!
//! ```text
//! f_n ≥ √(|f_t|²/μ² + τ²/μ_t²)   ⇔   |f_t|² + (τ μ/μ_t)² ≤ μ² f_n²,
//! ```
//!
//! with τ = 0 for hard contacts, and μ = tan(θ − δ/2) reduced by half the
//! force-closure margin δ (as I1: `model.fc_margin_deg`), μ_t scaled by the
//! same factor (`HandConfig::mu_torsion`). Each cone is a quadratic
//! inequality in F that holds from its larger root on (the squeeze
//! direction lies inside the cone for a force-closure pair), so the least
//! common squeeze is the largest root over contacts and scenarios, and the
//! largest normal force ("peak", F* here) is the largest normal over
//! scenarios at that squeeze. Grasping contacts press with at least
//! `load.min_grip` in every scenario.
//!
//! **Every disturbance, not sampled directions.** For a fixed squeeze the
//! loads a grasp holds form a convex set (each cone condition is convex in
//! (E, T), being a second-order cone in affine functions of them), so a
//! polytope containing the ball |d| ≤ F_d is held when its vertices are.
//! The scenarios are the 12 vertices of a regular icosahedron whose
//! inscribed sphere has radius F_d (vertices at 1.2584 F_d): guaranteed,
//! conservative by at most that factor along the vertex directions (the
//! same for torques; with both, the 144 vertex pairs). The acceleration
//! bound is the segment α ∈ [−α_max, α_max] k, its two ends. And the least
//! squeeze is a convex function of the load, so the squeeze a tick needs
//! never exceeds the plan-time bound over the same polytope.
//!
//! # Two soft contacts (the key identity of SPEC §3.3)
//! With p_i = R n_i, chord midpoint c, half chord d and u = d/|d|: the
//! squeeze is ±F along the chord, the load part −E/2 ∓ Δ/2 with d × Δ the
//! part of t = c × E + T normal to the chord, and the torsional moments
//! ±τ = ±(t·u)/(2 sin(θ/2)) about the normals give the rest. The contact
//! forces act through the chord, so *only torsion* resists the moment of
//! the load about it: |t·u| = R cos(θ/2) |E·ν| (+ T·u), ν the normal of the
//! plane through O and the two contacts — hence SPEC §3.3's
//! F* ≥ (R/2μ_t) cot(θ/2) |E·ν|: keep chords near antipodal and their plane
//! near vertical. (The torsions are split equally; the tests compare the
//! result with the exact SOCP of [`super::forces::LoadSolver`].)
//!
//! # Three hard contacts
//! The load part is the least-norm solution of G f = (−E, T) (6 × 9 grasp
//! map, computed once per grasp); the squeeze is λ times weighted sums of
//! the unit chords to the other two contacts: equal weights whenever they
//! hold within `load.max_grip` (so forces stay continuous along a motion),
//! else the pattern with the least peak out of seven.
//!
//! Nothing here allocates; a pair costs about 2 µs with the 12 disturbance
//! vertices, a triple about 5 µs (`benches/executor.rs`).

use nalgebra::{Matrix6, SMatrix, Vector3, Vector6};

use crate::HandConfig;

mod pair_terms;
mod spin;

use pair_terms::{LoadPart, PairContact};

/// Circumradius over inradius of the regular icosahedron:
/// 3√(10 + 2√5) / (√3 (3 + √5)).
pub const ICOSAHEDRON_RATIO: f64 = 1.258_408_572_364_819_4;

/// Most force (or torque) vertices of a disturbance polytope.
pub const VERTICES: usize = 12;

/// The 12 vertices of the regular icosahedron with unit inradius
/// (circumradius [`ICOSAHEDRON_RATIO`]).
pub fn icosahedron() -> [Vector3<f64>; VERTICES] {
    let phi = 0.5 * (1.0 + 5f64.sqrt());
    let mut v = [Vector3::zeros(); VERTICES];
    let mut k = 0;
    for s1 in [1.0, -1.0] {
        for s2 in [1.0, -1.0] {
            v[k] = Vector3::new(0.0, s1, s2 * phi);
            v[k + 1] = Vector3::new(s1, s2 * phi, 0.0);
            v[k + 2] = Vector3::new(s2 * phi, 0.0, s1);
            k += 3;
        }
    }
    v.map(|x| x.normalize() * ICOSAHEDRON_RATIO)
}

/// The object's angular acceleration the contacts must produce.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Accel {
    /// At rest (or a known zero).
    None,
    /// A known torque I α \[N·m\] (the executor knows α every tick).
    Known(Vector3<f64>),
    /// Any α along the unit axis up to `max` in size \[rad/s²\] (a
    /// rotation about that axis at the acceleration limit, while planning).
    About {
        /// Unit rotation axis.
        axis: Vector3<f64>,
        /// Largest |α| \[rad/s²\].
        max: f64,
    },
}

/// The load scenarios of one evaluation (module docs): scenario 0 is the
/// weight with the first acceleration torque (what the commanded grip
/// balances), then every combination of acceleration ends and
/// disturbance vertices.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Loads {
    weight: Vector3<f64>,
    accel: [Vector3<f64>; 2],
    n_accel: usize,
    force: [Vector3<f64>; VERTICES],
    n_force: usize,
    torque: [Vector3<f64>; VERTICES],
    n_torque: usize,
}

impl Loads {
    /// Number of scenarios.
    pub fn count(&self) -> usize {
        1 + self.n_accel * self.n_force.max(1) * self.n_torque.max(1)
    }

    /// Force E and torque T (the contacts supply −E and T) of scenario `s`.
    pub fn scenario(&self, s: usize) -> (Vector3<f64>, Vector3<f64>) {
        if s == 0 {
            return (self.weight, self.accel[0]);
        }
        let i = s - 1;
        let nf = self.n_force.max(1);
        let nt = self.n_torque.max(1);
        let f = i % nf;
        let t = (i / nf) % nt;
        let a = i / (nf * nt);
        let e = if self.n_force > 0 {
            self.weight + self.force[f]
        } else {
            self.weight
        };
        let torque = if self.n_torque > 0 {
            self.accel[a] - self.torque[t]
        } else {
            self.accel[a]
        };
        (e, torque)
    }

    /// The weight m g \[N\].
    pub fn weight(&self) -> Vector3<f64> {
        self.weight
    }
}

/// The chord of a soft pair on the sphere of radius R: midpoint c, half
/// chord d, |d|², |d| and u = d/|d| (module docs).
struct Chord {
    c: Vector3<f64>,
    d: Vector3<f64>,
    dn2: f64,
    len: f64,
    u: Vector3<f64>,
}

impl Chord {
    fn new(n1: &Vector3<f64>, n2: &Vector3<f64>, r: f64) -> Self {
        let c = (n1 + n2) * (0.5 * r);
        let d = (n2 - n1) * (0.5 * r);
        let dn2 = d.norm_squared();
        let len = dn2.sqrt();
        Self {
            c,
            d,
            dn2,
            len,
            u: d / len,
        }
    }
}

/// Grip forces of one grasp (contacts in the order given).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hold {
    /// Commanded normal force per contact (scenario 0) \[N\].
    pub normal: [f64; 3],
    /// Contact force on the object per contact, scenario 0 \[N\].
    pub force: [Vector3<f64>; 3],
    /// Torsional moment per contact, scenario 0 \[N·m\] (moment −τ n on the
    /// object; 0 for hard contacts).
    pub torsion: [f64; 3],
    /// Largest normal force per contact over all scenarios \[N\].
    pub peak: [f64; 3],
    /// The largest of `peak` (F*; +∞ when no squeeze works) \[N\].
    pub max_peak: f64,
    /// Whether F* ≤ `load.max_grip`: the grasp holds the load (I1').
    pub feasible: bool,
    /// Whether the commanded squeeze was lowered to keep the commanded
    /// normals within `load.max_grip` (then `feasible` is false).
    pub capped: bool,
}

impl Hold {
    /// No contact carries anything (an empty grasp: infeasible).
    pub const NONE: Self = Self {
        normal: [0.0; 3],
        force: [Vector3::new(0.0, 0.0, 0.0); 3],
        torsion: [0.0; 3],
        peak: [0.0; 3],
        max_peak: f64::INFINITY,
        feasible: false,
        capped: false,
    };
}

/// Squeeze patterns tried for three hard contacts: weights of the chord
/// pairs (0–1, 0–2, 1–2).
const SQUEEZE_PATTERNS: [[f64; 3]; 7] = [
    [1.0, 1.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [2.0, 1.0, 1.0],
    [1.0, 2.0, 1.0],
    [1.0, 1.0, 2.0],
];

/// The closed-form hold model of one configuration (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HoldModel {
    radius: f64,
    mu: f64,
    torsion_scale: f64,
    /// μ_t, not reduced: the torsional friction of a spinning contact.
    spin_torsion: f64,
    weight: Vector3<f64>,
    inertia: f64,
    min_grip: f64,
    max_grip: f64,
    force_vertices: [Vector3<f64>; VERTICES],
    n_force: usize,
    torque_vertices: [Vector3<f64>; VERTICES],
    n_torque: usize,
}

impl HoldModel {
    /// From a validated configuration.
    pub fn new(c: &HandConfig) -> Self {
        let m = &c.model;
        let theta = m.friction_angle_deg.to_radians();
        let margin = m.fc_margin_deg.to_radians();
        let l = &c.load;
        let ico = icosahedron();
        let (nf, nt) = (
            if l.disturbance_force > 0.0 {
                VERTICES
            } else {
                0
            },
            if l.disturbance_torque > 0.0 {
                VERTICES
            } else {
                0
            },
        );
        Self {
            radius: m.object_radius,
            mu: (theta - 0.5 * margin).tan(),
            torsion_scale: c.mu() / c.mu_torsion(),
            spin_torsion: c.mu_torsion(),
            weight: Vector3::from(l.gravity) * l.object_mass,
            inertia: 0.4 * l.object_mass * m.object_radius * m.object_radius,
            min_grip: l.min_grip,
            max_grip: l.max_grip,
            force_vertices: ico.map(|v| v * l.disturbance_force),
            n_force: nf,
            torque_vertices: ico.map(|v| v * l.disturbance_torque),
            n_torque: nt,
        }
    }

    /// The largest normal force a finger may apply (`load.max_grip`) \[N\].
    pub fn max_grip(&self) -> f64 {
        self.max_grip
    }

    /// The same model with the largest normal force `max_grip` where that
    /// is lower (a chain hand's motors, [`crate::grasp::FingerStatics::push_limit`]).
    pub fn within(mut self, max_grip: f64) -> Self {
        self.max_grip = self.max_grip.min(max_grip.max(0.0));
        self
    }

    /// The weight m g \[N\].
    pub fn weight(&self) -> Vector3<f64> {
        self.weight
    }

    /// The object's moment of inertia about O, (2/5) m R² \[kg m²\].
    pub fn inertia(&self) -> f64 {
        self.inertia
    }

    /// The scenarios for the configured weight and `accel`.
    pub fn loads(&self, accel: Accel) -> Loads {
        self.loads_with_weight(self.weight, accel)
    }

    /// The scenarios for another weight vector (tables over directions).
    pub fn loads_with_weight(&self, weight: Vector3<f64>, accel: Accel) -> Loads {
        let (a, n_accel) = match accel {
            Accel::None => ([Vector3::zeros(); 2], 1),
            Accel::Known(t) => ([t, Vector3::zeros()], 1),
            Accel::About { axis, max } => {
                let t = axis * (self.inertia * max);
                if max > 0.0 { ([t, -t], 2) } else { ([t, t], 1) }
            }
        };
        Loads {
            weight,
            accel: a,
            n_accel,
            force: self.force_vertices,
            n_force: self.n_force,
            torque: self.torque_vertices,
            n_torque: self.n_torque,
        }
    }

    /// Least squeeze F ≥ 0 with |A F + B|² + s² ≤ μ² (a F + b)² and
    /// a F + b ≥ `floor`; `None` if no F works (the squeeze direction lies
    /// outside the cone).
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
        if qa >= 0.0 {
            return None;
        }
        let qb = 2.0 * (aa.dot(bb) - mu2 * a * b);
        let qc = bb.norm_squared() + s * s - mu2 * b * b;
        let mut f = ((floor - b) / a).max(0.0);
        let disc = qb * qb - 4.0 * qa * qc;
        if disc > 0.0 {
            // Opens downward: feasible from the larger root on.
            f = f.max((-qb - disc.sqrt()) / (2.0 * qa));
        }
        Some(f)
    }

    /// Load part of a soft pair for one scenario: contact forces g1, g2
    /// (without squeeze) and the torsion τ (module docs).
    fn pair_parts(
        &self,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        e: &Vector3<f64>,
        t: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>, f64) {
        self.chord_parts(&Chord::new(n1, n2, self.radius), e, t)
    }

    /// [`HoldModel::pair_parts`] on a pair's chord computed once.
    fn chord_parts(
        &self,
        ch: &Chord,
        e: &Vector3<f64>,
        t: &Vector3<f64>,
    ) -> (Vector3<f64>, Vector3<f64>, f64) {
        let tt = ch.c.cross(e) + t;
        let along = tt.dot(&ch.u);
        let t_perp = tt - ch.u * along;
        let delta = t_perp.cross(&ch.d) / ch.dn2;
        let g1 = -e * 0.5 - delta * 0.5;
        let g2 = -e * 0.5 + delta * 0.5;
        // Torsional moments τ n2 − τ n1 = (2|d|/R) τ u supply t·u.
        let tau = along * self.radius / (2.0 * ch.len);
        (g1, g2, tau)
    }

    /// Whether two soft contacts at unit normals `n` hold `loads` (the
    /// verdict of [`HoldModel::pair`]'s `feasible`, without the forces): it
    /// stops at the first scenario that makes the peak exceed
    /// `load.max_grip` (the peak only grows with more scenarios).
    ///
    /// The load part is linear in (E, T), and every scenario is the sum of
    /// three terms — (m g, I α) for one acceleration end, a force vertex, a
    /// torque vertex — so the parts of those 2 + 12 + 12 terms are computed
    /// once, in each contact's own frame, and a scenario costs a sum and two
    /// quadratic roots (the planner asks this for up to 289 scenarios per
    /// pair, many times per plan) — or none, where the scenario is already
    /// inside both cones at the squeeze found so far (most are).
    pub fn pair_holds(&self, n: &[Vector3<f64>; 2], loads: &Loads) -> bool {
        let (n1, n2) = (&n[0], &n[1]);
        let d = n2 - n1;
        if d.norm_squared() < 1e-18 {
            return false;
        }
        let u = d.normalize();
        let a_sq = u.dot(&-n1);
        let frames = [
            PairContact::new(&u, n1, self.mu),
            PairContact::new(&(-u), n2, self.mu),
        ];
        if frames.iter().any(|c| c.a <= 0.0 || c.qa >= 0.0) {
            // The squeeze direction lies outside a cone: nothing holds.
            return false;
        }
        let chord = Chord::new(n1, n2, self.radius);
        let part = |e: &Vector3<f64>, t: &Vector3<f64>| {
            let (g1, g2, tau) = self.chord_parts(&chord, e, t);
            LoadPart::new(&frames, &[g1, g2], tau * self.torsion_scale)
        };
        let zero = Vector3::zeros();
        let mut squeeze: f64 = 0.0;
        let mut b_max = f64::NEG_INFINITY;
        let mut held = |p: &LoadPart| {
            for (c, frame) in frames.iter().enumerate() {
                let [b, x, y] = p.contact[c];
                b_max = b_max.max(b);
                squeeze = frame.least_beyond(squeeze, b, x, y, p.torsion, self.min_grip);
            }
            let peak = a_sq * squeeze + b_max;
            !(peak > self.max_grip || peak.is_nan())
        };
        // Scenario 0, then every combination (Loads::scenario's set); a
        // term's part is computed when first needed, so an early refusal
        // costs little.
        let first = part(&loads.weight, &loads.accel[0]);
        if !held(&first) {
            return false;
        }
        let mut force = [LoadPart::ZERO; VERTICES];
        let mut torque = [LoadPart::ZERO; VERTICES];
        for a in 0..loads.n_accel {
            let base = if a == 0 {
                first
            } else {
                part(&loads.weight, &loads.accel[a])
            };
            let torques = torque.iter_mut().enumerate().take(loads.n_torque.max(1));
            for (t, torque_part) in torques {
                if a == 0 && t < loads.n_torque {
                    *torque_part = part(&zero, &-loads.torque[t]);
                }
                let with_torque = base.plus(torque_part);
                let forces = force.iter_mut().enumerate().take(loads.n_force.max(1));
                for (f, force_part) in forces {
                    if a == 0 && t == 0 && f < loads.n_force {
                        *force_part = part(&loads.force[f], &zero);
                    }
                    if !held(&with_torque.plus(force_part)) {
                        return false;
                    }
                }
            }
        }
        true
    }

    /// Two soft contacts at unit normals `n` holding `loads`.
    pub fn pair(&self, n: &[Vector3<f64>; 2], loads: &Loads) -> Hold {
        let (n1, n2) = (&n[0], &n[1]);
        let d = n2 - n1;
        if d.norm_squared() < 1e-18 {
            return Hold::NONE;
        }
        let u = d.normalize();
        let mut squeeze: f64 = 0.0;
        let mut possible = true;
        let count = loads.count();
        // The normals are a F + b_s at both contacts, a = sin(θ/2): the
        // largest b_s per contact gives the peak.
        let a_sq = u.dot(&-n1);
        let mut b_max = [f64::NEG_INFINITY; 2];
        let chord = Chord::new(n1, n2, self.radius);
        for s in 0..count {
            let (e, t) = loads.scenario(s);
            let (g1, g2, tau) = self.chord_parts(&chord, &e, &t);
            for (i, (dir, g, nn)) in [(u, g1, n1), (-u, g2, n2)].into_iter().enumerate() {
                let a = dir.dot(&-nn);
                let b = g.dot(&-nn);
                b_max[i] = b_max[i].max(b);
                let aa = dir + nn * a;
                let bb = g + nn * b;
                match self.least(a, b, &aa, &bb, tau * self.torsion_scale, self.min_grip) {
                    Some(f) => squeeze = squeeze.max(f),
                    None => possible = false,
                }
            }
        }
        // Contact forces of scenario s at squeeze f.
        let normals = |f: f64, s: usize| {
            let (e, t) = loads.scenario(s);
            let (g1, g2, tau) = self.chord_parts(&chord, &e, &t);
            let f1 = u * f + g1;
            let f2 = -u * f + g2;
            (f1, f2, tau)
        };
        let peak = [a_sq * squeeze + b_max[0], a_sq * squeeze + b_max[1], 0.0];
        let mut max_peak = if possible {
            peak[0].max(peak[1])
        } else {
            f64::INFINITY
        };
        if !max_peak.is_finite() {
            max_peak = f64::INFINITY;
        }
        let feasible = possible && max_peak <= self.max_grip;
        // Commanded: scenario 0, lowered if it would exceed max_grip.
        let (mut f1, mut f2, tau) = normals(squeeze, 0);
        let mut capped = false;
        let top = f1.dot(&-n1).max(f2.dot(&-n2));
        if !possible || top > self.max_grip {
            capped = true;
            // The normals are a F + b with a = sin(θ/2) at both contacts.
            let a = u.dot(&-n1);
            let lower = (top - self.max_grip) / a.max(1e-9);
            let f = if possible {
                (squeeze - lower).max(0.0)
            } else {
                0.0
            };
            (f1, f2, _) = normals(f, 0);
        }
        let mut out = Hold {
            normal: [f1.dot(&-n1).max(0.0), f2.dot(&-n2).max(0.0), 0.0],
            force: [f1, f2, Vector3::zeros()],
            torsion: [tau, -tau, 0.0],
            peak,
            max_peak,
            feasible,
            capped,
        };
        if !possible {
            out.peak = [f64::INFINITY, f64::INFINITY, 0.0];
        }
        out
    }

    /// Three hard contacts at unit normals `n` holding `loads`.
    pub fn triple(&self, n: &[Vector3<f64>; 3], loads: &Loads) -> Hold {
        let r = self.radius;
        let p = [n[0] * r, n[1] * r, n[2] * r];
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
            return Hold::NONE;
        };
        let pinv: SMatrix<f64, 9, 6> = g.transpose() * inv;
        let load_part = |s: usize| {
            let (e, t) = loads.scenario(s);
            let f = pinv * Vector6::new(-e.x, -e.y, -e.z, t.x, t.y, t.z);
            let v: [Vector3<f64>; 3] =
                core::array::from_fn(|i| Vector3::new(f[3 * i], f[3 * i + 1], f[3 * i + 2]));
            v
        };
        let u = |i: usize, j: usize| (p[j] - p[i]).normalize();
        let count = loads.count();
        // (peak, λ, chords, per-contact peaks) of the best pattern.
        type Best = (f64, f64, [Vector3<f64>; 3], [f64; 3]);
        let mut best: Option<Best> = None;
        for w in SQUEEZE_PATTERNS {
            let chords = [
                u(0, 1) * w[0] + u(0, 2) * w[1],
                u(1, 0) * w[0] + u(1, 2) * w[2],
                u(2, 0) * w[1] + u(2, 1) * w[2],
            ];
            let mut lambda: f64 = 0.0;
            let mut ok = true;
            for s in 0..count {
                let gl = load_part(s);
                for i in 0..3 {
                    let a = chords[i].dot(&-n[i]);
                    let b = gl[i].dot(&-n[i]);
                    let aa = chords[i] + n[i] * a;
                    let bb = gl[i] + n[i] * b;
                    match self.least(a, b, &aa, &bb, 0.0, self.min_grip) {
                        Some(l) => lambda = lambda.max(l),
                        None => ok = false,
                    }
                }
                if !ok {
                    break;
                }
            }
            if !ok {
                continue;
            }
            let mut peak = [0.0f64; 3];
            for s in 0..count {
                let gl = load_part(s);
                for i in 0..3 {
                    peak[i] = peak[i].max((chords[i] * lambda + gl[i]).dot(&-n[i]));
                }
            }
            let top = peak[0].max(peak[1]).max(peak[2]);
            if best.is_none_or(|(m, ..)| top < m) {
                best = Some((top, lambda, chords, peak));
            }
            // The equal squeeze whenever it holds within the limit: one
            // pattern throughout keeps the forces continuous along a
            // motion (the least-peak choice could switch and jump).
            if w == SQUEEZE_PATTERNS[0] && top <= self.max_grip {
                break;
            }
        }
        let gl = load_part(0);
        let Some((max_peak, mut lambda, chords, peak)) = best else {
            let mut out = Hold::NONE;
            for i in 0..3 {
                out.force[i] = gl[i];
                out.normal[i] = gl[i].dot(&-n[i]).max(0.0);
            }
            out.capped = true;
            return out;
        };
        let feasible = max_peak <= self.max_grip;
        let top = (0..3)
            .map(|i| (chords[i] * lambda + gl[i]).dot(&-n[i]))
            .fold(0.0, f64::max);
        let mut capped = false;
        if top > self.max_grip {
            capped = true;
            // Lower the squeeze until the largest commanded normal fits.
            let mut lo = 0.0;
            let mut hi = lambda;
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                let t = (0..3)
                    .map(|i| (chords[i] * mid + gl[i]).dot(&-n[i]))
                    .fold(0.0, f64::max);
                if t > self.max_grip {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            lambda = lo;
        }
        let mut out = Hold {
            normal: [0.0; 3],
            force: [Vector3::zeros(); 3],
            torsion: [0.0; 3],
            peak,
            max_peak,
            feasible,
            capped,
        };
        for i in 0..3 {
            out.force[i] = chords[i] * lambda + gl[i];
            out.normal[i] = out.force[i].dot(&-n[i]).max(0.0);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosahedron_contains_the_unit_ball() {
        let v = icosahedron();
        // Every face plane is at distance ≥ 1 from O: the 20 faces are the
        // vertex triples at mutual edge length; their centroid is the
        // nearest point of the face plane, at distance 1 (inradius).
        let edge = (v[0] - v[1]).norm().min(
            (0..12)
                .map(|j| (v[0] - v[j]).norm())
                .filter(|d| *d > 1e-9)
                .fold(f64::MAX, f64::min),
        );
        let mut faces = 0;
        for i in 0..12 {
            for j in i + 1..12 {
                for k in j + 1..12 {
                    let e = |a: usize, b: usize| ((v[a] - v[b]).norm() - edge).abs() < 1e-9;
                    if e(i, j) && e(j, k) && e(i, k) {
                        faces += 1;
                        let nrm = (v[j] - v[i]).cross(&(v[k] - v[i])).normalize();
                        let dist = nrm.dot(&v[i]).abs();
                        assert!((dist - 1.0).abs() < 1e-12, "{dist}");
                    }
                }
            }
        }
        assert_eq!(faces, 20);
    }

    #[test]
    fn antipodal_horizontal_pair_needs_mg_over_two_mu() {
        // An antipodal pair on a horizontal line needs
        // m g / (2 μ) (no disturbance, no floor).
        let mut c = HandConfig::default();
        c.load.disturbance_force = 0.0;
        c.load.min_grip = 0.0;
        c.model.fc_margin_deg = 0.0;
        let m = HoldModel::new(&c);
        let h = m.pair(&[Vector3::x(), -Vector3::x()], &m.loads(Accel::None));
        let want = 0.1 * 9.81 / (2.0 * c.mu());
        assert!((h.max_peak - want).abs() < 1e-9, "{} vs {want}", h.max_peak);
        assert!(h.feasible);
    }

    #[test]
    fn the_early_verdict_is_the_full_one() {
        // pair_holds stops early and sums the scenarios' load parts; it
        // must say what pair(..).feasible says, for pairs on both sides of
        // the limit, at rest and turning, with and without torque vertices.
        let mut with_torque = HandConfig::default();
        with_torque.load.disturbance_torque = 0.004;
        for c in [HandConfig::default(), with_torque] {
            let m = HoldModel::new(&c);
            let (mut held, mut dropped) = (0, 0);
            for i in 0..4000 {
                let a = i as f64 * 0.731;
                let n1 = Vector3::new(
                    a.cos() * (0.37 * a).sin(),
                    a.sin() * (0.37 * a).sin(),
                    (0.37 * a).cos(),
                )
                .normalize();
                let w = n1
                    .cross(&Vector3::new((1.3 * a).sin(), (1.7 * a).cos(), 0.4))
                    .normalize();
                let theta = 2.4 + 0.74 * ((0.113 * i as f64).sin() * 0.5 + 0.5);
                let n2 = nalgebra::UnitQuaternion::from_axis_angle(
                    &nalgebra::Unit::new_normalize(w),
                    theta,
                ) * n1;
                let accel = if i % 2 == 0 {
                    Accel::None
                } else {
                    Accel::About { axis: w, max: 4.0 }
                };
                let loads = m.loads(accel);
                let full = m.pair(&[n1, n2], &loads).feasible;
                assert_eq!(m.pair_holds(&[n1, n2], &loads), full, "pair {i}");
                if full {
                    held += 1;
                } else {
                    dropped += 1;
                }
            }
            assert!(held > 400 && dropped > 400, "{held} held, {dropped} not");
        }
    }
}

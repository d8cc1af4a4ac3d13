//! Two soft contacts and a spinning one (SPEC §1.3 I1', §2.4): the grip of
//! a three-finger grasp while one fingertip spins on the still object.
//!
//! A contact that spins slides in torsion, so its coupled cone is used up
//! by the torsional friction μ_t λ (λ its normal force) and it has no
//! tangential friction left: it pushes along its normal and twists the
//! object by ±μ_t λ about it (either sign: the friction opposes the spin,
//! and the model does not depend on the spin's direction). The other two
//! contacts, soft and sticking, carry the rest of every load scenario:
//! the force E − λ n_k and the torque T ∓ μ_t λ n_k (contact k at unit
//! normal n_k pushes with −λ n_k, through O). The push's line misses the
//! other two's chord, so it can supply the moment about that chord that
//! their torsion alone could not (the key identity of [`super`]): the two
//! need not be a force-closure pair.
//!
//! As in [`HoldModel::pair`] the two carry a squeeze F along their chord
//! plus the least-norm load part. Unlike there, the squeeze and λ follow
//! the scenario: both are reactions of the compliant fingertips (the
//! MuJoCo plant's press springs), the commanded grip is scenario 0's, and
//! a common squeeze would leave the non-force-closure pair unable to meet
//! disturbances from every side. Everything is affine in (F, λ), each cone
//! a second-order cone in them: for a fixed F the λ that work form an
//! interval, and within it the largest normal force is convex and
//! piecewise linear in λ, least at an end or a crossing; the least of that
//! over λ is convex in F, found by a fixed scan of [`SQUEEZE_STEPS`]
//! values refined by [`SQUEEZE_REFINE`] golden-section steps (bounded
//! work, nothing allocates: it also runs every tick of a spin).

use nalgebra::Vector3;

use super::{Hold, HoldModel, Loads};

/// Squeezes scanned.
pub const SQUEEZE_STEPS: usize = 16;

/// Golden-section steps around the best scanned squeeze.
pub const SQUEEZE_REFINE: usize = 12;

/// Most scenarios (with both torsion signs) handled: 1 + 2 · 12 · 12
/// load scenarios at most, twice.
const MAX_CASES: usize = 2 * (1 + 2 * 12 * 12);

/// x in [lo, hi] (empty when lo > hi).
#[derive(Clone, Copy)]
struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    fn empty(&self) -> bool {
        self.lo > self.hi
    }

    /// Intersects with {x : q₂x² + q₁x + q₀ ≤ 0} on the nappe that presses
    /// (the normal force grows with x when `up`).
    fn quadratic(&mut self, q2: f64, q1: f64, q0: f64, up: bool) {
        if q2.abs() < 1e-14 {
            self.linear(q1, q0);
            return;
        }
        let disc = q1 * q1 - 4.0 * q2 * q0;
        if q2 > 0.0 {
            if disc < 0.0 {
                self.lo = f64::INFINITY;
                return;
            }
            let s = disc.sqrt();
            self.lo = self.lo.max((-q1 - s) / (2.0 * q2));
            self.hi = self.hi.min((-q1 + s) / (2.0 * q2));
        } else if disc > 0.0 {
            // Outside the roots; one side is the nappe that pulls.
            let s = disc.sqrt();
            let (small, large) = ((-q1 + s) / (2.0 * q2), (-q1 - s) / (2.0 * q2));
            if up {
                self.lo = self.lo.max(large);
            } else {
                self.hi = self.hi.min(small);
            }
        }
    }

    /// Intersects with {x : q₁x + q₀ ≤ 0}.
    fn linear(&mut self, q1: f64, q0: f64) {
        if q1 > 0.0 {
            self.hi = self.hi.min(-q0 / q1);
        } else if q1 < 0.0 {
            self.lo = self.lo.max(-q0 / q1);
        } else if q0 > 0.0 {
            self.lo = f64::INFINITY;
        }
    }
}

/// One scenario (with one torsion sign) for the two carriers, affine in
/// λ: load-part forces g = g0 + λ dg, torsion τ = τ0 + λ dτ.
#[derive(Clone, Copy)]
struct Case {
    g: [Vector3<f64>; 2],
    dg: [Vector3<f64>; 2],
    tau: f64,
    dtau: f64,
}

/// The geometry of one evaluation.
struct Setup<'a> {
    model: &'a HoldModel,
    /// Chord direction from carrier 0 to carrier 1, and their normals.
    u: Vector3<f64>,
    n: [Vector3<f64>; 2],
    cases: [Case; MAX_CASES],
    count: usize,
}

impl Setup<'_> {
    /// Squeeze direction of carrier c (± the chord).
    fn dir(&self, c: usize) -> Vector3<f64> {
        if c == 0 { self.u } else { -self.u }
    }

    /// The λ that work for case `s` at squeeze `f`, and the least largest
    /// normal force (λ included) over them: (λ, peak), or None. With
    /// `cap`, the least λ whose normals all stay within `cap` instead.
    fn best_lambda(&self, s: usize, f: f64, cap: Option<f64>) -> Option<(f64, f64)> {
        let m = self.model;
        let mu2 = m.mu * m.mu;
        let case = &self.cases[s];
        // The spinner presses at least min_grip, as every grasping finger
        // (it must stay in contact while it spins).
        let mut iv = Interval {
            lo: m.min_grip.max(0.0),
            hi: m.max_grip,
        };
        // Normal of carrier c: N + λ dN.
        let mut normal = [(0.0, 0.0); 2];
        for (c, slot) in normal.iter_mut().enumerate() {
            let nn = self.n[c];
            let dir = self.dir(c);
            let a = dir.dot(&-nn);
            let (g, dg) = (case.g[c], case.dg[c]);
            let (b, db) = (g.dot(&-nn), dg.dot(&-nn));
            // Tangential part P + λ Q, scaled torsion S + λ dS (carrier 1
            // twists the other way: the square does not mind).
            let p = dir * f + g + nn * (a * f + b);
            let q = dg + nn * db;
            let (st, dst) = (case.tau * m.torsion_scale, case.dtau * m.torsion_scale);
            let nf = a * f + b;
            iv.quadratic(
                q.norm_squared() + dst * dst - mu2 * db * db,
                2.0 * (p.dot(&q) + st * dst - mu2 * nf * db),
                p.norm_squared() + st * st - mu2 * nf * nf,
                db > 0.0,
            );
            // min_grip ≤ N + λ dN ≤ max_grip.
            iv.linear(-db, m.min_grip - nf);
            iv.linear(db, nf - m.max_grip);
            *slot = (nf, db);
        }
        let peak = |l: f64| {
            l.max(normal[0].0 + l * normal[0].1)
                .max(normal[1].0 + l * normal[1].1)
        };
        if let Some(cap) = cap {
            iv.hi = iv.hi.min(cap);
            for (n0, d0) in normal {
                iv.linear(d0, n0 - cap);
            }
            return (!iv.empty()).then(|| (iv.lo, peak(iv.lo)));
        }
        if iv.empty() {
            return None;
        }
        // max(λ, N₀ + λ dN₀, N₁ + λ dN₁): least at an end or a crossing.
        let mut best = (iv.lo, peak(iv.lo));
        let mut consider = |l: f64| {
            if l > iv.lo && l < iv.hi {
                let p = peak(l);
                if p < best.1 {
                    best = (l, p);
                }
            }
        };
        for (n0, d0) in normal {
            if (1.0 - d0).abs() > 1e-12 {
                consider(n0 / (1.0 - d0));
            }
        }
        let ((n0, d0), (n1, d1)) = (normal[0], normal[1]);
        if (d0 - d1).abs() > 1e-12 {
            consider((n1 - n0) / (d0 - d1));
        }
        let p = peak(iv.hi);
        if p < best.1 {
            best = (iv.hi, p);
        }
        Some(best)
    }

    /// The least largest normal force of case `s` over squeezes in
    /// [0, `top`], and that squeeze.
    fn least_peak(&self, s: usize, top: f64) -> (f64, f64) {
        least(top, |f| {
            self.best_lambda(s, f, None).map_or(f64::INFINITY, |b| b.1)
        })
    }
}

/// The least of `peak` over [0, `top`] and where: a scan, then
/// golden-section steps (for functions convex where finite).
fn least(top: f64, peak: impl Fn(f64) -> f64) -> (f64, f64) {
    let step = top / (SQUEEZE_STEPS - 1) as f64;
    let mut best = (f64::INFINITY, 0.0);
    for i in 0..SQUEEZE_STEPS {
        let f = step * i as f64;
        let p = peak(f);
        if p < best.0 {
            best = (p, f);
        }
    }
    if !best.0.is_finite() {
        return best;
    }
    let (mut lo, mut hi) = ((best.1 - step).max(0.0), (best.1 + step).min(top));
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
    let (mut p1, mut p2) = (peak(x1), peak(x2));
    for _ in 0..SQUEEZE_REFINE {
        if p1 <= p2 {
            (hi, x2, p2) = (x2, x1, p1);
            x1 = hi - phi * (hi - lo);
            p1 = peak(x1);
        } else {
            (lo, x1, p1) = (x1, x2, p2);
            x2 = lo + phi * (hi - lo);
            p2 = peak(x2);
        }
    }
    for (p, x) in [(p1, x1), (p2, x2)] {
        if p < best.0 {
            best = (p, x);
        }
    }
    best
}

impl HoldModel {
    /// Three contacts at unit normals `n`, contact `spinner` spinning
    /// (module docs), holding `loads`; infeasible (`max_peak` +∞) when no
    /// squeeze holds every scenario with some push of the spinner.
    pub fn spinning(&self, n: &[Vector3<f64>; 3], spinner: usize, loads: &Loads) -> Hold {
        let k = spinner.min(2);
        let (i, j) = match k {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        let d = n[j] - n[i];
        if d.norm_squared() < 1e-18 {
            return Hold::NONE;
        }
        let empty = Case {
            g: [Vector3::zeros(); 2],
            dg: [Vector3::zeros(); 2],
            tau: 0.0,
            dtau: 0.0,
        };
        let mut setup = Setup {
            model: self,
            u: d.normalize(),
            n: [n[i], n[j]],
            cases: [empty; MAX_CASES],
            count: 0,
        };
        for s in 0..loads.count() {
            let (e, t) = loads.scenario(s);
            for sign in [1.0, -1.0] {
                if setup.count == MAX_CASES {
                    break;
                }
                // At λ = 0 and the change per newton of λ (affine).
                let (g1, g2, tau) = self.pair_parts(&n[i], &n[j], &e, &t);
                // E − λ n_k and T ∓ μ_t λ n_k: per newton of λ.
                let de = -n[k];
                let dt = -n[k] * (sign * self.spin_torsion);
                let (d1, d2, dtau) = self.pair_parts(&n[i], &n[j], &de, &dt);
                setup.cases[setup.count] = Case {
                    g: [g1, g2],
                    dg: [d1, d2],
                    tau,
                    dtau,
                };
                setup.count += 1;
            }
        }
        // Each case its own squeeze and push (both reactions of the
        // compliant fingertips); F* the worst case's least peak.
        let a = setup.u.dot(&-n[i]).max(1e-6);
        let top = 2.0 * self.max_grip / a;
        let mut max_peak: f64 = 0.0;
        for s in 0..setup.count {
            max_peak = max_peak.max(setup.least_peak(s, top).0);
            if !max_peak.is_finite() {
                return Hold::NONE;
            }
        }
        // Commanded: scenario 0 (the torsion of the first sign) with the
        // spinner pressing as little as the peak allows — its torsional
        // friction twists the object, the others must resist it.
        let cap = max_peak * (1.0 + 1e-9) + 1e-12;
        let push = |f: f64| {
            setup
                .best_lambda(0, f, Some(cap))
                .map_or(f64::INFINITY, |b| b.0)
        };
        let (_, squeeze) = least(top, push);
        let Some((lambda, _)) = setup.best_lambda(0, squeeze, Some(cap)) else {
            return Hold::NONE;
        };
        let c = &setup.cases[0];
        let f1 = setup.u * squeeze + c.g[0] + c.dg[0] * lambda;
        let f2 = -setup.u * squeeze + c.g[1] + c.dg[1] * lambda;
        let tau = c.tau + c.dtau * lambda;
        let mut out = Hold {
            normal: [0.0; 3],
            force: [Vector3::zeros(); 3],
            torsion: [0.0; 3],
            peak: [max_peak; 3],
            max_peak,
            feasible: max_peak <= self.max_grip,
            capped: false,
        };
        out.normal[i] = f1.dot(&-n[i]).max(0.0);
        out.normal[j] = f2.dot(&-n[j]).max(0.0);
        out.normal[k] = lambda;
        out.force[i] = f1;
        out.force[j] = f2;
        out.force[k] = -n[k] * lambda;
        out.torsion[i] = tau;
        out.torsion[j] = -tau;
        out.torsion[k] = self.spin_torsion * lambda;
        out
    }
}

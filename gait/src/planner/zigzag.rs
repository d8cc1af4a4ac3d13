//! A contact rolled beyond one great circle's reach in at most three
//! great-circle legs, the quickest found (SPEC §2.4, §4.3).
//!
//! One great-circle roll from the fingertip pole moves the object contact
//! at most (r/R)·90° (Theory 2: the fingertip contact reaches its
//! hemisphere's rim), 18° at the defaults. Under load the paper start's
//! pair must open 21–24° per finger before it holds the weight. The
//! rolling planner then relocates the
//! contact with the paper's Fig. 2 paths plus a closing roll: four
//! rest-to-rest legs (4.7 s at the defaults). Pure rolling cannot do
//! better with two legs (at most 20.4° under the roll limit), but three
//! legs in a zigzag can: a short first leg moves the fingertip contact off
//! its pole, the second crosses the fingertip to its rim at one side of the
//! target direction, the third crosses back to the rim on the other, their
//! roll changes (τ̇ = ω_f·a_f, SPEC §1.1) cancelling in part. Found by
//! differential evolution over the legs' directions and lengths (22° in
//! 2.88 s, 24° in 3.37 s, against 4.7 s) and computed here by a
//! deterministic grid search refined by Nelder–Mead.
//!
//! A leg about the unit axis w ⊥ n by δ turns the contact normal n and the
//! fingertip about w, the fingertip by c δ with c = (R + r)/r (SPEC §2.3
//! with ω_o = 0): n' = Rot(w, δ) n, a' = Rot(w, c δ) a, τ' = τ + c δ (w·a).
//! Along it the fingertip contact's height over the fingertip equator is
//! m_z = −a'·n' = −a·Rot(w, (1 − c) t) n, a sinusoid in t, and the cone
//! test d_k·n a sinusoid too, so every leg is checked exactly; τ is linear
//! along a leg, so its ends bound it.

use std::collections::HashMap;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::Vector3;

use super::geometry::{Geometry, Sinusoid, angle_between, rotation};
use super::timing::DurationModel;

/// One great-circle leg of a zigzag: the contact turns about `axis` by
/// `angle` ≥ 0 on the object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leg {
    /// Unit axis w, perpendicular to the contact normal where the leg starts.
    pub axis: Vector3<f64>,
    /// Angle on the object \[rad\].
    pub angle: f64,
}

/// The legs (zero-length ones left out) and their summed rest-to-rest
/// rolling time \[s\].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Zigzag {
    /// The legs in order; `None` after the last.
    pub legs: [Option<Leg>; 3],
    /// Σ of the legs' rest-to-rest durations \[s\].
    pub time: f64,
}

/// A rolling contact: normal n, fingertip pole axis a (both hand frame),
/// roll τ.
#[derive(Debug, Clone, Copy)]
struct Tip {
    n: Vector3<f64>,
    a: Vector3<f64>,
    tau: f64,
}

/// Kept inside every limit by the search (rad, or cosine near the rim and
/// the cone's edge): it minimises time plus a penalty on breaches, which
/// its optimum may graze, so it breaches limits this much tighter than the
/// real ones.
const MARGIN: f64 = 1e-3;
/// The largest breach of the search's limits a returned path may have
/// (far below [`MARGIN`], so the real limits hold).
const BREACH_ALLOWED: f64 = 1e-6;
/// Weight of a limit's breach against the time \[s per rad\].
const PENALTY: f64 = 100.0;

/// Grid of the first leg's direction (steps of 30°) and the second's (15°).
const PSI1_STEPS: usize = 12;
const PSI2_STEPS: usize = 24;
/// Grid of the first leg's length, in fractions of a pole-to-rim roll.
const DELTA1_GRID: [f64; 4] = [0.0, 0.12, 0.25, 0.4];
/// Grid of the second leg's length, in fractions of what its fingertip
/// hemisphere allows (the search's coordinate too: the rim is where the
/// quickest paths turn).
const DELTA2_GRID: [f64; 4] = [0.0, 0.7, 0.85, 1.0];
/// Starting points of the Nelder–Mead refinement kept from the grid, and
/// its iterations per run. Three first, not all eight at once: the
/// refinement is ~70 % of a search, and the other five rarely find a
/// quicker path.
const REFINE_FROM: usize = 3;
/// Further starting points refined when none of the first
/// [`REFINE_FROM`] ends inside the limits.
const MORE_REFINED: usize = 5;
const NM_ITERATIONS: usize = 300;

/// The quickest path of at most three great-circle legs found that rolls
/// finger `k` (contact normal `n`, pole axis `a`, roll `tau`) to the
/// contact `target` (unit, hand frame), keeping its contact in its cone
/// and on its fingertip hemisphere and its roll within γ − margin; `None`
/// if no grid point or refinement of it gets there. Deterministic.
pub fn zigzag(
    g: &Geometry,
    timing: &DurationModel,
    k: usize,
    n: &Vector3<f64>,
    a: &Vector3<f64>,
    tau: f64,
    target: &Vector3<f64>,
) -> Option<Zigzag> {
    let start = Tip { n: *n, a: *a, tau };
    let towards = target - n * n.dot(target);
    if towards.norm() < 1e-12 || tau.abs() > g.roll_limit + 1e-12 {
        return None;
    }
    let ea = towards.normalize();
    let c = g.contact_radius / g.fingertip_radius;
    // A pole-to-rim roll on the object (Theory 2): (r/R)·π/2.
    let reach = std::f64::consts::FRAC_PI_2 * g.fingertip_radius / g.object_radius;
    let ctx = Ctx {
        g,
        timing,
        k,
        c,
        target: *target,
        start,
        ea,
    };
    let mut found: Vec<([f64; 4], f64)> = Vec::new();
    for i1 in 0..PSI1_STEPS {
        let psi1 = std::f64::consts::TAU * i1 as f64 / PSI1_STEPS as f64;
        for &f1 in &DELTA1_GRID {
            if f1 == 0.0 && i1 > 0 {
                continue;
            }
            for i2 in 0..PSI2_STEPS {
                let psi2 = std::f64::consts::TAU * i2 as f64 / PSI2_STEPS as f64;
                for &f2 in &DELTA2_GRID {
                    if f2 == 0.0 && i2 > 0 {
                        continue;
                    }
                    let x = [psi1, f1 * reach, psi2, f2];
                    let t = ctx.cost(&x);
                    if t.is_finite() {
                        found.push((x, t));
                    }
                }
            }
        }
    }
    found.sort_by(|p, q| p.1.total_cmp(&q.1));
    found.truncate(REFINE_FROM + MORE_REFINED);
    let steps = [0.25, 0.2 * reach, 0.125, 0.1];
    let refined = |from: &[([f64; 4], f64)]| {
        from.iter()
            .map(|&(x, t)| ctx.refine(x, t, steps))
            .min_by(|p, q| p.1.total_cmp(&q.1))
    };
    let (first, next) = found.split_at(found.len().min(REFINE_FROM));
    let best = refined(first)?;
    // None of the best few refines into the limits: the next ones may.
    ctx.path(&best.0).or_else(|| ctx.path(&refined(next)?.0))
}

/// Zigzags found so far, by their exact inputs (the search is a pure
/// function of them, so a hit returns what a new search would): the paper
/// start is planned from again and again with few distinct targets, and
/// one search takes milliseconds. Bounded: emptied when full. One per
/// timing model (a planner re-timed for other limits gets its own).
#[derive(Debug, Default)]
pub struct ZigzagCache {
    found: Mutex<HashMap<[u64; 11], Option<Zigzag>>>,
    /// Searches made (inputs not found).
    searches: AtomicU64,
}

/// Entries a [`ZigzagCache`] holds before it is emptied.
const CACHE_ENTRIES: usize = 4096;

impl ZigzagCache {
    /// Searches made so far (inputs not found in the cache).
    pub fn searches(&self) -> u64 {
        self.searches.load(Ordering::Relaxed)
    }

    /// [`zigzag`], from the cache when these inputs were searched before.
    #[allow(clippy::too_many_arguments)]
    pub fn zigzag(
        &self,
        g: &Geometry,
        timing: &DurationModel,
        k: usize,
        n: &Vector3<f64>,
        a: &Vector3<f64>,
        tau: f64,
        target: &Vector3<f64>,
    ) -> Option<Zigzag> {
        let key = [
            k as u64,
            n.x.to_bits(),
            n.y.to_bits(),
            n.z.to_bits(),
            a.x.to_bits(),
            a.y.to_bits(),
            a.z.to_bits(),
            tau.to_bits(),
            target.x.to_bits(),
            target.y.to_bits(),
            target.z.to_bits(),
        ];
        // (A panic elsewhere while the lock was held leaves a map that is
        // still consistent: every entry is inserted whole.)
        let lock = || self.found.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(z) = lock().get(&key) {
            return *z;
        }
        self.searches.fetch_add(1, Ordering::Relaxed);
        let z = zigzag(g, timing, k, n, a, tau, target);
        let mut map = lock();
        if map.len() >= CACHE_ENTRIES {
            map.clear();
        }
        map.insert(key, z);
        z
    }
}

struct Ctx<'a> {
    g: &'a Geometry,
    timing: &'a DurationModel,
    k: usize,
    c: f64,
    target: Vector3<f64>,
    start: Tip,
    ea: Vector3<f64>,
}

impl Ctx<'_> {
    /// The leg from `tip` about `axis` by δ and by how much it breaks a
    /// limit (0 if it keeps them all, with [`MARGIN`] to spare): the
    /// fingertip contact's dip below its rim, the contact's exit from its
    /// cone (cosines) and the roll beyond γ − margin (rad).
    fn leg(&self, tip: &Tip, axis: Vector3<f64>, delta: f64) -> (Tip, f64) {
        if delta <= 0.0 {
            return (*tip, 0.0);
        }
        let g = self.g;
        // Fingertip contact height: −a·Rot(−w, u) n for u = (c − 1) t.
        let height = Sinusoid::new(&-axis, &tip.n, &-tip.a);
        let dip = (MARGIN - min_on(&height, (self.c - 1.0) * delta)).max(0.0);
        let cone = Sinusoid::new(&axis, &tip.n, &g.base[self.k]);
        let out = (g.cos_cone + MARGIN - min_on(&cone, delta)).max(0.0);
        let tau = tip.tau + self.c * delta * axis.dot(&tip.a);
        let over = (tau.abs() - (g.roll_limit - MARGIN)).max(0.0);
        let next = Tip {
            n: rotation(&axis, delta) * tip.n,
            a: rotation(&axis, self.c * delta) * tip.a,
            tau,
        };
        (next, dip + out + over)
    }

    /// The axis that moves the contact at `n` in direction ψ measured from
    /// `ea` (towards the target at the start) about n.
    fn axis(&self, n: &Vector3<f64>, psi: f64) -> Vector3<f64> {
        // Frame carried to n: ea, eb projected onto n's tangent plane.
        let ea = (self.ea - n * n.dot(&self.ea)).normalize();
        let eb = n.cross(&ea);
        let d = ea * psi.cos() + eb * psi.sin();
        n.cross(&d).normalize()
    }

    /// The three legs of x = (ψ1, δ1, ψ2, δ2), the closing one to the
    /// target, and their summed breach of the limits (`None` if the
    /// closing leg is undefined: the contact antipodal to the target).
    fn legs(&self, x: &[f64; 4]) -> Option<([Leg; 3], f64)> {
        let w1 = self.axis(&self.start.n, x[0]);
        let (t1, b1) = self.leg(&self.start, w1, x[1].max(0.0));
        let w2 = self.axis(&t1.n, x[2]);
        // δ2 as a fraction of what the fingertip hemisphere allows.
        let room = Sinusoid::new(&-w2, &t1.n, &-t1.a).first_below(MARGIN) / (self.c - 1.0);
        let delta2 = x[3].clamp(0.0, 1.0) * room.min(std::f64::consts::PI);
        let (t2, b2) = self.leg(&t1, w2, delta2);
        let d3 = angle_between(&t2.n, &self.target);
        let w3 = t2.n.cross(&self.target);
        if d3 > 1e-12 && w3.norm() < 1e-9 {
            return None;
        }
        let w3 = if d3 > 1e-12 { w3.normalize() } else { w2 };
        let (_, b3) = self.leg(&t2, w3, d3);
        let leg = |axis, angle: f64| Leg {
            axis,
            angle: angle.max(0.0),
        };
        Some(([leg(w1, x[1]), leg(w2, delta2), leg(w3, d3)], b1 + b2 + b3))
    }

    /// Summed rest-to-rest rolling time of x plus the penalty for its
    /// breach of the limits.
    fn cost(&self, x: &[f64; 4]) -> f64 {
        self.legs(x).map_or(f64::INFINITY, |(legs, bad)| {
            legs.iter()
                .map(|l| self.timing.roll(l.angle * self.c))
                .sum::<f64>()
                + PENALTY * bad
        })
    }

    /// Nelder–Mead from x with initial simplex edges `steps`, restarted
    /// once from its result, [`NM_ITERATIONS`] steps each.
    fn refine(&self, x: [f64; 4], t: f64, steps: [f64; 4]) -> ([f64; 4], f64) {
        let (x, t) = self.nelder_mead(x, t, steps);
        self.nelder_mead(x, t, steps.map(|s| 0.25 * s))
    }

    fn nelder_mead(&self, x0: [f64; 4], t0: f64, steps: [f64; 4]) -> ([f64; 4], f64) {
        let f = |x: &[f64; 4]| self.cost(&clamp(*x));
        let mut pts: [([f64; 4], f64); 5] = [(x0, t0); 5];
        for i in 0..4 {
            let mut y = x0;
            y[i] += steps[i];
            pts[i + 1] = (y, f(&y));
        }
        for _ in 0..NM_ITERATIONS {
            pts.sort_by(|p, q| p.1.total_cmp(&q.1));
            if pts[4].1 - pts[0].1 < 1e-9 {
                break;
            }
            // Centroid of the four best points.
            let centre: [f64; 4] =
                std::array::from_fn(|i| pts[..4].iter().map(|p| 0.25 * p.0[i]).sum());
            let along = |lam: f64| -> [f64; 4] {
                std::array::from_fn(|i| centre[i] + lam * (pts[4].0[i] - centre[i]))
            };
            let r = along(-1.0);
            let fr = f(&r);
            if fr < pts[0].1 {
                let e = along(-2.0);
                let fe = f(&e);
                pts[4] = if fe < fr { (e, fe) } else { (r, fr) };
            } else if fr < pts[3].1 {
                pts[4] = (r, fr);
            } else {
                let cx = if fr < pts[4].1 {
                    along(-0.5)
                } else {
                    along(0.5)
                };
                let fc = f(&cx);
                if fc < pts[4].1.min(fr) {
                    pts[4] = (cx, fc);
                } else {
                    let best = pts[0].0;
                    for p in pts.iter_mut().skip(1) {
                        p.0 = std::array::from_fn(|i| best[i] + 0.5 * (p.0[i] - best[i]));
                        p.1 = f(&p.0);
                    }
                }
            }
        }
        pts.sort_by(|p, q| p.1.total_cmp(&q.1));
        (clamp(pts[0].0), pts[0].1)
    }

    /// The legs of x if they keep every limit (zero-length legs left out).
    fn path(&self, x: &[f64; 4]) -> Option<Zigzag> {
        let (legs, bad) = self.legs(x)?;
        // A breach this small stays within MARGIN of the real limits.
        if bad > BREACH_ALLOWED {
            return None;
        }
        let mut out = Zigzag {
            legs: [None; 3],
            time: 0.0,
        };
        for (slot, l) in out
            .legs
            .iter_mut()
            .zip(legs.into_iter().filter(|l| l.angle > 1e-12))
        {
            out.time += self.timing.roll(l.angle * self.c);
            *slot = Some(l);
        }
        Some(out)
    }
}

/// The search's coordinates within their ranges: lengths ≥ 0, the second
/// a fraction ≤ 1.
fn clamp(x: [f64; 4]) -> [f64; 4] {
    [x[0], x[1].max(0.0), x[2], x[3].clamp(0.0, 1.0)]
}

/// Minimum of a sinusoid over t ∈ [0, t_end].
fn min_on(s: &Sinusoid, t_end: f64) -> f64 {
    -Sinusoid {
        a: -s.a,
        b: -s.b,
        c: -s.c,
    }
    .max_on(t_end)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;
    use crate::hand_state::HandState;

    /// The paper start's finger 1 rolled towards −e_φ (away from finger 2)
    /// by `deg` on the equator.
    fn case(deg: f64) -> Option<Zigzag> {
        let cfg = HandConfig::default();
        let g = Geometry::new(&cfg);
        let t = DurationModel::new(&cfg);
        let h = HandState::paper_start(&cfg);
        let f = &h.fingers[1];
        let n = f.contact_normal();
        let w = Vector3::z();
        let target = rotation(&w, -deg.to_radians()) * n;
        zigzag(&g, &t, 1, &n, &f.pole_axis(), f.roll, &target)
    }

    #[test]
    fn within_one_great_circle_it_is_the_direct_roll() {
        let z = case(12.0).unwrap();
        assert!(z.legs[1].is_none(), "{z:?}");
        assert!((z.legs[0].unwrap().angle - 12f64.to_radians()).abs() < 1e-9);
    }

    #[test]
    fn beyond_it_three_legs_reach_what_fig2_paths_reach_in_four() {
        for (deg, best) in [(22.0, 2.882), (24.0, 3.368)] {
            let z = case(deg).unwrap();
            assert!(z.legs.iter().all(Option::is_some), "{deg}: {z:?}");
            // Within 2 % of the differential evolution's optimum.
            assert!(z.time < best * 1.02, "{deg}°: {} s", z.time);
        }
    }

    /// Every path found, replayed leg by leg through the plan's own roll
    /// step (`Step::eval`, not this module's sinusoids): the fingertip
    /// contact stays on its hemisphere, the roll within γ − margin, the
    /// contact in its cone, and the last sample is the target.
    #[test]
    fn every_path_found_keeps_the_limits_when_replayed() {
        use crate::planner::plan::{GreatCircleRoll, Motion, Step, StepKind};
        let cfg = HandConfig::default();
        let g = Geometry::new(&cfg);
        let t = DurationModel::new(&cfg);
        let cache = ZigzagCache::default();
        let ratio = g.contact_radius / g.fingertip_radius;
        let mut found = 0;
        for k in 0..3 {
            let h0 = HandState::paper_start(&cfg);
            let n0 = h0.fingers[k].contact_normal();
            for dir in 0..8 {
                // Directions all round the contact, 4°–26° away.
                let d = std::f64::consts::TAU * dir as f64 / 8.0 + 0.3;
                let tangent = rotation(&n0, d) * Vector3::z();
                let w = n0.cross(&tangent).normalize();
                for deg in [4.0, 15.0, 19.0, 21.0, 23.0, 26.0] {
                    let target = rotation(&w, f64::to_radians(deg)) * n0;
                    let f = &h0.fingers[k];
                    let args = (&n0, &f.pole_axis(), f.roll, &target);
                    let Some(z) = zigzag(&g, &t, k, args.0, args.1, args.2, args.3) else {
                        continue;
                    };
                    assert_eq!(
                        cache.zigzag(&g, &t, k, args.0, args.1, args.2, args.3),
                        Some(z)
                    );
                    assert_eq!(
                        cache.zigzag(&g, &t, k, args.0, args.1, args.2, args.3),
                        Some(z)
                    );
                    found += 1;
                    let mut h = h0;
                    for leg in z.legs.iter().flatten() {
                        let mut rolls = [None; 3];
                        rolls[0] = Some(GreatCircleRoll {
                            finger: k,
                            axis: leg.axis,
                            angle: leg.angle,
                        });
                        let step = Step {
                            kind: StepKind::Roll,
                            start: h,
                            motion: Motion::Roll { rolls, ratio },
                            duration: 0.0,
                            handover: None,
                        };
                        let len = step.dofs().length;
                        for i in 0..=200 {
                            let s = step
                                .eval(&len.map(|l| l * i as f64 / 200.0), &[0.0; 3])
                                .state;
                            let tip = &s.fingers[k];
                            assert!(
                                tip.fingertip_contact().z > -1e-9,
                                "{k} {dir} {deg}: off the hemisphere"
                            );
                            assert!(
                                tip.roll.abs() <= g.roll_limit + 1e-9,
                                "{k} {dir} {deg}: roll {}",
                                tip.roll
                            );
                            assert!(
                                g.in_cone(k, &tip.contact_normal()),
                                "{k} {dir} {deg}: out of the cone"
                            );
                            h = s;
                        }
                    }
                    let end = h.fingers[k].contact_normal();
                    assert!(
                        (end - target).norm() < 1e-9,
                        "{k} {dir} {deg}: ends {end:?}"
                    );
                }
            }
        }
        // Every one is within reach (26° stays well inside the cone).
        assert_eq!(found, 144, "paths found of 144");
    }
}

//! Planning under load (SPEC §1.3 I1', issue "Holding against gravity"):
//! a closed-form *sufficient* test for the search and the exact check of a
//! built plan.
//!
//! # The search's test ([`PairLoad`])
//! For a soft pair with contact normals n1, n2 (angle θ, a = cos(θ/2),
//! b = sin(θ/2)) take the frame ĉ (bisector), u (chord), ν = u × ĉ (normal
//! of the plane through O and both contacts). With the squeeze F and the
//! load part of [`crate::grasp::hold`] (load E through O, torque T the
//! contacts supply), contact 1 carries, written out in that frame,
//!
//! ```text
//! normal      N₁ = b F + a E_c/2 − E_u/(2b) + a T_ν/(2Rb)
//! in plane    a F − b E_c/2 − T_ν/(2R)
//! along ν     −E_ν/2 + T_c/(2Rb)
//! torsion     τ = (R a E_ν + T_u)/(2b)
//! ```
//!
//! and contact 2 the same with the signs of the E_u and T terms of N, of
//! the T_ν term in plane and of T_c flipped (its in-plane force is
//! −(a F − b E_c/2 + T_ν/(2R))). The torsion line is SPEC §3.3's key
//! identity: only torsion resists the load's moment about the chord.
//! Everything is affine in the load. The weight and the acceleration
//! torque about a known axis (both signs) enter exactly; the disturbance
//! force d (|d| ≤ D, D the radius of the ball around the icosahedron of
//! [`crate::grasp::hold`]), the disturbance torque and, for an unknown
//! axis, I α enter through the norms of their columns (so N changes by at
//! most ρ_N, the cone's left side by at most ρ). With the largest squeeze
//! F for which no normal exceeds F_max, the test is
//! μ (N₀ − ρ_N) − ‖(a F + in-plane₀, ν₀, τ₀ μ/μ_t)‖ − ρ ≥ 0 at both contacts,
//! N₀ − ρ_N ≥ `min_grip`.
//! That is [`PairLoad::slack`] ≥ 0; it implies the closed form of
//! `grasp::hold` — and so the SOCP — holds the load with peak ≤ F_max
//! (tested: `gait/tests/planner_load.rs`). It costs a few dozen flops, so
//! the search evaluates it for every candidate pair; along a rotation by t
//! about k the weight turns by −t in the pair's frame, and
//! [`PairLoad::exit`] steps t to the first angle where the test fails
//! (where the exact tier stands behind it, that tier is asked at the
//! turned contacts, as the plan's check asks it: the disturbance's
//! icosahedron is fixed in the hand frame, so a turned pair meets it
//! turned).
//!
//! # The exact check of a plan ([`check_steps`])
//! Every step is sampled (rotations every [`ROTATION_SAMPLE`], rolls 8
//! times, still steps at their ends) and the grasp that carries the load —
//! tracked through placements, handovers and lifts exactly as the executor
//! does — is evaluated with the closed form of [`crate::grasp::grip`],
//! with the acceleration bound ±α_max along a rotation's axis. Both ends of
//! every handover must hold (the blend between them then does). A plan that
//! fails is not returned.

use nalgebra::Vector3;

use super::geometry::{Sinusoid, any_perpendicular, rotation};
use super::plan::{Motion, Step};
use crate::HandConfig;
use crate::grasp::grip::{CARRY_BITS, Grip, GripModel, grasp_mask};
use crate::grasp::hold::{Accel, HoldModel, ICOSAHEDRON_RATIO};
use crate::hand_state::HandState;

/// Largest rotation between two exact checks of a Rotate step \[rad\] (3°).
pub const ROTATION_SAMPLE: f64 = 3.0 * std::f64::consts::PI / 180.0;

/// Samples per roll step in the exact check.
pub(crate) const ROLL_SAMPLES: usize = 8;

/// Step of [`PairLoad::exit`]'s scan \[rad\] (5°), refined by bisection
/// to 0.02°.
const EXIT_STEP: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// The search's closed-form load test for soft pairs (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLoad {
    radius: f64,
    mu: f64,
    torsion_scale: f64,
    min_grip: f64,
    max_grip: f64,
    weight: Vector3<f64>,
    disturbance: f64,
    torque: f64,
    inertia_torque: f64,
    /// Whether there is any load to hold beyond the squeeze floor (with
    /// none, the test reduces to force closure and is skipped).
    active: bool,
    /// The closed form of `grasp::hold` (what a plan is checked with), or
    /// `None`: where the sufficient test fails, ask it too.
    exact: Option<HoldModel>,
    /// α_max for the exact model \[rad/s²\].
    max_accel: f64,
}

impl PairLoad {
    /// From a validated configuration.
    pub fn new(c: &HandConfig) -> Self {
        let m = &c.model;
        let l = &c.load;
        let theta = m.friction_angle_deg.to_radians() - 0.5 * m.fc_margin_deg.to_radians();
        let weight = Vector3::from(l.gravity) * l.object_mass;
        let inertia = 0.4 * l.object_mass * m.object_radius * m.object_radius;
        let inertia_torque = inertia * c.limits.object.acceleration;
        Self {
            radius: m.object_radius,
            mu: theta.tan(),
            torsion_scale: c.mu() / c.mu_torsion(),
            min_grip: l.min_grip,
            max_grip: l.max_grip,
            weight,
            disturbance: ICOSAHEDRON_RATIO * l.disturbance_force,
            torque: ICOSAHEDRON_RATIO * l.disturbance_torque,
            inertia_torque,
            active: weight.norm() > 0.0
                || l.disturbance_force > 0.0
                || l.disturbance_torque > 0.0
                || inertia_torque > 0.0,
            exact: None,
            max_accel: c.limits.object.acceleration,
        }
    }

    /// The same test, and where it fails the exact closed form of
    /// `grasp::hold` as well (the model a plan is checked with). It
    /// accepts more pairs (119 against 102 of 400 random pairs 140–180°
    /// apart, `gait/tests/load_exact.rs`) but costs far more per refused
    /// pair (~1 µs against ~0.1 µs): the planner asks its hold table
    /// ([`super::fingertips::hold_table`]) first.
    pub fn with_exact(&self, c: &HandConfig) -> Self {
        Self {
            exact: Some(HoldModel::new(c)),
            ..*self
        }
    }

    /// The exact model's verdict for the pair holding `w`.
    fn exact_holds(
        &self,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        w: &Vector3<f64>,
        axis: Option<&Vector3<f64>>,
    ) -> bool {
        self.exact.is_some_and(|m| {
            let accel = axis.map_or(Accel::None, |k| Accel::About {
                axis: *k,
                max: self.max_accel,
            });
            m.pair_holds(&[*n1, *n2], &m.loads_with_weight(*w, accel))
        })
    }

    /// F* of the exact model for the pair holding the configured weight at
    /// rest (`None` without the exact model; +∞ where nothing holds).
    pub fn exact_peak(&self, n1: &Vector3<f64>, n2: &Vector3<f64>) -> Option<f64> {
        self.exact.map(|m| {
            m.pair(&[*n1, *n2], &m.loads_with_weight(self.weight, Accel::None))
                .max_peak
        })
    }

    /// The largest normal force a pair may need (`load.max_grip`) \[N\].
    pub fn max_grip(&self) -> f64 {
        self.max_grip
    }

    /// Whether the test constrains anything.
    pub fn active(&self) -> bool {
        self.active
    }

    /// The pair's frame and the parts of the test that do not depend on
    /// the weight's direction (rotating about `axis`, or at rest).
    fn frame(
        &self,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        axis: Option<&Vector3<f64>>,
    ) -> Option<PairFrame> {
        let sum = n1 + n2;
        let diff = n2 - n1;
        let a = 0.5 * sum.norm();
        let b = 0.5 * diff.norm();
        if b < 1e-9 {
            return None;
        }
        let u = diff / (2.0 * b);
        let c_hat = if a > 1e-9 {
            sum / (2.0 * a)
        } else {
            any_perpendicular(&u)
        };
        let nu = u.cross(&c_hat);
        let r = self.radius;
        let s = self.torsion_scale;
        // Known: the acceleration torque about the axis (both signs).
        // Unknown: the disturbance force (|d| ≤ D) and torque (by norm).
        let known = axis.map_or(Vector3::zeros(), |k| {
            Vector3::new(k.dot(&c_hat), k.dot(&u), k.dot(&nu)) * self.inertia_torque
        });
        let tq = self.torque;
        let d = self.disturbance;
        // Worst change of N, and of the cone's left side, per unit of the
        // unknowns: the norm at the known load plus the map's norm, or the
        // norm of the componentwise bounds (rows: in-plane, along ν,
        // torsion); both hold, the smaller is used.
        let rho_n = d * (0.25 * a * a + 0.25 / (b * b)).sqrt() + tq * a / (2.0 * r * b);
        let rows = [
            0.5 * b * d + tq * 0.5 / r,
            0.5 * d + tq * 0.5 / (r * b),
            s * r * a * d / (2.0 * b) + tq * 0.5 * s / b,
        ];
        let rho_need = d * (0.5 * b).max((0.25 + (s * r * a / (2.0 * b)).powi(2)).sqrt())
            + tq * (0.5 / r).max(0.5 / (r * b)).max(0.5 * s / b);
        Some(PairFrame {
            a,
            b,
            axes: [c_hat, u, nu],
            known,
            rho_n,
            rows,
            rho_need,
        })
    }

    /// The test's slack \[N\] for the weight components (ĉ, u, ν); with
    /// `sign_only`, any negative value as soon as one is found.
    fn slack_in(&self, p: &PairFrame, ec: f64, eu: f64, en: f64, sign_only: bool) -> f64 {
        self.margins_in(p, ec, eu, en, sign_only).slack
    }

    /// [`PairLoad::slack_in`] with the squeeze F and the least N₀ − ρ_N
    /// behind it (meaningful where the slack is ≥ 0).
    fn margins_in(&self, p: &PairFrame, ec: f64, eu: f64, en: f64, sign_only: bool) -> Margins {
        let fail = |slack| Margins {
            slack,
            squeeze: 0.0,
            normal: 0.0,
        };
        let (a, b) = (p.a, p.b);
        let r = self.radius;
        let s = self.torsion_scale;
        // Quick reject: the torsion alone needs more than any normal can
        // carry (μ N ≤ μ F_max).
        let tors_low = s * (r * a * en.abs() - p.known.y.abs()) / (2.0 * b) - p.rows[2];
        if sign_only && tors_low > self.mu * self.max_grip {
            return fail(-1.0);
        }
        let mut terms = [(0.0, 0.0, 0.0, 0.0); 4];
        let mut f = f64::INFINITY;
        // At rest both signs of the acceleration are the same case.
        let signs = if p.known == Vector3::zeros() { 1 } else { 2 };
        for (idx, sign) in [1.0, -1.0].into_iter().enumerate().take(signs) {
            let t = p.known * sign;
            let (tc, tu, tn) = (t.x, t.y, t.z);
            let tors = s * (r * a * en + tu) / (2.0 * b);
            for (c, sigma) in [1.0, -1.0].into_iter().enumerate() {
                let n0 = 0.5 * a * ec - sigma * eu / (2.0 * b) + sigma * a * tn / (2.0 * r * b);
                let in0 = -0.5 * b * ec - sigma * tn / (2.0 * r);
                let along = -0.5 * en + sigma * tc / (2.0 * r * b);
                terms[2 * idx + c] = (n0, in0, along, tors);
                f = f.min((self.max_grip - n0 - p.rho_n) / b);
            }
        }
        if f <= 0.0 {
            return fail(f);
        }
        let mut slack = f64::INFINITY;
        let mut normal = f64::INFINITY;
        for &(n0, in0, along, tors) in &terms[..2 * signs] {
            let n = b * f + n0 - p.rho_n;
            if n < self.min_grip {
                return fail(n - self.min_grip);
            }
            normal = normal.min(n);
            let x = [(a * f + in0).abs(), along.abs(), tors.abs()];
            let by_norm = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt() + p.rho_need;
            let by_rows = ((x[0] + p.rows[0]).powi(2)
                + (x[1] + p.rows[1]).powi(2)
                + (x[2] + p.rows[2]).powi(2))
            .sqrt();
            slack = slack.min(self.mu * n - by_norm.min(by_rows));
            if sign_only && slack < 0.0 {
                return fail(slack);
            }
        }
        Margins {
            slack,
            squeeze: f,
            normal,
        }
    }

    /// How far \[N\] the weight's components (ĉ, u, ν) can move from where
    /// `m` was found (a passing test) and the test still pass: each
    /// quantity of [`PairLoad::margins_in`] is Lipschitz in them, with the
    /// constants below read off its affine parts (module docs):
    /// N₀ has gradient (a/2, ∓1/(2b), 0), so F moves by at most |∇N₀|/b and
    /// N₀ − ρ_N by 2|∇N₀|; the cone's left side by at most |∇x| with
    /// x = (a F + in-plane₀, ν₀, τ₀ μ/μ_t).
    fn reach(&self, p: &PairFrame, m: &Margins) -> f64 {
        if m.slack < 0.0 {
            return 0.0;
        }
        let (a, b) = (p.a, p.b);
        let grad_n = (0.25 * a * a + 0.25 / (b * b)).sqrt();
        let grad_x = ((a * grad_n / b + 0.5 * b).powi(2)
            + 0.25
            + (self.torsion_scale * self.radius * a / (2.0 * b)).powi(2))
        .sqrt();
        (m.squeeze * b / grad_n)
            .min((m.normal - self.min_grip) / (2.0 * grad_n))
            .min(m.slack / (2.0 * self.mu * grad_n + grad_x))
            .max(0.0)
    }

    /// Slack \[N\] of the sufficient condition (module docs) for the soft
    /// pair at unit normals `n1`, `n2` holding the weight `w` (hand frame),
    /// while rotating about the unit `axis` at up to the acceleration
    /// limit (`None`: at rest). ≥ 0: the pair holds the load.
    pub fn slack_with(
        &self,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        w: &Vector3<f64>,
        axis: Option<&Vector3<f64>>,
    ) -> f64 {
        match self.frame(n1, n2, axis) {
            Some(p) => self.slack_in(
                &p,
                w.dot(&p.axes[0]),
                w.dot(&p.axes[1]),
                w.dot(&p.axes[2]),
                false,
            ),
            None => f64::NEG_INFINITY,
        }
    }

    /// [`PairLoad::slack_with`] for the configured weight.
    pub fn slack(&self, n1: &Vector3<f64>, n2: &Vector3<f64>, axis: Option<&Vector3<f64>>) -> f64 {
        if !self.active {
            return f64::INFINITY;
        }
        self.slack_with(n1, n2, &self.weight, axis)
    }

    /// Whether the pair holds the load now (rotating about `axis`, or at
    /// rest).
    pub fn holds(&self, n1: &Vector3<f64>, n2: &Vector3<f64>, axis: Option<&Vector3<f64>>) -> bool {
        if !self.active {
            return true;
        }
        let w = &self.weight;
        // Quick reject (most candidates): the torsion the weight's moment
        // about the chord needs, less what the acceleration could give
        // back, beyond what any normal can carry. |n1 × n2| = 2ab and the
        // plane normal is ν = ±(n1 × n2)/(2ab).
        let cross = n1.cross(n2);
        let ab2 = cross.norm();
        if ab2 > 1e-9 {
            let a = 0.5 * (n1 + n2).norm();
            let b = 0.5 * (n2 - n1).norm();
            let en = w.dot(&cross).abs() / ab2;
            let r = self.radius;
            let slack_torque = axis.map_or(0.0, |_| self.inertia_torque) + self.torque;
            let low =
                self.torsion_scale * (r * a * (en - self.disturbance) - slack_torque) / (2.0 * b);
            if low > self.mu * self.max_grip {
                return false;
            }
        }
        self.frame(n1, n2, axis).is_some_and(|p| {
            self.slack_in(
                &p,
                w.dot(&p.axes[0]),
                w.dot(&p.axes[1]),
                w.dot(&p.axes[2]),
                true,
            ) >= 0.0
        }) || self.exact_holds(n1, n2, w, axis)
    }

    /// Whether the pair holds the load turning about *any* axis at up to
    /// the acceleration limit: the sufficient test with the acceleration
    /// torque among the unknown disturbances (a ball of radius I α_max);
    /// no exact fallback. Independent of the axis, so its verdicts can be
    /// kept across goals.
    pub fn holds_turning(&self, n1: &Vector3<f64>, n2: &Vector3<f64>) -> bool {
        if !self.active {
            return true;
        }
        let any = Self {
            torque: self.torque + self.inertia_torque,
            exact: None,
            ..*self
        };
        any.holds(n1, n2, None)
    }

    /// How far (rad, at most `limit`) the pair can rotate about the unit
    /// `axis` and still hold the load: 0 if it does not now, `limit` if it
    /// does all the way. Scans every 5° and bisects the first failure.
    /// The pair turned by t sees the weight turned by −t: its components
    /// in the pair's frame are sinusoids in t, moving at |k × w| per
    /// radian, so a passing sufficient test vouches for the scan's angles
    /// within its reach (`reach`) and those are not asked again (the
    /// result is the plain scan's).
    pub fn exit(
        &self,
        n1: &Vector3<f64>,
        n2: &Vector3<f64>,
        axis: &Vector3<f64>,
        limit: f64,
    ) -> f64 {
        if !self.active {
            return limit;
        }
        let Some(p) = self.frame(n1, n2, Some(axis)) else {
            return 0.0;
        };
        // w · Rot(k, t) e = A + B cos t + C sin t for each frame axis e.
        let waves = p.axes.map(|e| Sinusoid::new(axis, &e, &self.weight));
        // The components move at |k × w| per radian: a passing test at t
        // holds on to t + reach / rate.
        let rate = axis.cross(&self.weight).norm();
        let ok = |t: f64| {
            let (sin, cos) = t.sin_cos();
            let c = waves.map(|w| w.a + w.b * cos + w.c * sin);
            let m = self.margins_in(&p, c[0], c[1], c[2], true);
            if m.slack >= 0.0 {
                // Shrunk a little against rounding at the far end.
                let sure = 0.999 * self.reach(&p, &m) / rate;
                return (true, if sure.is_nan() { 0.0 } else { sure });
            }
            // The exact model's disturbance vertices are fixed in the hand
            // frame, as in the plan's check: turn the contacts, not the
            // weight.
            let q = rotation(axis, t);
            let held = self.exact_holds(&(q * n1), &(q * n2), &self.weight, Some(axis));
            (held, 0.0)
        };
        scan_exit(limit, EXIT_STEP, ok)
    }
}

/// The first angle in [0, `limit`] where `ok` fails, by a scan every
/// `step` and a bisection of the first failure (0 if it fails at 0,
/// `limit` if it never does). A full turn brings the load back, so one
/// turn decides beyond it. `ok(t)` also says how far beyond t it surely
/// still holds: the scan does not ask there (its answer would be yes).
fn scan_exit(limit: f64, step: f64, ok: impl Fn(f64) -> (bool, f64)) -> f64 {
    let (held, mut sure) = ok(0.0);
    if !held {
        return 0.0;
    }
    let ok = |t: f64, sure: &mut f64| {
        if t <= *sure {
            return true;
        }
        let (held, beyond) = ok(t);
        if held {
            *sure = t + beyond;
        }
        held
    };
    let span = limit.min(std::f64::consts::TAU);
    let mut good = 0.0;
    loop {
        let t = (good + step).min(span);
        if !ok(t, &mut sure) {
            let mut bad = t;
            for _ in 0..8 {
                let mid = 0.5 * (good + bad);
                if ok(mid, &mut sure) {
                    good = mid;
                } else {
                    bad = mid;
                }
            }
            return good;
        }
        good = t;
        if good >= span {
            return limit;
        }
    }
}

/// The test's slack and the margins of its other conditions (F > 0,
/// N₀ − ρ_N ≥ `min_grip`) \[N\].
#[derive(Debug, Clone, Copy)]
struct Margins {
    slack: f64,
    squeeze: f64,
    normal: f64,
}

/// A pair's frame (ĉ, u, ν), its a = cos(θ/2), b = sin(θ/2), the known
/// acceleration torque in that frame and the bounds of the unknowns.
#[derive(Debug, Clone, Copy)]
struct PairFrame {
    a: f64,
    b: f64,
    axes: [Vector3<f64>; 3],
    known: Vector3<f64>,
    rho_n: f64,
    rows: [f64; 3],
    rho_need: f64,
}

/// Where a plan's exact load check failed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadViolation {
    /// Step index.
    pub step: usize,
    /// Largest normal force needed there (+∞: no grip holds) \[N\].
    pub peak: f64,
}

/// The largest forces along a plan (the samples of [`check_steps`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlanForces {
    /// Largest F* (normal force over all load scenarios) \[N\].
    pub max_peak: f64,
    /// Largest commanded (weight-only) normal force \[N\].
    pub max_normal: f64,
}

/// The exact check of a built plan (module docs): every sample's carrying
/// grasp holds the load within `load.max_grip`.
pub fn check_steps(
    grip: &GripModel,
    max_acceleration: f64,
    start: &HandState,
    steps: &[Step],
) -> Result<(), LoadViolation> {
    let mut bad = None;
    visit_steps(grip, max_acceleration, start, steps, |i, g| {
        if !g.feasible && bad.is_none() {
            bad = Some(LoadViolation {
                step: i,
                peak: g.peak,
            });
        }
        bad.is_none()
    });
    bad.map_or(Ok(()), Err)
}

/// The largest forces the samples of [`check_steps`] need.
pub fn plan_forces(
    grip: &GripModel,
    max_acceleration: f64,
    start: &HandState,
    steps: &[Step],
) -> PlanForces {
    let mut out = PlanForces::default();
    visit_steps(grip, max_acceleration, start, steps, |_, g| {
        out.max_peak = out.max_peak.max(g.peak);
        out.max_normal = out
            .max_normal
            .max(g.normal.iter().copied().fold(0.0, f64::max));
        true
    });
    out
}

/// Calls `f(step, grip)` for every sample of every step (module docs)
/// until it returns false.
fn visit_steps(
    grip: &GripModel,
    max_acceleration: f64,
    start: &HandState,
    steps: &[Step],
    mut f: impl FnMut(usize, &Grip) -> bool,
) {
    let mut carrying = grasp_mask(start);
    for (i, st) in steps.iter().enumerate() {
        let d = st.dofs();
        let at = |lam: f64| st.eval(&d.length.map(|l| l * lam), &[0.0; 3]).state;
        match st.motion {
            Motion::Rotate { axis, angle, .. } | Motion::Carry { axis, angle, .. }
                if angle > 0.0 =>
            {
                let n = (angle / ROTATION_SAMPLE).ceil().max(1.0) as usize;
                let accel = Accel::About {
                    axis,
                    max: max_acceleration,
                };
                for k in 0..=n {
                    let g = grip.carried_with(&at(k as f64 / n as f64), accel, carrying);
                    if !f(i, &g) {
                        return;
                    }
                }
            }
            Motion::Roll { .. } | Motion::RollSegment { .. } => {
                // Rolling or spinning contacts: three hold as hard contacts
                // (no pair of them on its own: a spinning one has no
                // torsion), two as soft.
                for k in 0..=ROLL_SAMPLES {
                    let s = at(k as f64 / ROLL_SAMPLES as f64);
                    let g = if carrying & CARRY_BITS & grasp_mask(&s) == CARRY_BITS
                        && carrying >> 3 == 0
                    {
                        grip.triple(&s, Accel::None)
                    } else {
                        grip.carried_with(&s, Accel::None, carrying)
                    };
                    if !f(i, &g) {
                        return;
                    }
                }
            }
            _ => {
                // Still grasp: the fingers that stay in contact throughout.
                let end = at(1.0);
                let set = carrying & grasp_mask(&st.start) & grasp_mask(&end);
                if !f(i, &grip.carried_with(&st.start, Accel::None, set)) {
                    return;
                }
            }
        }
        let end = st.eval(&d.length, &[0.0; 3]).state;
        let grasp = grasp_mask(&end);
        let joined = grasp & !grasp_mask(&st.start);
        let take = st.handover.map_or(0, |h| h.take_mask());
        carrying = (carrying | (joined & !take)) & (grasp | grasp << 3);
        if (carrying & CARRY_BITS).count_ones() < 2 {
            carrying = grasp;
        }
        if let Some(h) = st.handover.filter(|h| h.duration > 0.0) {
            if !f(i, &grip.carried_with(&end, Accel::None, carrying)) {
                return;
            }
            carrying = h.target(carrying);
            if !f(i, &grip.carried_with(&end, Accel::None, carrying)) {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
        loop {
            let v = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            );
            if v.norm() > 0.1 && v.norm() < 1.0 {
                return v.normalize();
            }
        }
    }

    /// The reach of a passing test is a radius, in the weight's components,
    /// within which it still passes: from random pairs (130–180° apart),
    /// axes and weights, every direction probed fails no nearer than the
    /// reach (the scan of [`PairLoad::exit`] skips on it). The least ratio
    /// of the distance to the failure over the reach says how tight it is.
    #[test]
    fn a_passing_test_passes_within_its_reach() {
        let cfg = HandConfig::default();
        let load = PairLoad::new(&cfg);
        let w = load.weight.norm();
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let (mut probed, mut tightest) = (0, f64::INFINITY);
        while probed < 4000 {
            let (n1, n2) = (unit(&mut rng), unit(&mut rng));
            if n1.dot(&n2) > 130f64.to_radians().cos() {
                continue;
            }
            let axis = rng.random_bool(0.5).then(|| unit(&mut rng));
            let Some(p) = load.frame(&n1, &n2, axis.as_ref()) else {
                continue;
            };
            let c = unit(&mut rng) * w * rng.random_range(0.0..3.0);
            let m = load.margins_in(&p, c.x, c.y, c.z, true);
            let reach = load.reach(&p, &m);
            if m.slack < 0.0 || reach <= 1e-9 {
                continue;
            }
            for _ in 0..8 {
                probed += 1;
                let d = unit(&mut rng);
                let passes = |s: f64| {
                    let e = c + d * s;
                    load.slack_in(&p, e.x, e.y, e.z, true) >= 0.0
                };
                // The first failure along d, to 1e-6 of the reach.
                let (mut good, mut bad) = (0.0, reach);
                while passes(bad) {
                    good = bad;
                    bad *= 2.0;
                    if bad > 1e3 * reach {
                        break;
                    }
                }
                if passes(bad) {
                    continue;
                }
                while bad - good > 1e-6 * reach {
                    let mid = 0.5 * (good + bad);
                    if passes(mid) {
                        good = mid;
                    } else {
                        bad = mid;
                    }
                }
                assert!(
                    good >= reach * (1.0 - 1e-6),
                    "fails {good:.4e} N away, inside its reach {reach:.4e} N \
                     ({n1:?}, {n2:?}, axis {axis:?}, weight {c:?})"
                );
                tightest = tightest.min(good / reach);
            }
        }
        println!("{probed} directions probed; the nearest failure at {tightest:.2} × the reach");
        assert!(
            tightest.is_finite(),
            "no failure found to measure the bound against"
        );
    }
}

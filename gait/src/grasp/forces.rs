//! Grasp force optimisation (SPEC.md §3.3).
//!
//! # What is computed
//! Contact forces f⁰ that balance the object's weight m·g, chosen so that
//! the grasp also holds **any disturbance** (d_f, d_τ) — a force through O
//! with |d_f| ≤ F_d (`load.disturbance_force`) together with a torque about
//! O with |d_τ| ≤ T_d (`load.disturbance_torque`) — while minimising the
//! largest normal force that occurs.
//!
//! # Disturbance response model (stated, and tested)
//! A rigid-body grasp is statically indeterminate, so "the grasp holds a
//! disturbance" needs a model of how the contacts share it. Here the
//! contacts behave like equal isotropic springs: a disturbance wrench δw
//! adds the minimum-norm force increment Δf = −G⁺ δw, G⁺ = Gᵀ(G Gᵀ)⁻¹, with
//! G the normalised grasp map of [`super::contact`] (torques divided by R,
//! torsion measured as s = τ_n μ/μ_t). The problem is
//!
//! ```text
//! minimise  F + ε Σ_i f⁰_n,i
//! s.t.  G f⁰ = −(m g, 0)                                   (weight)
//!       f⁰ − G⁺ δw ∈ K  and  f⁰_n,i − (G⁺ δw)_n,i ≤ F  ∀ i,   ∀ δw ∈ D
//! ```
//!
//! with K the product of friction cones ‖(f_1, f_2 \[, s\])‖ ≤ μ f_n. The
//! constraint set is convex in δw, so it suffices to impose it at the
//! vertices of a polytope containing D: the octahedra {|d|₁ ≤ √3 F_d} ⊇
//! {|d|₂ ≤ F_d} (vertices ±√3 F_d e_a), and likewise for torques — 6
//! scenarios when one of F_d, T_d is 0, 36 when both are positive, plus the
//! weight-only scenario. The result is therefore guaranteed (every
//! disturbance of the stated size is held under the model) and conservative
//! by at most √3 along the vertex directions. F is the peak normal force
//! the fingers must be able to apply; f⁰ is what the controller commands
//! (it includes the squeeze that makes room for the disturbance). The
//! tie-break ε = [`TIE_BREAK`] picks the least squeeze among min–max
//! optimal solutions and costs at most a factor (1 + ε k) on F (k
//! contacts), checked in the tests against ε = 0. With a disturbance, G
//! must have rank 6 (otherwise some disturbance cannot be held:
//! [`GraspError::Infeasible`]).
//!
//! Orders of magnitude at the default load (0.1 kg, F_d = 0.5 N): the
//! paper's start grasp needs 1.69 N per finger (peak 1.98 N), an antipodal
//! soft pair 2.54 N, a soft pair 143° apart (3° inside Fact 3) 108 N —
//! near the force-closure boundary the equal-spring response uses friction
//! poorly, so grip forces grow quickly; keep pairs well inside the margin
//! or lower F_d.
//!
//! Only the 6 equilibrium rows of the constraint matrix change with the
//! contacts; the scenario data go into the right-hand side. It is an SOCP
//! solved with Clarabel, built once per (contact kinds, scenario count) and
//! re-solved with `update_A`/`update_b`. It is not a per-tick computation
//! (see the benchmarks): run it when the plan is made or the grasp changes.

use clarabel::solver::{
    DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus, SupportedConeT,
    ZeroConeT,
};
use nalgebra::{Vector3, Vector6};

use super::GraspError;
use super::contact::{
    Contact, ContactFrame, ContactKind, Friction, grasp_columns, grasp_gram, grasp_rank,
};
use super::load_socp::LoadRows;
use super::socp::{self, CscBuilder, EntrySink, ValueWriter};
use crate::HandConfig;

/// Weight ε of the tie-breaking Σ f_n term in the objective.
pub const TIE_BREAK: f64 = 1e-3;

/// The load the grasp must hold (SPEC §3.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Load {
    /// Weight m·g of the object, hand frame \[N\].
    pub weight: Vector3<f64>,
    /// Disturbance force magnitude F_d \[N\], any direction, through O.
    pub disturbance_force: f64,
    /// Disturbance torque magnitude T_d \[N·m\], any axis, about O.
    pub disturbance_torque: f64,
}

impl Load {
    /// The configuration's load: m·g, `load.disturbance_force`,
    /// `load.disturbance_torque`.
    pub fn from_config(config: &HandConfig) -> Self {
        let l = &config.load;
        Self {
            weight: Vector3::from(l.gravity) * l.object_mass,
            disturbance_force: l.disturbance_force,
            disturbance_torque: l.disturbance_torque,
        }
    }

    fn is_valid(&self) -> bool {
        self.weight.iter().all(|v| v.is_finite())
            && self.disturbance_force.is_finite()
            && self.disturbance_force >= 0.0
            && self.disturbance_torque.is_finite()
            && self.disturbance_torque >= 0.0
    }

    /// Number of scenarios: 1 + (6 or 36 or 0).
    pub fn scenario_count(&self) -> usize {
        let f = if self.disturbance_force > 0.0 { 6 } else { 1 };
        let t = if self.disturbance_torque > 0.0 { 6 } else { 1 };
        if f * t == 1 { 1 } else { 1 + f * t }
    }

    /// External wrench (force \[N\], torque about O \[N·m\]) of scenario `s`:
    /// s = 0 is the weight alone, then weight plus octahedron vertices.
    pub fn scenario(&self, s: usize) -> (Vector3<f64>, Vector3<f64>) {
        let w = self.weight;
        if s == 0 {
            return (w, Vector3::zeros());
        }
        let vertex = |i: usize, size: f64| {
            let mut v = Vector3::zeros();
            v[i / 2] = if i.is_multiple_of(2) { size } else { -size } * 3f64.sqrt();
            v
        };
        let i = s - 1;
        let (fi, ti) = if self.disturbance_torque > 0.0 && self.disturbance_force > 0.0 {
            (Some(i / 6), Some(i % 6))
        } else if self.disturbance_force > 0.0 {
            (Some(i), None)
        } else {
            (None, Some(i))
        };
        let f = fi.map_or(Vector3::zeros(), |i| vertex(i, self.disturbance_force));
        let t = ti.map_or(Vector3::zeros(), |i| vertex(i, self.disturbance_torque));
        (w + f, t)
    }
}

/// The force one contact applies to the object.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactForce {
    /// Commanded normal (grip) force f_n \[N\], ≥ 0.
    pub normal: f64,
    /// Total contact force on the object in the weight-only scenario,
    /// hand frame \[N\]: f_n (−n) + tangential part.
    pub force: Vector3<f64>,
    /// Torsional moment τ_n about the inward normal −n, weight-only
    /// scenario \[N·m\] (0 for hard contacts).
    pub torsion: f64,
}

/// Summary of one optimisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceSolution {
    /// The largest commanded normal force max_i f⁰_n,i \[N\].
    pub max_normal: f64,
    /// The largest normal force over the weight-only and all disturbance
    /// scenarios \[N\] (the optimised F: what the fingers must be able to
    /// apply).
    pub peak_normal: f64,
    /// Interior-point iterations.
    pub iterations: u32,
}

struct Problem {
    kinds: Vec<ContactKind>,
    scenarios: usize,
    solver: DefaultSolver<f64>,
    values: Vec<f64>,
    b: Vec<f64>,
}

/// Re-solvable grasp force optimiser (SPEC §3.3), see the module docs.
pub struct GraspForceSolver {
    friction: Friction,
    load: Load,
    tie_break: f64,
    problem: Option<Problem>,
}

impl core::fmt::Debug for GraspForceSolver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("GraspForceSolver")
            .field("friction", &self.friction)
            .field("load", &self.load)
            .field("tie_break", &self.tie_break)
            .finish()
    }
}

/// Row layout: 6 equilibrium rows, then S·D cone rows (scenario-major),
/// then S·k rows F − f_n,i − Δ_n,i ≥ 0.
struct Layout {
    k: usize,
    d_sum: usize,
    scenarios: usize,
}

impl Layout {
    fn new(kinds: impl Iterator<Item = ContactKind> + Clone, scenarios: usize) -> Self {
        Self {
            k: kinds.clone().count(),
            d_sum: kinds.map(|c| c.dim()).sum(),
            scenarios,
        }
    }
    fn cone_row(&self, s: usize, off: usize) -> usize {
        6 + s * self.d_sum + off
    }
    fn cap_row(&self, s: usize, i: usize) -> usize {
        6 + self.scenarios * self.d_sum + s * self.k + i
    }
    fn rows(&self) -> usize {
        6 + self.scenarios * (self.d_sum + self.k)
    }
    fn vars(&self) -> usize {
        self.d_sum + 1
    }
}

fn emit<S: EntrySink>(contacts: &[Contact], friction: &Friction, lay: &Layout, sink: &mut S) {
    let mut off = 0;
    for (i, c) in contacts.iter().enumerate() {
        let g = grasp_columns(c, friction);
        for (j, col) in g.iter().enumerate().take(c.kind.dim()) {
            // Equilibrium rows: the normal column has no torque, the
            // torsion column no force (identically, on a sphere).
            let rows = match j {
                0 => 0..3,
                3 => 3..6,
                _ => 0..6,
            };
            for r in rows {
                sink.push(r, col[r]);
            }
            let top = if j == 0 { -friction.mu } else { -1.0 };
            for s in 0..lay.scenarios {
                sink.push(lay.cone_row(s, off + j), top);
            }
            if j == 0 {
                for s in 0..lay.scenarios {
                    sink.push(lay.cap_row(s, i), 1.0);
                }
            }
            sink.end_column();
        }
        off += c.kind.dim();
    }
    for s in 0..lay.scenarios {
        for i in 0..lay.k {
            sink.push(lay.cap_row(s, i), -1.0);
        }
    }
    sink.end_column();
}

/// Right-hand side: weight in the equilibrium rows, the scenario force
/// increments Δ = −G⁺ δw in the cone and cap rows. Fails when a
/// disturbance is asked for and G has rank < 6.
fn fill_b(
    contacts: &[Contact],
    load: &Load,
    friction: &Friction,
    lay: &Layout,
    b: &mut [f64],
) -> Result<(), GraspError> {
    b.fill(0.0);
    let inv_r = 1.0 / friction.object_radius;
    let (w, _) = load.scenario(0);
    for r in 0..3 {
        b[r] = -w[r];
    }
    if lay.scenarios == 1 {
        return Ok(());
    }
    if grasp_rank(contacts, friction) < 6 {
        return Err(GraspError::Infeasible);
    }
    let Some(chol) = grasp_gram(contacts, friction).cholesky() else {
        return Err(GraspError::Infeasible);
    };
    for s in 1..lay.scenarios {
        let (f, t) = load.scenario(s);
        let dw = Vector6::new(
            f.x - w.x,
            f.y - w.y,
            f.z - w.z,
            t.x * inv_r,
            t.y * inv_r,
            t.z * inv_r,
        );
        let y = chol.solve(&dw);
        let mut off = 0;
        for (i, c) in contacts.iter().enumerate() {
            let g = grasp_columns(c, friction);
            for (j, col) in g.iter().enumerate().take(c.kind.dim()) {
                let delta = -col.dot(&y);
                if j == 0 {
                    b[lay.cone_row(s, off)] = friction.mu * delta;
                    b[lay.cap_row(s, i)] = -delta;
                } else {
                    b[lay.cone_row(s, off + j)] = delta;
                }
            }
            off += c.kind.dim();
        }
    }
    Ok(())
}

impl GraspForceSolver {
    /// An optimiser for `friction` and `load` (nothing built yet).
    pub fn new(friction: Friction, load: Load) -> Self {
        Self::with_tie_break(friction, load, TIE_BREAK)
    }

    /// Same with another tie-break weight ε ≥ 0 (0 = pure min–max, whose
    /// grip forces below the maximum are not unique).
    pub fn with_tie_break(friction: Friction, load: Load, tie_break: f64) -> Self {
        Self {
            friction,
            load,
            tie_break,
            problem: None,
        }
    }

    /// The friction used.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// The load used.
    pub fn load(&self) -> Load {
        self.load
    }

    /// Changes the load; a change of scenario count rebuilds on next solve.
    pub fn set_load(&mut self, load: Load) {
        self.load = load;
    }

    /// Builds the problem for these contact kinds unless built. Allocates.
    pub fn prepare(&mut self, kinds: &[ContactKind]) -> Result<(), GraspError> {
        if kinds.is_empty() {
            return Err(GraspError::NoContacts);
        }
        let scenarios = self.load.scenario_count();
        if self
            .problem
            .as_ref()
            .is_some_and(|p| p.kinds == kinds && p.scenarios == scenarios)
        {
            return Ok(());
        }
        let lay = Layout::new(kinds.iter().copied(), scenarios);
        let nominal: Vec<Contact> = kinds
            .iter()
            .enumerate()
            .map(|(i, &kind)| Contact {
                normal: socp::nominal_normal(i, lay.k),
                kind,
            })
            .collect();
        let nominal_friction = Friction::from_config(&HandConfig::default());
        let mut builder = CscBuilder::new(lay.rows());
        emit(&nominal, &nominal_friction, &lay, &mut builder);
        let a = builder.build();
        let values = a.nzval.clone();
        let n = lay.vars();
        let mut q = vec![0.0; n];
        let mut off = 0;
        for kind in kinds {
            q[off] = self.tie_break;
            off += kind.dim();
        }
        q[n - 1] = 1.0;
        let b = vec![0.0; lay.rows()];
        let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(6)];
        for _ in 0..scenarios {
            cones.extend(kinds.iter().map(|c| SecondOrderConeT(c.dim())));
        }
        cones.push(NonnegativeConeT(scenarios * lay.k));
        let mut solver =
            DefaultSolver::new(&socp::zero_p(n), &q, &a, &b, &cones, socp::settings()?)
                .map_err(|_| GraspError::SolverSetup)?;
        // One solve on the nominal data brings clarabel's internal timer
        // maps to their steady state, so later solves allocate only what
        // the crate docs state.
        solver.solve();
        self.problem = Some(Problem {
            kinds: kinds.to_vec(),
            scenarios,
            solver,
            values,
            b,
        });
        Ok(())
    }

    /// Optimises the contact forces for `contacts`, writes one
    /// [`ContactForce`] per contact into `out` (same length). Allocation-free
    /// when the problem for these kinds and the load's scenario count is
    /// built, except for Clarabel's own per-solve allocation (crate docs).
    pub fn solve(
        &mut self,
        contacts: &[Contact],
        out: &mut [ContactForce],
    ) -> Result<ForceSolution, GraspError> {
        if contacts.is_empty() {
            return Err(GraspError::NoContacts);
        }
        if out.len() != contacts.len() {
            return Err(GraspError::OutputLength);
        }
        let ok = self.friction.is_valid()
            && self.load.is_valid()
            && self.tie_break.is_finite()
            && self.tie_break >= 0.0
            && contacts
                .iter()
                .all(|c| c.normal.iter().all(|v| v.is_finite()) && c.normal.norm() > 1e-12);
        if !ok {
            return Err(GraspError::BadInput);
        }
        let scenarios = self.load.scenario_count();
        let same = self.problem.as_ref().is_some_and(|p| {
            p.scenarios == scenarios
                && p.kinds.len() == contacts.len()
                && p.kinds.iter().zip(contacts).all(|(k, c)| *k == c.kind)
        });
        if !same {
            let kinds: Vec<ContactKind> = contacts.iter().map(|c| c.kind).collect();
            self.prepare(&kinds)?;
        }
        let (friction, load) = (self.friction, self.load);
        let Some(p) = self.problem.as_mut() else {
            return Err(GraspError::SolverSetup);
        };
        let lay = Layout::new(contacts.iter().map(|c| c.kind), scenarios);
        let mut writer = ValueWriter::new(&mut p.values);
        emit(contacts, &friction, &lay, &mut writer);
        if !writer.complete() {
            return Err(GraspError::SolverSetup);
        }
        fill_b(contacts, &load, &friction, &lay, &mut p.b)?;
        p.solver
            .update_A(&p.values)
            .map_err(|_| GraspError::SolverSetup)?;
        p.solver
            .update_b(&p.b)
            .map_err(|_| GraspError::SolverSetup)?;
        p.solver.solve();
        let sol = &p.solver.solution;
        match sol.status {
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                return Err(GraspError::Infeasible);
            }
            s if !socp::solved(s) => {
                return Err(GraspError::SolverFailed {
                    iterations: sol.iterations,
                });
            }
            _ => {}
        }
        let x = &sol.x;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(GraspError::SolverFailed {
                iterations: sol.iterations,
            });
        }
        let mut max_normal = 0.0f64;
        let mut off = 0;
        for (c, o) in contacts.iter().zip(out.iter_mut()) {
            let fr = ContactFrame::new(&c.normal);
            let f_n = x[off].max(0.0);
            let torsion = if c.kind == ContactKind::Soft {
                x[off + 3] * friction.mu_torsion / friction.mu
            } else {
                0.0
            };
            *o = ContactForce {
                normal: f_n,
                force: -fr.n * f_n + fr.t1 * x[off + 1] + fr.t2 * x[off + 2],
                torsion,
            };
            max_normal = max_normal.max(f_n);
            off += c.kind.dim();
        }
        // Peak over scenarios, from the data (b holds −Δ_n in the cap rows).
        let mut peak = max_normal;
        let mut off = 0;
        for (i, c) in contacts.iter().enumerate() {
            for s in 1..scenarios {
                peak = peak.max(x[off] - p.b[lay.cap_row(s, i)]);
            }
            off += c.kind.dim();
        }
        Ok(ForceSolution {
            max_normal,
            peak_normal: peak,
            iterations: sol.iterations,
        })
    }
}

/// The largest normal force a grasp needs to hold a set of loads, as an
/// SOCP (SPEC §1.3 I1', §3.3): the reference the closed forms of
/// [`super::hold`] are checked against.
///
/// ```text
/// minimise  F
/// s.t.  G f_s = (−E_s, T_s / R)                    for every scenario s
///       ‖(f_1, f_2 [, τ μ/μ_t])‖ ≤ μ f_n,   floor ≤ f_n ≤ F   (each contact, each s)
/// ```
///
/// with G the normalised grasp map of [`super::contact`] (torques divided
/// by R; the soft contacts' coupled, elliptic cone f_n ≥ √(|f_t|²/μ² +
/// τ²/μ_t²)), E_s the force on the object the contacts must balance and T_s
/// the torque about O they must supply. Each scenario's forces are free:
/// F* is the least force limit under which *every* listed load can be held
/// (F* of SPEC §3.3). Builds a fresh problem per call (allocates): for
/// tests, benchmarks and plan-time studies, not for the tick.
#[derive(Debug, Clone, Copy)]
pub struct LoadSolver {
    friction: Friction,
}

/// The answer of [`LoadSolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadSolution {
    /// F*: the least largest normal force over all scenarios \[N\].
    pub peak_normal: f64,
    /// Interior-point iterations.
    pub iterations: u32,
}

impl LoadSolver {
    /// A solver for `friction` (μ, μ_t, R).
    pub fn new(friction: Friction) -> Self {
        Self { friction }
    }

    /// F* for `contacts` and the loads `scenarios` (force E \[N\], torque T
    /// \[N·m\]), every normal force at least `floor` \[N\].
    /// [`GraspError::Infeasible`] when no forces hold some load.
    pub fn solve(
        &self,
        contacts: &[Contact],
        scenarios: &[(Vector3<f64>, Vector3<f64>)],
        floor: f64,
    ) -> Result<LoadSolution, GraspError> {
        let k = contacts.len();
        let ns = scenarios.len();
        // The caller's rows: f_n,i,s − F ≤ 0, each contact, each scenario.
        let mut rows = LoadRows::new(contacts, &self.friction, scenarios, floor, ns * k)?;
        let f_col = rows.objective();
        for s in 0..ns {
            for i in 0..k {
                rows.push(s * k + i, rows.var(s, i, 0), 1.0);
                rows.push(s * k + i, f_col, -1.0);
            }
        }
        let (x, iterations) = rows.solve(200)?;
        Ok(LoadSolution {
            peak_normal: x[f_col],
            iterations,
        })
    }
}

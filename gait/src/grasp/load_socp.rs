//! What the per-call load SOCPs share ([`super::forces::LoadSolver`],
//! [`super::torque_box::TorqueBoxSolver`]): for every scenario s its own
//! contact forces f_s, which balance the load and sit in the friction
//! cones, every normal force at least a floor (SPEC §1.3 I1'):
//!
//! ```text
//! G f_s = (−E_s, T_s / R)                                every s
//! ‖(f_1, f_2 [, s μ/μ_t])‖ ≤ μ f_n,   f_n ≥ floor       each contact, each s
//! ```
//!
//! (G, f and the torsion variable as in [`super::contact`].) Each solver
//! adds its own linear rows on these variables and one more, the
//! objective, which the solve minimises.

use clarabel::solver::{NonnegativeConeT, SecondOrderConeT, SupportedConeT, ZeroConeT};
use nalgebra::Vector3;

use super::GraspError;
use super::contact::{Contact, Friction, grasp_columns};
use super::socp;

/// The shared rows, then the caller's (module docs).
pub struct LoadRows {
    contacts: usize,
    scenarios: usize,
    /// Variables per scenario (Σ contact dims).
    per_scenario: usize,
    /// Each contact's first variable within a scenario.
    offsets: Vec<usize>,
    dims: Vec<usize>,
    /// Rows before the caller's.
    shared: usize,
    extra: usize,
    entries: Vec<(usize, usize, f64)>,
    b: Vec<f64>,
}

impl LoadRows {
    /// The shared rows for `contacts` under `friction`, the loads
    /// `scenarios` (force E the contacts balance \[N\], torque T they
    /// supply \[N·m\]), normal forces ≥ `floor`, and room for `extra` rows of
    /// the caller. Checks the inputs it is given.
    pub fn new(
        contacts: &[Contact],
        friction: &Friction,
        scenarios: &[(Vector3<f64>, Vector3<f64>)],
        floor: f64,
        extra: usize,
    ) -> Result<Self, GraspError> {
        if contacts.is_empty() || scenarios.is_empty() {
            return Err(GraspError::NoContacts);
        }
        let ok = friction.is_valid()
            && floor.is_finite()
            && floor >= 0.0
            && contacts
                .iter()
                .all(|c| c.normal.iter().all(|v| v.is_finite()) && c.normal.norm() > 1e-12)
            && scenarios
                .iter()
                .all(|(e, t)| e.iter().chain(t.iter()).all(|v| v.is_finite()));
        if !ok {
            return Err(GraspError::BadInput);
        }
        let (k, ns) = (contacts.len(), scenarios.len());
        let dims: Vec<usize> = contacts.iter().map(|c| c.kind.dim()).collect();
        let offsets: Vec<usize> = dims
            .iter()
            .scan(0, |at, d| {
                let o = *at;
                *at += d;
                Some(o)
            })
            .collect();
        let d: usize = dims.iter().sum();
        let (eq_rows, cone_rows) = (6 * ns, ns * d);
        let shared = eq_rows + cone_rows + ns * k;
        let mut rows = Self {
            contacts: k,
            scenarios: ns,
            per_scenario: d,
            offsets,
            dims,
            shared,
            extra,
            entries: Vec::new(),
            b: vec![0.0; shared + extra],
        };
        let cols: Vec<_> = contacts
            .iter()
            .map(|c| grasp_columns(c, friction))
            .collect();
        let inv_r = 1.0 / friction.object_radius;
        for (s, (e, t)) in scenarios.iter().enumerate() {
            let rhs = [-e.x, -e.y, -e.z, t.x * inv_r, t.y * inv_r, t.z * inv_r];
            rows.b[6 * s..6 * s + 6].copy_from_slice(&rhs);
            for (i, columns) in cols.iter().enumerate() {
                for (v, column) in columns.iter().enumerate().take(rows.dims[i]) {
                    let col = rows.var(s, i, v);
                    for (r, &x) in column.iter().enumerate() {
                        if x != 0.0 {
                            rows.entries.push((6 * s + r, col, x));
                        }
                    }
                    let top = if v == 0 { -friction.mu } else { -1.0 };
                    let cone_row = eq_rows + s * d + rows.offsets[i] + v;
                    rows.entries.push((cone_row, col, top));
                }
                let fl = eq_rows + cone_rows + s * k + i;
                rows.entries.push((fl, rows.var(s, i, 0), -1.0));
                rows.b[fl] = -floor;
            }
        }
        Ok(rows)
    }

    /// Variable `v` (f_n, f_1, f_2 \[, s\]) of contact `i` in scenario `s`.
    pub fn var(&self, s: usize, i: usize, v: usize) -> usize {
        s * self.per_scenario + self.offsets[i] + v
    }

    /// The objective's column (after every force variable).
    pub fn objective(&self) -> usize {
        self.scenarios * self.per_scenario
    }

    /// Adds a·x to the caller's row `row` (< `extra`): row ≤ its bound.
    pub fn push(&mut self, row: usize, column: usize, a: f64) {
        self.entries.push((self.shared + row, column, a));
    }

    /// Sets the caller's row `row`'s bound: a·x ≤ `bound`.
    pub fn bound(&mut self, row: usize, bound: f64) {
        self.b[self.shared + row] = bound;
    }

    /// Minimises the objective; the primal solution and the iterations
    /// ([`socp::solve_once`]).
    pub fn solve(self, max_iter: u32) -> Result<(Vec<f64>, u32), GraspError> {
        let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(6 * self.scenarios)];
        for _ in 0..self.scenarios {
            cones.extend(self.dims.iter().map(|&d| SecondOrderConeT(d)));
        }
        cones.push(NonnegativeConeT(
            self.scenarios * self.contacts + self.extra,
        ));
        let objective = self.objective();
        socp::solve_once(
            self.shared + self.extra,
            objective + 1,
            self.entries,
            &self.b,
            &cones,
            objective,
            max_iter,
        )
    }
}

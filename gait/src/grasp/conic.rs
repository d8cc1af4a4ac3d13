//! Exact force-closure test and margin $t^\star$ (SPEC.md §3.2) with
//! Clarabel.
//!
//! Contact $i = 1, \dots, k$ carries the force vector
//! $f_i = (f_{n,i}, f_{1,i}, f_{2,i})$ (normal, then the two tangential
//! components) if it is a hard contact, and
//! $f_i = (f_{n,i}, f_{1,i}, f_{2,i}, s_i)$ with $s_i = \tau_{n,i} \mu / \mu_t$
//! (the torsion about the normal, scaled into the cone) if it is soft.
//! With $G$ the normalised grasp map of [`super::contact`] and
//! $f = (f_1, \dots, f_k)$, the margin is the optimum of the second-order
//! cone program
//!
//! $$\begin{aligned}
//! t^\star = \max_{f, t} \quad & t \\\\
//! \text{s.t.} \quad & G f = 0, \qquad \textstyle\sum_{i=1}^k f_{n,i} = 1, \\\\
//! & \left\lVert (f_{1,i}, f_{2,i}) \right\rVert_2 \le \mu f_{n,i} - t
//! && \text{hard contact } i, \\\\
//! & \left\lVert (f_{1,i}, f_{2,i}, s_i) \right\rVert_2 \le \mu f_{n,i} - t
//! && \text{soft contact } i,
//! \end{aligned}$$
//!
//! one second-order cone per contact. The grasp is force-closure if and
//! only if $\operatorname{rank} G = 6$ and $t^\star > 0$: an internal force
//! strictly inside every friction cone exists. $t^\star \le \mu / k$, and it
//! is dimensionless (a tangential force per unit of total normal force).
//!
//! In Clarabel's form
//!
//! $$\min_x \ q^\top x \quad \text{s.t.} \quad A x + s = b, \quad s \in \mathcal K$$
//!
//! the variables are $x = (f_1, \dots, f_k, t)$ and $q = -e_t$; the rows of
//! $A$ are $6 + 1$ zero-cone rows ($G f = 0$ and $\sum_i f_{n,i} = 1$, so
//! $b = e_7$), then per contact a second-order cone
//! $s = (\mu f_{n,i} - t, f_{1,i}, f_{2,i} [, s_i])$: the cone
//! $\mathcal K = \\{0\\}^7 \times \mathcal Q_1 \times \dots \times \mathcal Q_k$,
//! $\mathcal Q_i$ of dimension 3 (hard) or 4 (soft). Only $A$ changes with
//! the contacts and $\mu$; its pattern is fixed per contact-kind sequence,
//! so a [`ConicSolver`] builds the problem once and re-solves with
//! `update_A` (see the crate docs for the measured allocations per
//! re-solve).

use clarabel::solver::{DefaultSolver, IPSolver, SecondOrderConeT, SupportedConeT, ZeroConeT};

use super::GraspError;
use super::contact::{Contact, ContactKind, Friction, grasp_columns, grasp_rank};
use super::socp::{self, CscBuilder, EntrySink, ValueWriter};

/// Result of the exact test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosureMargin {
    /// Numerical rank of the normalised grasp map (0..=6).
    pub rank: u8,
    /// The margin $t^\star$; `None` when rank < 6 (not force-closure, no solve).
    pub t_star: Option<f64>,
    /// Interior-point iterations used (0 when not solved).
    pub iterations: u32,
}

impl ClosureMargin {
    /// Force closure: rank 6 and $t^\star > 0$.
    pub fn is_force_closure(&self) -> bool {
        self.rank == 6 && self.t_star.is_some_and(|t| t > 0.0)
    }
}

struct Problem {
    kinds: Vec<ContactKind>,
    solver: DefaultSolver<f64>,
    values: Vec<f64>,
}

/// A re-solvable force-closure margin problem (SPEC §3.2).
///
/// The Clarabel problem is built on the first call for a given sequence of
/// contact kinds (this allocates) and reused for every later call with the
/// same sequence: only the values of A are overwritten. A call with a
/// different sequence rebuilds. [`ConicSolver::prepare`] builds ahead of
/// time, e.g. before a control loop starts.
pub struct ConicSolver {
    friction: Friction,
    problem: Option<Problem>,
}

impl core::fmt::Debug for ConicSolver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ConicSolver")
            .field("friction", &self.friction)
            .field("kinds", &self.problem.as_ref().map(|p| p.kinds.as_slice()))
            .finish()
    }
}

/// Emits A's entries in column order for contacts with the given normals.
fn emit<S: EntrySink>(contacts: &[Contact], friction: &Friction, sink: &mut S) {
    let mu = friction.mu;
    let mut soc_row = 7;
    for c in contacts {
        let cols = grasp_columns(c, friction);
        let dim = c.kind.dim();
        // f_n: force rows (torque rows are identically 0 on a sphere),
        // Σ f_n row, cone top.
        for (row, v) in cols[0].iter().take(3).enumerate() {
            sink.push(row, *v);
        }
        sink.push(6, 1.0);
        sink.push(soc_row, -mu);
        sink.end_column();
        // f_1, f_2: all six wrench rows.
        for (j, col) in cols.iter().enumerate().take(3).skip(1) {
            for (row, v) in col.iter().enumerate() {
                sink.push(row, *v);
            }
            sink.push(soc_row + j, -1.0);
            sink.end_column();
        }
        // s: torque rows only.
        if c.kind == ContactKind::Soft {
            for (row, v) in cols[3].iter().enumerate().skip(3) {
                sink.push(row, *v);
            }
            sink.push(soc_row + 3, -1.0);
            sink.end_column();
        }
        soc_row += dim;
    }
    // t: +1 in every cone top.
    let mut soc_row = 7;
    for c in contacts {
        sink.push(soc_row, 1.0);
        soc_row += c.kind.dim();
    }
    sink.end_column();
}

fn valid(contacts: &[Contact], friction: &Friction) -> Result<(), GraspError> {
    if contacts.is_empty() {
        return Err(GraspError::NoContacts);
    }
    let ok = friction.is_valid()
        && contacts
            .iter()
            .all(|c| c.normal.iter().all(|v| v.is_finite()) && c.normal.norm() > 1e-12);
    if ok {
        Ok(())
    } else {
        Err(GraspError::BadInput)
    }
}

impl ConicSolver {
    /// A solver for `friction` (nothing built yet).
    pub fn new(friction: Friction) -> Self {
        Self {
            friction,
            problem: None,
        }
    }

    /// The friction the margins are computed for.
    pub fn friction(&self) -> Friction {
        self.friction
    }

    /// Changes the friction (kept across re-solves; no rebuild).
    pub fn set_friction(&mut self, friction: Friction) {
        self.friction = friction;
    }

    /// Builds the problem for this sequence of contact kinds unless it is
    /// already built. Allocates (once).
    pub fn prepare(&mut self, kinds: &[ContactKind]) -> Result<(), GraspError> {
        if kinds.is_empty() {
            return Err(GraspError::NoContacts);
        }
        if self.problem.as_ref().is_some_and(|p| p.kinds == kinds) {
            return Ok(());
        }
        let nominal: Vec<Contact> = kinds
            .iter()
            .enumerate()
            .map(|(i, &kind)| Contact {
                normal: socp::nominal_normal(i, kinds.len()),
                kind,
            })
            .collect();
        let nominal_friction = Friction::from_config(&crate::HandConfig::default());
        let nvars: usize = kinds.iter().map(|k| k.dim()).sum::<usize>() + 1;
        let nrows = 7 + nvars - 1;
        let mut builder = CscBuilder::new(nrows);
        emit(&nominal, &nominal_friction, &mut builder);
        let a = builder.build();
        let values = a.nzval.clone();
        let mut q = vec![0.0; nvars];
        q[nvars - 1] = -1.0;
        let mut b = vec![0.0; nrows];
        b[6] = 1.0;
        let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(7)];
        cones.extend(kinds.iter().map(|k| SecondOrderConeT(k.dim())));
        let mut solver =
            DefaultSolver::new(&socp::zero_p(nvars), &q, &a, &b, &cones, socp::settings()?)
                .map_err(|_| GraspError::SolverSetup)?;
        // One solve on the nominal data brings clarabel's internal timer
        // maps to their steady state, so later solves allocate only what
        // the crate docs state.
        solver.solve();
        self.problem = Some(Problem {
            kinds: kinds.to_vec(),
            solver,
            values,
        });
        Ok(())
    }

    /// Builds (first time for this kind sequence) or updates, then solves.
    /// Returns the rank of G and, when it is 6, t*. Allocation-free when
    /// the kind sequence matches the built problem, except what Clarabel's
    /// `solve` itself allocates (see the crate docs).
    pub fn margin(&mut self, contacts: &[Contact]) -> Result<ClosureMargin, GraspError> {
        valid(contacts, &self.friction)?;
        let rank = grasp_rank(contacts, &self.friction);
        if rank < 6 {
            return Ok(ClosureMargin {
                rank,
                t_star: None,
                iterations: 0,
            });
        }
        let same = self.problem.as_ref().is_some_and(|p| {
            p.kinds.len() == contacts.len()
                && p.kinds.iter().zip(contacts).all(|(k, c)| *k == c.kind)
        });
        if !same {
            let kinds: Vec<ContactKind> = contacts.iter().map(|c| c.kind).collect();
            self.prepare(&kinds)?;
        }
        let friction = self.friction;
        let Some(p) = self.problem.as_mut() else {
            return Err(GraspError::SolverSetup);
        };
        let mut writer = ValueWriter::new(&mut p.values);
        emit(contacts, &friction, &mut writer);
        if !writer.complete() {
            return Err(GraspError::SolverSetup);
        }
        p.solver
            .update_A(&p.values)
            .map_err(|_| GraspError::SolverSetup)?;
        p.solver.solve();
        let sol = &p.solver.solution;
        if !socp::solved(sol.status) {
            return Err(GraspError::SolverFailed {
                iterations: sol.iterations,
            });
        }
        let t = sol.x[sol.x.len() - 1];
        if !t.is_finite() {
            return Err(GraspError::SolverFailed {
                iterations: sol.iterations,
            });
        }
        Ok(ClosureMargin {
            rank,
            t_star: Some(t),
            iterations: sol.iterations,
        })
    }

    /// The internal force of the last successful solve, in variable order
    /// (per contact f_n, f_1, f_2 \[, s\]; then t). `None` before any solve.
    pub fn last_solution(&self) -> Option<&[f64]> {
        self.problem
            .as_ref()
            .map(|p| p.solver.solution.x.as_slice())
    }
}

/// One-shot margin: builds a fresh solver (allocates), solves once.
pub fn closure_margin(
    contacts: &[Contact],
    friction: &Friction,
) -> Result<ClosureMargin, GraspError> {
    ConicSolver::new(*friction).margin(contacts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HandConfig;
    use nalgebra::Vector3;

    fn eq(deg: f64) -> Vector3<f64> {
        let a = deg.to_radians();
        Vector3::new(a.cos(), a.sin(), 0.0)
    }

    #[test]
    fn paper_start_is_three_finger_fc() {
        let f = Friction::from_config(&HandConfig::default());
        let c = [0.0, 120.0, 240.0].map(|d| Contact::hard(eq(d)));
        let m = closure_margin(&c, &f).unwrap();
        assert_eq!(m.rank, 6);
        assert!(m.is_force_closure(), "{m:?}");
        // Upper bound μ/k.
        assert!(m.t_star.unwrap() <= f.mu / 3.0 + 1e-7);
    }

    #[test]
    fn antipodal_soft_pair_margin_is_mu_over_two() {
        let f = Friction::from_config(&HandConfig::default());
        let c = [Contact::soft(eq(0.0)), Contact::soft(eq(180.0))];
        let m = closure_margin(&c, &f).unwrap();
        assert!((m.t_star.unwrap() - f.mu / 2.0).abs() < 1e-6, "{m:?}");
    }
}

//! Shared plumbing for the Clarabel problems of this module: solver
//! settings that allow allocation-free data updates, and a sparse-pattern
//! builder that keeps structural zeros.
//!
//! Every problem is written as a stream of `(row, value)` entries in column
//! order. Building collects the stream into a CSC matrix (pattern and
//! values); updating overwrites the values in the same order. Because the
//! stream has the same shape for every datum (entries that happen to be 0,
//! such as a normal's zero component, are still emitted), the pattern never
//! changes and Clarabel's `update_A` accepts the new values.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

use super::GraspError;

/// Interior-point iteration cap of every solve. The problems here converge
/// in 8–20 iterations (measured in the tests); the cap bounds the worst
/// case of a control tick.
pub const MAX_ITERATIONS: u32 = 60;

/// Solver settings for re-solvable problems (SPEC §3.2): presolve off and
/// structural zeros kept (both would block `update_*`); chordal
/// decomposition does not exist without clarabel's `sdp` feature, which is
/// off; bounded iterations; no time limit, because a clock-dependent stop
/// would break determinism (same input ⇒ same output bit for bit).
pub fn settings() -> Result<DefaultSettings<f64>, GraspError> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .input_sparse_dropzeros(false)
        .max_iter(MAX_ITERATIONS)
        .time_limit(f64::INFINITY)
        .max_threads(1)
        .direct_solve_method("qdldl".to_owned())
        .build()
        .map_err(|_| GraspError::SolverSetup)
}

/// Collects a column-ordered entry stream into a CSC matrix.
pub struct CscBuilder {
    rows: usize,
    colptr: Vec<usize>,
    rowval: Vec<usize>,
    nzval: Vec<f64>,
}

impl CscBuilder {
    /// An empty `rows`-row matrix.
    pub fn new(rows: usize) -> Self {
        Self {
            rows,
            colptr: vec![0],
            rowval: Vec::new(),
            nzval: Vec::new(),
        }
    }

    /// Appends an entry to the current column (rows must increase).
    pub fn push(&mut self, row: usize, value: f64) {
        self.rowval.push(row);
        self.nzval.push(value);
    }

    /// Closes the current column.
    pub fn end_column(&mut self) {
        self.colptr.push(self.rowval.len());
    }

    /// The finished matrix.
    pub fn build(self) -> CscMatrix<f64> {
        let cols = self.colptr.len() - 1;
        CscMatrix::new(self.rows, cols, self.colptr, self.rowval, self.nzval)
    }
}

/// Receives a problem's entry stream: either a [`CscBuilder`] or a value
/// overwrite.
pub trait EntrySink {
    /// One entry of the current column.
    fn push(&mut self, row: usize, value: f64);
    /// End of the current column.
    fn end_column(&mut self);
}

impl EntrySink for CscBuilder {
    fn push(&mut self, row: usize, value: f64) {
        CscBuilder::push(self, row, value);
    }
    fn end_column(&mut self) {
        CscBuilder::end_column(self);
    }
}

/// Overwrites values in stream order (no allocation). Counts entries so a
/// mismatch with the built pattern is detected instead of corrupting data.
pub struct ValueWriter<'a> {
    values: &'a mut [f64],
    next: usize,
    overflow: bool,
}

impl<'a> ValueWriter<'a> {
    /// Writes into `values` from the start.
    pub fn new(values: &'a mut [f64]) -> Self {
        Self {
            values,
            next: 0,
            overflow: false,
        }
    }

    /// True when exactly `values.len()` entries were written.
    pub fn complete(&self) -> bool {
        !self.overflow && self.next == self.values.len()
    }
}

impl EntrySink for ValueWriter<'_> {
    fn push(&mut self, _row: usize, value: f64) {
        if let Some(v) = self.values.get_mut(self.next) {
            *v = value;
        } else {
            self.overflow = true;
        }
        self.next += 1;
    }
    fn end_column(&mut self) {}
}

/// An empty n×n matrix (no quadratic term).
pub fn zero_p(n: usize) -> CscMatrix<f64> {
    CscMatrix::new(n, n, vec![0; n + 1], Vec::new(), Vec::new())
}

/// Whether a final status carries a usable primal solution.
pub fn solved(status: SolverStatus) -> bool {
    matches!(status, SolverStatus::Solved | SolverStatus::AlmostSolved)
}

/// Golden-spiral unit directions: a fixed, generic (no zero components)
/// layout used to build each problem before the first real data arrive,
/// so Clarabel's one-time equilibration never depends on call history.
pub fn nominal_normal(i: usize, count: usize) -> nalgebra::Vector3<f64> {
    let golden = core::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
    let rho = (1.0 - z * z).sqrt();
    let phi = golden * i as f64 + 0.3;
    nalgebra::Vector3::new(rho * phi.cos(), rho * phi.sin(), z * 0.9 + 0.05).normalize()
}

/// One solve of a problem built for that call (tests, plan-time studies):
/// minimise x\[`objective`\] subject to A x + s = b, s in `cones`, A given as
/// (row, column, value) entries over `columns` variables. The primal
/// solution and the iterations, or why not: [`GraspError::Infeasible`]
/// for a primal infeasible problem, [`GraspError::SolverFailed`] when
/// Clarabel stops without a finite objective.
pub fn solve_once(
    rows: usize,
    columns: usize,
    mut entries: Vec<(usize, usize, f64)>,
    b: &[f64],
    cones: &[SupportedConeT<f64>],
    objective: usize,
    max_iter: u32,
) -> Result<(Vec<f64>, u32), GraspError> {
    entries.sort_by_key(|&(r, c, _)| (c, r));
    let mut colptr = vec![0usize; columns + 1];
    let mut rowval = Vec::with_capacity(entries.len());
    let mut nzval = Vec::with_capacity(entries.len());
    for &(r, c, v) in &entries {
        colptr[c + 1] += 1;
        rowval.push(r);
        nzval.push(v);
    }
    for c in 0..columns {
        colptr[c + 1] += colptr[c];
    }
    let a = CscMatrix::new(rows, columns, colptr, rowval, nzval);
    let mut q = vec![0.0; columns];
    q[objective] = 1.0;
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(max_iter)
        .max_threads(1)
        .build()
        .map_err(|_| GraspError::SolverSetup)?;
    let mut solver = DefaultSolver::new(&zero_p(columns), &q, &a, b, cones, settings)
        .map_err(|_| GraspError::SolverSetup)?;
    solver.solve();
    let sol = &solver.solution;
    match sol.status {
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            Err(GraspError::Infeasible)
        }
        s if solved(s) && sol.x[objective].is_finite() => Ok((sol.x.clone(), sol.iterations)),
        _ => Err(GraspError::SolverFailed {
            iterations: sol.iterations,
        }),
    }
}

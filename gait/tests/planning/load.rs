//! An independent load check (SPEC §1.3 I1') for the tests, written from
//! the configuration and the SPEC alone — its own SOCP on Clarabel, its
//! own contact model and its own disturbance directions; nothing of
//! `gait::grasp` or `gait::planner::load`.
//!
//! The contacts at unit normals n_i (sphere radius R) push with f_n along
//! −n_i and rub with f_t ⊥ n_i; a soft contact adds a moment τ about n_i in
//! the coupled (elliptic) cone f_n ≥ √(|f_t|²/μ² + τ²/μ_t²) (μ = tan θ,
//! μ_t = `HandConfig::mu_torsion`, no margins). For each load (force E on
//! the object, torque T about O) the contact forces must cancel it; F* is
//! the least bound on every normal force for which all listed loads can be
//! cancelled (each with its own forces). The loads: the weight m g plus a
//! disturbance of size `load.disturbance_force` along each of 26
//! directions (the cube's faces, edges and corners) and, while the object
//! is accelerated about an axis k, the torque ±I α_max k with I = (2/5) m
//! R² (a solid sphere).

#![allow(dead_code)]

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT,
    SolverStatus, SupportedConeT, ZeroConeT,
};
use gait::HandConfig;
use nalgebra::Vector3;

/// The 26 unit directions of the cube's faces, edges and corners.
pub fn directions() -> Vec<Vector3<f64>> {
    let mut v = Vec::new();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    v.push(Vector3::new(x as f64, y as f64, z as f64).normalize());
                }
            }
        }
    }
    v
}

/// The test's own load model.
pub struct LoadCheck {
    r: f64,
    mu: f64,
    mu_t: f64,
    weight: Vector3<f64>,
    disturbance: f64,
    inertia_torque: f64,
    pub max_grip: f64,
    dirs: Vec<Vector3<f64>>,
}

/// Whether contacts are soft (torsion) or hard.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Kind {
    Soft,
    Hard,
}

impl LoadCheck {
    pub fn new(c: &HandConfig) -> Self {
        let m = &c.model;
        let mass = c.load.object_mass;
        Self {
            r: m.object_radius,
            mu: m.friction_angle_deg.to_radians().tan(),
            mu_t: c.mu_torsion(),
            weight: Vector3::new(c.load.gravity[0], c.load.gravity[1], c.load.gravity[2]) * mass,
            disturbance: c.load.disturbance_force,
            inertia_torque: 0.4
                * mass
                * m.object_radius
                * m.object_radius
                * c.limits.object.acceleration,
            max_grip: c.load.max_grip,
            dirs: directions(),
        }
    }

    /// The loads (E, T): weight, weight plus each disturbance direction,
    /// each with ±I α k when rotating about `axis`.
    pub fn loads(&self, axis: Option<&Vector3<f64>>) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let torques: Vec<Vector3<f64>> = match axis {
            Some(k) => vec![k * self.inertia_torque, -k * self.inertia_torque],
            None => vec![Vector3::zeros()],
        };
        let mut out = Vec::new();
        for t in &torques {
            out.push((self.weight, *t));
            if self.disturbance > 0.0 {
                for d in &self.dirs {
                    out.push((self.weight + d * self.disturbance, *t));
                }
            }
        }
        out
    }

    /// F* \[N\] for contacts `normals` of `kind` and the loads (None: no
    /// forces hold some load).
    pub fn peak(
        &self,
        normals: &[Vector3<f64>],
        kind: Kind,
        loads: &[(Vector3<f64>, Vector3<f64>)],
    ) -> Option<f64> {
        self.peak_with(normals, kind, loads, 0)
    }

    /// [`LoadCheck::peak`] with the contacts in the bit mask `frictionless`
    /// pushing along their normals only (μ = 0 in their cones: no
    /// tangential force, no torsion) — a contact that spins on the object
    /// has used its whole coupled cone for the spin's torsion.
    pub fn peak_with(
        &self,
        normals: &[Vector3<f64>],
        kind: Kind,
        loads: &[(Vector3<f64>, Vector3<f64>)],
        frictionless: u8,
    ) -> Option<f64> {
        let k = normals.len();
        let dim = if kind == Kind::Soft { 4 } else { 3 };
        let ns = loads.len();
        let n = ns * k * dim + 1;
        let fcol = n - 1;
        // Tangent bases.
        let frames: Vec<(Vector3<f64>, Vector3<f64>)> = normals
            .iter()
            .map(|nn| {
                let helper = if nn.x.abs() < 0.6 {
                    Vector3::x()
                } else {
                    Vector3::y()
                };
                let t1 = nn.cross(&helper).normalize();
                (t1, nn.cross(&t1))
            })
            .collect();
        let mut trip: Vec<(usize, usize, f64)> = Vec::new();
        let eq = 6 * ns;
        let cone0 = eq;
        let caps = cone0 + ns * k * dim;
        let rows = caps + ns * k + ns * k;
        let mut b = vec![0.0; rows];
        for (s, (e, t)) in loads.iter().enumerate() {
            // Σ F_i = −E; Σ p_i × F_i + moments = −(torque the load gives)
            // … here T is what the contacts must supply: Σ = T.
            for a in 0..3 {
                b[6 * s + a] = -e[a];
                b[6 * s + 3 + a] = t[a];
            }
            for (i, nn) in normals.iter().enumerate() {
                let (t1, t2) = frames[i];
                let p = nn * self.r;
                // Columns: f_n (force −n), f_1 (t1), f_2 (t2), [τ (moment n)].
                let cols: Vec<(Vector3<f64>, Vector3<f64>)> = {
                    let mut c = vec![
                        (-nn, Vector3::zeros()),
                        (t1, p.cross(&t1)),
                        (t2, p.cross(&t2)),
                    ];
                    if kind == Kind::Soft {
                        c.push((Vector3::zeros(), *nn));
                    }
                    c
                };
                for (j, (f, m)) in cols.iter().enumerate() {
                    let col = (s * k + i) * dim + j;
                    for a in 0..3 {
                        if f[a] != 0.0 {
                            trip.push((6 * s + a, col, f[a]));
                        }
                        if m[a] != 0.0 {
                            trip.push((6 * s + 3 + a, col, m[a]));
                        }
                    }
                    // Cone rows: (μ f_n, f_1, f_2, τ μ/μ_t) ∈ SOC.
                    let slick = frictionless & (1 << i) != 0;
                    let scale = match j {
                        0 if slick => 0.0,
                        0 => self.mu,
                        3 => self.mu / self.mu_t,
                        _ => 1.0,
                    };
                    if scale != 0.0 {
                        trip.push((cone0 + (s * k + i) * dim + j, col, -scale));
                    }
                    if j == 0 {
                        let cap = caps + s * k + i;
                        trip.push((cap, col, 1.0));
                        trip.push((cap, fcol, -1.0));
                        let nonneg = caps + ns * k + s * k + i;
                        trip.push((nonneg, col, -1.0));
                    }
                }
            }
        }
        trip.sort_by_key(|&(r, c, _)| (c, r));
        let mut colptr = vec![0usize; n + 1];
        let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
        for &(r, c, v) in &trip {
            colptr[c + 1] += 1;
            rowval.push(r);
            nzval.push(v);
        }
        for c in 0..n {
            colptr[c + 1] += colptr[c];
        }
        let a = CscMatrix::new(rows, n, colptr, rowval, nzval);
        let p = CscMatrix::new(n, n, vec![0; n + 1], Vec::new(), Vec::new());
        let mut q = vec![0.0; n];
        q[fcol] = 1.0;
        let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(eq)];
        for _ in 0..ns * k {
            cones.push(SecondOrderConeT(dim));
        }
        cones.push(NonnegativeConeT(2 * ns * k));
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .build()
            .unwrap();
        let mut solver = DefaultSolver::new(&p, &q, &a, &b, &cones, settings).ok()?;
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => Some(solver.solution.x[fcol]),
            _ => None,
        }
    }

    /// Whether the contacts hold the loads within `load.max_grip` (a
    /// relative tolerance of 1e-6 for the solver's accuracy).
    pub fn holds(
        &self,
        normals: &[Vector3<f64>],
        kind: Kind,
        axis: Option<&Vector3<f64>>,
    ) -> (bool, f64) {
        self.holds_with(normals, kind, axis, 0)
    }

    /// [`LoadCheck::holds`] with the contacts in `frictionless` pushing
    /// only ([`LoadCheck::peak_with`]).
    pub fn holds_with(
        &self,
        normals: &[Vector3<f64>],
        kind: Kind,
        axis: Option<&Vector3<f64>>,
        frictionless: u8,
    ) -> (bool, f64) {
        let loads = self.loads(axis);
        match self.peak_with(normals, kind, &loads, frictionless) {
            Some(f) => (f <= self.max_grip * (1.0 + 1e-6), f),
            None => (false, f64::INFINITY),
        }
    }
}

impl LoadCheck {
    /// Whether contact forces with normal forces within `tol` \[N\] of
    /// `f_n` (the commanded grip; a compliant fingertip takes up the rest)
    /// and tangential forces (and torsion) in the cones can cancel the
    /// weight while the contacts supply the torque `torque` (I α). A
    /// feasibility SOCP.
    pub fn commanded_holds_weight(
        &self,
        normals: &[Vector3<f64>],
        f_n: &[f64],
        kind: Kind,
        torque: &Vector3<f64>,
        tol: f64,
    ) -> bool {
        self.commanded_holds_weight_with(normals, f_n, kind, torque, tol, 0)
    }

    /// [`LoadCheck::commanded_holds_weight`] with the contacts in the bit
    /// mask `frictionless` pushing along their normals only (a contact
    /// spinning on the object).
    pub fn commanded_holds_weight_with(
        &self,
        normals: &[Vector3<f64>],
        f_n: &[f64],
        kind: Kind,
        torque: &Vector3<f64>,
        tol: f64,
        frictionless: u8,
    ) -> bool {
        let k = normals.len();
        let dim = if kind == Kind::Soft { 4 } else { 3 };
        let n = k * dim;
        let mut trip: Vec<(usize, usize, f64)> = Vec::new();
        let cones0 = 6;
        let boxes = cones0 + k * dim;
        let rows = boxes + 2 * k;
        let mut b = vec![0.0; rows];
        for a in 0..3 {
            b[a] = -self.weight[a];
            b[3 + a] = torque[a];
        }
        for (i, nn) in normals.iter().enumerate() {
            let helper = if nn.x.abs() < 0.6 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let t1 = nn.cross(&helper).normalize();
            let t2 = nn.cross(&t1);
            let p = nn * self.r;
            let mut cols = vec![
                (-nn, Vector3::zeros()),
                (t1, p.cross(&t1)),
                (t2, p.cross(&t2)),
            ];
            if kind == Kind::Soft {
                cols.push((Vector3::zeros(), *nn));
            }
            for (j, (f, m)) in cols.iter().enumerate() {
                let col = i * dim + j;
                for a in 0..3 {
                    if f[a] != 0.0 {
                        trip.push((a, col, f[a]));
                    }
                    if m[a] != 0.0 {
                        trip.push((3 + a, col, m[a]));
                    }
                }
                let slick = frictionless & (1 << i) != 0;
                let scale = match j {
                    0 if slick => 0.0,
                    0 => self.mu,
                    3 => self.mu / self.mu_t,
                    _ => 1.0,
                };
                if scale != 0.0 {
                    trip.push((cones0 + i * dim + j, col, -scale));
                }
                if j == 0 {
                    // c − tol ≤ f_n ≤ c + tol.
                    trip.push((boxes + 2 * i, col, 1.0));
                    b[boxes + 2 * i] = f_n[i] + tol;
                    trip.push((boxes + 2 * i + 1, col, -1.0));
                    b[boxes + 2 * i + 1] = -(f_n[i] - tol).max(0.0);
                }
            }
        }
        trip.sort_by_key(|&(r, c, _)| (c, r));
        let mut colptr = vec![0usize; n + 1];
        let (mut rowval, mut nzval) = (Vec::new(), Vec::new());
        for &(r, c, v) in &trip {
            colptr[c + 1] += 1;
            rowval.push(r);
            nzval.push(v);
        }
        for c in 0..n {
            colptr[c + 1] += colptr[c];
        }
        let a = CscMatrix::new(rows, n, colptr, rowval, nzval);
        let p = CscMatrix::new(n, n, vec![0; n + 1], Vec::new(), Vec::new());
        let q = vec![0.0; n];
        let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(6)];
        for _ in 0..k {
            cones.push(SecondOrderConeT(dim));
        }
        cones.push(NonnegativeConeT(2 * k));
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .max_iter(200)
            .build()
            .unwrap();
        let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &b, &cones, settings) else {
            return false;
        };
        solver.solve();
        matches!(
            solver.solution.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        )
    }
}

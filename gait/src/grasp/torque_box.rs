//! Holding a load with chain fingers whose motors are torque-limited (SPEC
//! §14.1 "Forces", §1.3 I1'): the torque box replaces the fixed grip limit.
//!
//! A chain finger pushes the object with the force F at its contact point
//! p = c − r n and, through a soft contact, the torsional moment M about
//! the normal; its motors supply
//!
//! ```text
//! τ = J_pᵀ F + J_ωᵀ M + g,     |τ_j| ≤ τ_max,j   (every joint j)
//! ```
//!
//! with J_p = J_v + r \[n\]ₓ J_ω the Jacobian of the contact point, J_ω the
//! tip's angular Jacobian and g the torques that hold the links against
//! their own weight (zero where the hand compensates it). The grasp holds a
//! set of loads (the weight, the acceleration's torque, every disturbance
//! vertex: [`super::hold::Loads`]' scenarios) when each has contact forces
//! in the friction cones that balance it within every finger's box. As in
//! [`super::forces::LoadSolver`] each scenario's forces are free (I1' asks
//! only that forces exist); the SOCP finds the least torque use
//!
//! ```text
//! minimise  u
//! s.t.  G f_s = (−E_s, T_s / R)                                   every s
//!       ‖(f_1, f_2 [, s μ/μ_t])‖ ≤ μ f_n,  f_n ≥ floor         each contact, each s
//!       −u τ_max,j ≤ (J_pᵀ F_i,s + J_ωᵀ M_i,s + g_i)_j ≤ u τ_max,j   each finger, joint, s
//! ```
//!
//! (G, f and the torsion variable as in [`super::contact`]: F = −n f_n +
//! t₁ f₁ + t₂ f₂, M = −n (μ_t/μ) s.) The grasp holds exactly when u* ≤ 1;
//! 1/u* is how many times over. Builds a fresh problem per call
//! (allocates): for planning and checking, not for the tick.

use nalgebra::{Matrix3, Vector3};

use super::GraspError;
use super::contact::{Contact, ContactFrame, ContactKind, Friction};
use super::load_socp::LoadRows;

/// One finger's statics at its grasp (three joints).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerStatics {
    /// J_pᵀ: joint torques per unit force at the contact point (hand
    /// frame) \[N·m/N\].
    pub force_to_torque: Matrix3<f64>,
    /// J_ωᵀ: joint torques per unit moment on the object \[N·m/N·m\].
    pub moment_to_torque: Matrix3<f64>,
    /// g: the torques holding the links against their weight \[N·m\].
    pub bias: Vector3<f64>,
    /// τ_max per joint \[N·m\] (> 0).
    pub limit: Vector3<f64>,
}

impl FingerStatics {
    /// The strongest push along the inward normal of the outward unit
    /// normal `n` (a grip's normal force) these motors give while they also
    /// hold the links' weight: the largest f ≥ 0 with
    /// |g_j + f (J_pᵀ(−n))_j| ≤ τ_max,j for every joint j \[N\]; 0 where the
    /// weight alone is beyond a motor.
    pub fn push_limit(&self, n: &Vector3<f64>) -> f64 {
        let per_newton = self.force_to_torque * (-n);
        let mut limit = f64::INFINITY;
        for j in 0..3 {
            let (g, b, t) = (self.bias[j], per_newton[j], self.limit[j]);
            if g.abs() > t {
                return 0.0;
            }
            if b > 0.0 {
                limit = limit.min((t - g) / b);
            } else if b < 0.0 {
                limit = limit.min((t + g) / -b);
            }
        }
        limit
    }

    /// The largest share of a motor's effort, max_j |τ_j| / τ_max,j, the
    /// contact force `force` on the object needs with the links' weight:
    /// τ = J_pᵀ F + g.
    pub fn share(&self, force: &Vector3<f64>) -> f64 {
        let tau = self.force_to_torque * force + self.bias;
        (0..3)
            .map(|j| tau[j].abs() / self.limit[j])
            .fold(0.0, f64::max)
    }
}

/// The answer of [`TorqueBoxSolver::solve`].
#[derive(Debug, Clone, PartialEq)]
pub struct TorqueBoxSolution {
    /// u*: the least largest |τ_j| / τ_max,j over fingers, joints and
    /// scenarios (the grasp holds when ≤ 1).
    pub utilisation: f64,
    /// Per scenario, per contact: the force F on the object at the
    /// contact \[N\] and the torsional moment M \[N·m\] of the optimum.
    pub forces: Vec<Vec<(Vector3<f64>, Vector3<f64>)>>,
    /// Interior-point iterations.
    pub iterations: u32,
}

/// The least torque use of a grasp of chain fingers (module docs).
#[derive(Debug, Clone, Copy)]
pub struct TorqueBoxSolver {
    friction: Friction,
}

/// Iteration cap: these problems converge in about 10–25 iterations.
const MAX_ITER: u32 = 200;

impl TorqueBoxSolver {
    /// A solver for `friction` (μ, μ_t, R).
    pub fn new(friction: Friction) -> Self {
        Self { friction }
    }

    /// u* for `contacts` pressed by `fingers` (one each) against the loads
    /// `scenarios` (force E the contacts must balance \[N\], torque T they
    /// must supply \[N·m\]), every normal force at least `floor` \[N\].
    /// [`GraspError::Infeasible`] when some load cannot be balanced in the
    /// friction cones at all.
    pub fn solve(
        &self,
        contacts: &[Contact],
        fingers: &[FingerStatics],
        scenarios: &[(Vector3<f64>, Vector3<f64>)],
        floor: f64,
    ) -> Result<TorqueBoxSolution, GraspError> {
        if fingers.len() != contacts.len() {
            return Err(GraspError::OutputLength);
        }
        let fr = self.friction;
        let finite3 = |m: &Matrix3<f64>| m.iter().all(|v| v.is_finite());
        let ok = fingers.iter().all(|f| {
            finite3(&f.force_to_torque)
                && finite3(&f.moment_to_torque)
                && f.bias.iter().all(|v| v.is_finite())
                && f.limit.iter().all(|v| v.is_finite() && *v > 0.0)
        });
        if !ok {
            return Err(GraspError::BadInput);
        }
        let k = contacts.len();
        let ns = scenarios.len();
        // Per contact, per variable: the joint torques it makes.
        let torque_cols: Vec<[Vector3<f64>; 4]> = contacts
            .iter()
            .zip(fingers)
            .map(|(c, f)| {
                let frame = ContactFrame::new(&c.normal);
                let torsion = match c.kind {
                    ContactKind::Hard => Vector3::zeros(),
                    ContactKind::Soft => f.moment_to_torque * (-frame.n * (fr.mu_torsion / fr.mu)),
                };
                [
                    f.force_to_torque * -frame.n,
                    f.force_to_torque * frame.t1,
                    f.force_to_torque * frame.t2,
                    torsion,
                ]
            })
            .collect();
        // The caller's rows, per scenario, contact and joint, both sides:
        // a·x − u τ_max ≤ −g  and  −a·x − u τ_max ≤ g.
        let mut rows = LoadRows::new(contacts, &fr, scenarios, floor, 6 * ns * k)?;
        let u_col = rows.objective();
        for s in 0..ns {
            for (i, (c, per_var)) in contacts.iter().zip(&torque_cols).enumerate() {
                for j in 0..3 {
                    let row = ((s * k + i) * 3 + j) * 2;
                    for (v, t) in per_var.iter().enumerate().take(c.kind.dim()) {
                        rows.push(row, rows.var(s, i, v), t[j]);
                        rows.push(row + 1, rows.var(s, i, v), -t[j]);
                    }
                    let (g, lim) = (fingers[i].bias[j], fingers[i].limit[j]);
                    rows.push(row, u_col, -lim);
                    rows.push(row + 1, u_col, -lim);
                    rows.bound(row, -g);
                    rows.bound(row + 1, g);
                }
            }
        }
        let (x, iterations) = rows.solve(MAX_ITER)?;
        if !x.iter().all(|v| v.is_finite()) {
            return Err(GraspError::SolverFailed { iterations });
        }
        let d: usize = contacts.iter().map(|c| c.kind.dim()).sum();
        let forces = (0..ns)
            .map(|s| {
                let mut off = s * d;
                contacts
                    .iter()
                    .map(|c| {
                        let f = ContactFrame::new(&c.normal);
                        let force = -f.n * x[off] + f.t1 * x[off + 1] + f.t2 * x[off + 2];
                        let moment = match c.kind {
                            ContactKind::Hard => Vector3::zeros(),
                            ContactKind::Soft => -f.n * (x[off + 3] * fr.mu_torsion / fr.mu),
                        };
                        off += c.kind.dim();
                        (force, moment)
                    })
                    .collect()
            })
            .collect();
        Ok(TorqueBoxSolution {
            utilisation: x[u_col],
            forces,
            iterations,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fingers whose joints feel the contact force's hand-frame components
    /// one to one (J_p = I), no moment, no link weight, τ_max = 1.
    fn direct() -> FingerStatics {
        FingerStatics {
            force_to_torque: Matrix3::identity(),
            moment_to_torque: Matrix3::zeros(),
            bias: Vector3::zeros(),
            limit: Vector3::repeat(1.0),
        }
    }

    fn friction(mu: f64) -> Friction {
        Friction {
            mu,
            mu_torsion: 1e-3 * mu,
            object_radius: 0.05,
        }
    }

    /// Two soft contacts at ±x hold a weight w along −z: each carries w/2
    /// up by friction and presses f_n ≥ w/(2μ); with τ = F the largest
    /// torque is max(f_n, w/2), least at f_n = w/(2μ): u* = (w/2)·max(1, 1/μ).
    #[test]
    fn an_antipodal_pair_under_its_weight() {
        let contacts = [Contact::soft(Vector3::x()), Contact::soft(-Vector3::x())];
        let fingers = [direct(); 2];
        let w = 0.8;
        let load = [(Vector3::new(0.0, 0.0, -w), Vector3::zeros())];
        for mu in [0.4, 0.8, 1.5, 3.0] {
            let s = TorqueBoxSolver::new(friction(mu))
                .solve(&contacts, &fingers, &load, 0.0)
                .unwrap();
            let want = 0.5 * w * (1.0f64 / mu).max(1.0);
            assert!(
                (s.utilisation - want).abs() < 1e-6,
                "μ {mu}: u* {} want {want}",
                s.utilisation
            );
        }
    }

    /// The box is per joint: a finger whose joints feel the force twice as
    /// much needs twice the share, and one whose links' weight already
    /// uses a joint's torque needs that much more.
    #[test]
    fn the_share_follows_the_jacobian_and_the_links_weight() {
        let contacts = [Contact::soft(Vector3::x()), Contact::soft(-Vector3::x())];
        let load = [(Vector3::new(0.0, 0.0, -0.8), Vector3::zeros())];
        let solver = TorqueBoxSolver::new(friction(1.5));
        let base = solver
            .solve(&contacts, &[direct(); 2], &load, 0.0)
            .unwrap()
            .utilisation;
        let mut stiff = direct();
        stiff.force_to_torque *= 2.0;
        let doubled = solver
            .solve(&contacts, &[stiff; 2], &load, 0.0)
            .unwrap()
            .utilisation;
        assert!(
            (doubled - 2.0 * base).abs() < 1e-6,
            "{doubled} vs 2 × {base}"
        );
        let mut heavy = direct();
        heavy.bias = Vector3::new(0.0, 0.0, 0.3);
        let loaded = solver
            .solve(&contacts, &[heavy; 2], &load, 0.0)
            .unwrap()
            .utilisation;
        // The weight pushes each contact's z torque to w/2 + 0.3.
        assert!((loaded - (0.4 + 0.3)).abs() < 1e-6, "{loaded}");
    }

    /// A torque about the pair's own axis is held by torsion alone: each
    /// soft contact twists with T/2, which its finger's joints feel
    /// through J_ωᵀ (here one to one, the force barely felt).
    #[test]
    fn torsion_loads_the_motors() {
        let contacts = [Contact::soft(Vector3::x()), Contact::soft(-Vector3::x())];
        let finger = FingerStatics {
            force_to_torque: Matrix3::identity() * 1e-4,
            moment_to_torque: Matrix3::identity(),
            ..direct()
        };
        let t = 0.002;
        let load = [(Vector3::zeros(), Vector3::new(t, 0.0, 0.0))];
        let s = TorqueBoxSolver::new(friction(1.0))
            .solve(&contacts, &[finger; 2], &load, 0.0)
            .unwrap();
        assert!(
            (s.utilisation - t / 2.0).abs() < 1e-7,
            "u* {} want {}",
            s.utilisation,
            t / 2.0
        );
    }

    #[test]
    fn a_load_no_cone_can_balance_is_infeasible() {
        // Two contacts both on +x cannot push the object towards −x.
        let contacts = [
            Contact::soft(Vector3::x()),
            Contact::soft(Vector3::new(1.0, 0.1, 0.0).normalize()),
        ];
        let load = [(Vector3::new(-1.0, 0.0, 0.0), Vector3::zeros())];
        let r = TorqueBoxSolver::new(friction(0.3)).solve(&contacts, &[direct(); 2], &load, 0.0);
        assert_eq!(r.unwrap_err(), GraspError::Infeasible);
        let r = TorqueBoxSolver::new(friction(0.3)).solve(&contacts, &[direct()], &load, 0.0);
        assert_eq!(r.unwrap_err(), GraspError::OutputLength);
        let mut bad = direct();
        bad.limit.x = 0.0;
        let r = TorqueBoxSolver::new(friction(0.3)).solve(&contacts, &[bad, direct()], &load, 0.0);
        assert_eq!(r.unwrap_err(), GraspError::BadInput);
    }
}

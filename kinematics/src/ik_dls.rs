//! Damped-least-squares inverse kinematics for any chain (SPEC §14.3:
//! damped least squares with secondary objectives for more than 3 joints).
//!
//! Each iteration, with $e = t - c(q)$ the tip-centre error and $J = J_v(q)$:
//! 1. primary step $\Delta q = J^\top (J J^\top + \lambda^2 I)^{-1} e$,
//!    scaled as a whole so that no joint moves more than `max_step`, then
//!    $q$ clamped to the limits with margin. The damping
//!    $\lambda^2 = |e|^2 + \lambda_{min}^2$ shrinks with the error
//!    (Levenberg–Marquardt as in Yamashita & Fukushima: fast convergence
//!    near a solution, bounded steps near singularities);
//! 2. for N > 3, the secondary objective of the spare joints: the step
//!    $(I - J^{+} J)\,k\,(q_{mid} - q)$, $J^{+} = J^\top (J J^\top +
//!    \lambda_{min}^2 I)^{-1}$, moves them toward mid-range inside the null
//!    space of $J$ (projected with the floor damping only, so that it does
//!    not leak into the tip's motion), shortened to stay inside the limits
//!    (a clamp would move the tip and fight step 1), and kept only where
//!    its second-order effect on the tip leaves the error below a tenth of
//!    the iteration's starting error (else halved, at most four times): the
//!    error falls at least tenfold per iteration. With 3 joints there is no null space
//!    away from singularities and the step is left out.
//!
//! At most `max_iterations` iterations: the loop never runs unbounded.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use crate::chain::{Chain, ChainState};

/// Settings of [`Chain::ik_dls`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DlsParams {
    /// Iteration bound.
    pub max_iterations: usize,
    /// Converged when $|e|$ is below this \[m\].
    pub tolerance: f64,
    /// $\lambda_{min}$ \[m\].
    pub min_damping: f64,
    /// Gain k of the secondary objective (toward mid-range).
    pub null_gain: f64,
    /// Largest change of one joint per iteration \[rad\].
    pub max_step: f64,
}

impl Default for DlsParams {
    fn default() -> Self {
        DlsParams {
            max_iterations: 50,
            tolerance: 1e-9,
            min_damping: 1e-6,
            null_gain: 0.5,
            max_step: 0.3,
        }
    }
}

/// The outcome of [`Chain::ik_dls`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DlsResult<const N: usize> {
    /// The joints reached (inside the limits with margin).
    pub q: SVector<f64, N>,
    /// The tip-centre error left, $|t - c(q)|$ \[m\].
    pub error: f64,
    /// Iterations used.
    pub iterations: usize,
    /// Whether `error ≤ tolerance`.
    pub converged: bool,
}

impl<const N: usize> Chain<N> {
    /// Damped-least-squares IK for tip centre `target` from `q0`.
    pub fn ik_dls(
        &self,
        target: &Vector3<f64>,
        q0: &SVector<f64, N>,
        p: &DlsParams,
    ) -> DlsResult<N> {
        let (lo, hi, mid) = (self.lower(), self.upper(), self.mid_range());
        let mut q = q0.zip_zip_map(&lo, &hi, |x, l, h| x.clamp(l, h));
        let mut s = self.forward(&q);
        let mut iterations = 0;
        loop {
            let e = target - s.tip_centre();
            let err = e.norm();
            if err <= p.tolerance || iterations == p.max_iterations {
                return DlsResult {
                    q,
                    error: err,
                    iterations,
                    converged: err <= p.tolerance,
                };
            }
            iterations += 1;
            let j = s.jacobian_v();
            let Some(dq) = primary_step(
                &j,
                &e,
                err * err + p.min_damping * p.min_damping,
                p.max_step,
            ) else {
                return DlsResult {
                    q,
                    error: err,
                    iterations,
                    converged: false,
                };
            };
            q = (q + dq).zip_zip_map(&lo, &hi, |x, l, h| x.clamp(l, h));
            s = self.forward(&q);
            if N > 3 && p.null_gain > 0.0 {
                self.secondary_step(&mut q, &mut s, &j, target, 0.1 * err, &mid, &lo, &hi, p);
            }
        }
    }

    /// Step 2: toward mid-range in the null space, kept only where the tip
    /// error stays within `budget` (a tenth of the iteration's starting
    /// error), what step 1 left, or half the tolerance; halved up to four
    /// times.
    #[allow(clippy::too_many_arguments)]
    fn secondary_step(
        &self,
        q: &mut SVector<f64, N>,
        s: &mut ChainState<N>,
        j: &SMatrix<f64, 3, N>,
        target: &Vector3<f64>,
        budget: f64,
        mid: &SVector<f64, N>,
        lo: &SVector<f64, N>,
        hi: &SVector<f64, N>,
        p: &DlsParams,
    ) {
        let floor = p.min_damping * p.min_damping;
        let Some(inv0) = (j * j.transpose() + Matrix3::identity() * floor).try_inverse() else {
            return;
        };
        let null = SMatrix::<f64, N, N>::identity() - j.transpose() * inv0 * j;
        let dn = null * ((mid - *q) * p.null_gain);
        let mut alpha = (p.max_step / dn.amax().max(p.max_step)).min(1.0);
        for i in 0..N {
            if dn[i] > 0.0 {
                alpha = alpha.min((hi[i] - q[i]) / dn[i]);
            } else if dn[i] < 0.0 {
                alpha = alpha.min((lo[i] - q[i]) / dn[i]);
            }
        }
        let allowed = (target - s.tip_centre())
            .norm()
            .max(budget)
            .max(0.5 * p.tolerance);
        for _ in 0..5 {
            if alpha <= 0.0 {
                return;
            }
            let qn = *q + dn * alpha;
            let sn = self.forward(&qn);
            if (target - sn.tip_centre()).norm() <= allowed {
                *q = qn;
                *s = sn;
                return;
            }
            alpha *= 0.5;
        }
    }
}

/// Step 1: the damped least-squares step, scaled as a whole to `max_step`
/// (a per-joint clamp would turn it).
fn primary_step<const N: usize>(
    j: &SMatrix<f64, 3, N>,
    e: &Vector3<f64>,
    lambda2: f64,
    max_step: f64,
) -> Option<SVector<f64, N>> {
    let inv = (j * j.transpose() + Matrix3::identity() * lambda2).try_inverse()?;
    let step = j.transpose() * (inv * e);
    Some(step * (max_step / step.amax().max(max_step)))
}

//! The torque box (SPEC §14.1 "Forces").
//!
//! A tip pushing on the object with force $f$ (hand frame) needs the joint
//! torques
//! $$\tau = J_v(q)^\top f + g(q),\qquad |\tau_i| \le \tau_{max,i},$$
//! where $g(q)$ holds the links up against gravity $\mathbf g$ (the hand
//! frame's gravity vector, configurable):
//! $$g(q) = -\sum_j J_{c_j}(q)^\top m_j \mathbf g,$$
//! $m_j$ and $c_j$ the mass and centre of mass of the link moved by joint
//! j, $J_{c_j}$ the Jacobian of $c_j$ (columns of joints up to j). A hand
//! that compensates its links' weight itself passes $\mathbf g = 0$.
//!
//! The strongest force along a unit direction $d$ is the largest $s \ge 0$
//! with $|(J_v^\top d)_i\, s + g_i| \le \tau_{max,i}$ for every i: each
//! joint bounds $s$ by $(\tau_{max,i} - g_i)/a_i$ for $a_i > 0$ or
//! $(\tau_{max,i} + g_i)/|a_i|$ for $a_i < 0$, $a = J_v^\top d$.

use nalgebra::{SVector, Vector3};

use crate::chain::{Chain, ChainState};

/// $g(q)$: the torques that hold the links still against `gravity` \[N·m\].
pub fn gravity_torques<const N: usize>(
    chain: &Chain<N>,
    s: &ChainState<N>,
    gravity: &Vector3<f64>,
) -> SVector<f64, N> {
    let mut tau = SVector::<f64, N>::zeros();
    for j in 0..N {
        let b = &chain.bodies[j];
        if b.mass == 0.0 {
            continue;
        }
        let c = s.joints[j].point(&b.com);
        let weight = gravity * b.mass;
        for i in 0..=j {
            // −(w_i × (c − p_i))·(m g) = −w_i·((c − p_i) × m g)
            tau[i] -= s.axes[i].dot(&(c - s.joints[i].translation).cross(&weight));
        }
    }
    tau
}

/// $\tau = J_v^\top f + g$: the joint torques for tip force `f` \[N\] given
/// the gravity torques `g` (from [`gravity_torques`], or zero).
pub fn joint_torques<const N: usize>(
    s: &ChainState<N>,
    f: &Vector3<f64>,
    g: &SVector<f64, N>,
) -> SVector<f64, N> {
    s.jacobian_v().transpose() * f + g
}

/// The largest scale $s \ge 0$ of the unit force direction `d` with
/// $|J_v^\top (s d) + g|_i \le \tau_{max,i}$ for all i.
///
/// `None` when the links' weight alone exceeds a limit (no force is
/// admissible); `Some(f64::INFINITY)` when no joint feels `d` (a singular
/// direction: the structure, not the motors, carries it).
pub fn max_force_scale<const N: usize>(
    s: &ChainState<N>,
    d: &Vector3<f64>,
    g: &SVector<f64, N>,
    tau_max: &SVector<f64, N>,
) -> Option<f64> {
    let a = s.jacobian_v().transpose() * d;
    let mut best = f64::INFINITY;
    for i in 0..N {
        if g[i].abs() > tau_max[i] {
            return None;
        }
        let bound = if a[i] > 0.0 {
            (tau_max[i] - g[i]) / a[i]
        } else if a[i] < 0.0 {
            (tau_max[i] + g[i]) / -a[i]
        } else {
            f64::INFINITY
        };
        best = best.min(bound);
    }
    Some(best)
}

//! How far a finger's parts can travel between two configurations: the
//! bound a sampled check needs to say a distance held *between* its
//! samples, not only at them.
//!
//! Turning joint i by $\Delta q_i$ moves every point beyond it (its links,
//! the tip) by at most $|\Delta q_i|\,\rho_i$, where $\rho_i$ is the point's
//! distance from joint i's axis, itself at most its distance from the
//! joint's origin $p_i$. Summed over the joints, with $\rho_i$ the reach of
//! the parts (capsule surfaces included) at either end, this bounds the
//! travel of every surface point of the finger while its joints move
//! monotonically from one configuration to the other — what a finger's
//! path does between two close samples. A distance d to anything (the
//! object, another finger) is 1-Lipschitz in that travel, so between
//! samples where it is $d_a$ and $d_b$ it stays at least
//! $(d_a + d_b - D)/2$ with D the summed travel of the parts involved.

use nalgebra::SVector;

use crate::chain::{Chain, ChainState};

/// Per joint i, the largest distance from joint i's origin to a surface
/// point of the parts it moves (link capsules on later segments, and the
/// tip sphere) at `s` \[m\].
pub fn reach_radii<const N: usize>(chain: &Chain<N>, s: &ChainState<N>) -> [f64; N] {
    let caps = chain.capsules(s);
    std::array::from_fn(|i| {
        let p = s.joints[i].translation;
        let tip = (s.tip.translation - p).norm() + chain.tip_radius;
        chain
            .link_capsules()
            .iter()
            .zip(caps.as_slice())
            // Segment j (1-based) is moved by joints 1..=j, so by 0-based
            // joint i when j > i.
            .filter(|(lc, _)| lc.segment > i)
            .map(|(_, c)| (c.a - p).norm().max((c.b - p).norm()) + c.radius)
            .fold(tip, f64::max)
    })
}

/// A bound on how far any surface point of `chain`'s moving parts travels
/// between configuration `qa` (state `sa`) and `qb` (state `sb`) (module
/// docs) \[m\].
pub fn parts_travel<const N: usize>(
    chain: &Chain<N>,
    (qa, sa): (&SVector<f64, N>, &ChainState<N>),
    (qb, sb): (&SVector<f64, N>, &ChainState<N>),
) -> f64 {
    let ra = reach_radii(chain, sa);
    let rb = reach_radii(chain, sb);
    (0..N)
        .map(|i| (qb[i] - qa[i]).abs() * ra[i].max(rb[i]))
        .sum()
}

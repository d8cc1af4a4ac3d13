//! The workspace of a chain finger (SPEC §14.1 "Workspace", which replaces
//! the free fingertip's cone W_k): the object normals n at which the finger
//! can grasp.
//!
//! A normal n is in finger k's workspace when the tip centre
//! $c = O + (R + r)\,n$ has an IK solution q with
//! - every joint inside its limits with the chain's margin
//!   ([`Chain::limit_margin`] ≥ 0),
//! - the contact on the tip's patch with `patch_margin` to spare
//!   ([`crate::TipPatch::margin`] ≥ `patch_margin`),
//! - every link capsule at least `clearance` from the object's surface
//!   (the tip sphere itself touches it by construction),
//!
//! and the motors can press: the largest force along −n within the torque
//! box, the links' weight included ([`crate::max_force_scale`]), is what
//! [`Reach::max_push`] reports (the planner needs it at least as large as
//! its grip; a workspace test does not decide that).
//!
//! Of the closed-form branches (up to four) that pass, the one with the
//! largest joint-limit margin is kept. Clearance *between* fingers depends
//! on the grasp, not on one normal: [`finger_gap`] measures it for two
//! fingers at given configurations.
//!
//! Nothing here allocates except [`Workspace::new`], which tabulates a grid
//! once (start-up, off the loop).

use nalgebra::Vector3;

use crate::capsule::Capsule;
use crate::chain::{Chain, ChainState, MAX_CAPSULES};
use crate::description::Object;
use crate::ik_closed::ClosedFormIk;
use crate::torque::{gravity_torques, max_force_scale};

/// What a workspace test asks beyond the joint limits' own margin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Margins {
    /// Kept inside the tip patch \[rad\].
    pub patch: f64,
    /// Kept between every link capsule and the object's surface \[m\].
    pub clearance: f64,
}

/// How finger k reaches a normal: the configuration and its margins.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// The joints.
    pub q: Vector3<f64>,
    /// Joint-limit margin beyond the chain's own \[rad\] (≥ 0).
    pub joint_margin: f64,
    /// Tip-patch margin \[rad\] (≥ `Margins::patch`).
    pub patch_margin: f64,
    /// Smallest gap between a link capsule and the object \[m\]
    /// (≥ `Margins::clearance`; +∞ for a chain without capsules).
    pub clearance: f64,
    /// The largest force the tip can press along −n within the torque box,
    /// the links' weight included \[N\] (0 when the weight alone exceeds a
    /// motor's limit; +∞ at a singular direction).
    pub max_push: f64,
}

/// Finger `chain` (with its closed-form IK `ik`) grasping `object` at the
/// outward unit normal `n`, under gravity `gravity` (hand frame): the best
/// admissible configuration (module docs), or `None`.
pub fn reach(
    chain: &Chain<3>,
    ik: &ClosedFormIk,
    object: &Object,
    gravity: &Vector3<f64>,
    n: &Vector3<f64>,
    margins: &Margins,
) -> Option<Reach> {
    let target = object.centre + n * (object.radius + chain.tip_radius);
    let branches = ik.branches(&target);
    let mut best: Option<Reach> = None;
    for q in &branches.q[..branches.len] {
        let joint_margin = chain.limit_margin(q);
        if joint_margin < 0.0 {
            continue;
        }
        let s = chain.forward(q);
        // The branch must really put the tip there (the closed form's
        // inputs are exact only for a well-formed chain).
        if (s.tip_centre() - target).norm() > 1e-9 {
            continue;
        }
        let patch_margin = chain.patch.margin(&s.tip.rotation, n);
        if patch_margin < margins.patch {
            continue;
        }
        let clearance = object_clearance(chain, &s, object);
        if clearance < margins.clearance {
            continue;
        }
        if best.is_some_and(|b| b.joint_margin >= joint_margin) {
            continue;
        }
        let g = gravity_torques(chain, &s, gravity);
        let max_push = max_force_scale(&s, &(-n), &g, &chain.effort()).unwrap_or(0.0);
        best = Some(Reach {
            q: *q,
            joint_margin,
            patch_margin,
            clearance,
            max_push,
        });
    }
    best
}

/// The smallest gap between `chain`'s link capsules at `s` and the object
/// \[m\] (+∞ without capsules).
pub fn object_clearance(chain: &Chain<3>, s: &ChainState<3>, object: &Object) -> f64 {
    chain
        .capsules(s)
        .as_slice()
        .iter()
        .map(|c| c.sphere_gap(&object.centre, object.radius))
        .fold(f64::INFINITY, f64::min)
}

/// The smallest gap between two fingers at their configurations \[m\]:
/// [`FingerGap::gap`] with the pairs left out computed for this call (a
/// caller asking often keeps a [`FingerGap`]).
pub fn finger_gap(a: (&Chain<3>, &ChainState<3>), b: (&Chain<3>, &ChainState<3>)) -> f64 {
    FingerGap::new(a.0, b.0).gap(a, b)
}

/// The parts of a finger that can touch another: its link capsules and its
/// tip sphere (a capsule of zero length), hand frame.
fn parts(chain: &Chain<3>, s: &ChainState<3>) -> ([Capsule; MAX_CAPSULES + 1], usize) {
    let caps = chain.capsules(s);
    let tip = Capsule {
        a: s.tip_centre(),
        b: s.tip_centre(),
        radius: chain.tip_radius,
    };
    let mut all = [Capsule::POINT; MAX_CAPSULES + 1];
    let n = caps.as_slice().len();
    all[..n].copy_from_slice(caps.as_slice());
    all[n] = tip;
    (all, n + 1)
}

/// The gap between two given fingers: every link capsule and the tip
/// sphere of one against those of the other. Capsule pairs that already
/// overlap with both fingers at q = 0 are left out: the description's
/// capsules enclose its parts conservatively, and parts that overlap in
/// the zero pose (TriFingerPro: the three upper links, whose capsules'
/// caps meet above the arena's centre while the links turn only about
/// their own axes) are parts built not to collide. Which pairs those are
/// depends only on the two chains, so it is found once here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerGap {
    /// Bit j of entry i: part i of the first finger and part j of the
    /// second are compared.
    compared: [u32; MAX_CAPSULES + 1],
}

impl FingerGap {
    /// The pairs to compare between fingers `a` and `b`.
    pub fn new(a: &Chain<3>, b: &Chain<3>) -> Self {
        let (zero_a, len_a) = parts(a, &a.forward(&Vector3::zeros()));
        let (zero_b, len_b) = parts(b, &b.forward(&Vector3::zeros()));
        let mut compared = [0; MAX_CAPSULES + 1];
        for (i, row) in compared.iter_mut().enumerate().take(len_a) {
            for (j, other) in zero_b.iter().enumerate().take(len_b) {
                if zero_a[i].capsule_gap(other) >= 0.0 {
                    *row |= 1 << j;
                }
            }
        }
        Self { compared }
    }

    /// The smallest gap \[m\] between the two fingers (the chains given
    /// to [`FingerGap::new`], in that order) at their configurations (+∞
    /// when no pair is compared).
    pub fn gap(&self, a: (&Chain<3>, &ChainState<3>), b: (&Chain<3>, &ChainState<3>)) -> f64 {
        let (now_a, len_a) = parts(a.0, a.1);
        let (now_b, len_b) = parts(b.0, b.1);
        let mut gap = f64::INFINITY;
        for (i, part) in now_a.iter().enumerate().take(len_a) {
            for (j, other) in now_b.iter().enumerate().take(len_b) {
                if self.compared[i] & (1 << j) != 0 {
                    gap = gap.min(part.capsule_gap(other));
                }
            }
        }
        gap
    }
}

/// A finger's workspace tabulated over a grid of normals.
#[derive(Debug, Clone, PartialEq)]
pub struct Workspace {
    /// The grid's normals in the workspace, with how they are reached.
    pub reached: Vec<(Vector3<f64>, Reach)>,
    /// How many normals the grid had.
    pub tried: usize,
}

impl Workspace {
    /// Finger `chain`'s workspace over the unit normals `grid`.
    pub fn new(
        chain: &Chain<3>,
        ik: &ClosedFormIk,
        object: &Object,
        gravity: &Vector3<f64>,
        grid: &[Vector3<f64>],
        margins: &Margins,
    ) -> Self {
        let reached = grid
            .iter()
            .filter_map(|n| reach(chain, ik, object, gravity, n, margins).map(|r| (*n, r)))
            .collect();
        Self {
            reached,
            tried: grid.len(),
        }
    }

    /// The share of the grid reached.
    pub fn share(&self) -> f64 {
        self.reached.len() as f64 / self.tried.max(1) as f64
    }
}

/// `count` unit vectors spread evenly over the sphere (a Fibonacci
/// lattice): a grid of normals with no preferred direction.
pub fn sphere_grid(count: usize) -> Vec<Vector3<f64>> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vector3::new(rho * phi.cos(), rho * phi.sin(), z)
        })
        .collect()
}

//! The limits of a hand of finger chains for one state (SPEC §14.1), as
//! the per-tick check reports them: what replaces the free fingertips'
//! workspace cone, hemisphere, roll limit and fingertip collision.
//!
//! Each finger's joints come from its tip centre by the closed-form
//! inverse kinematics, on the branch nearest the joints of the state
//! checked before (a finger moving along a path stays on its branch; the
//! first state takes the branch the workspace test picks,
//! [`ChainHand::joints`]). Then:
//!
//! - **joint limits** (the chain's workspace): the margin of those joints
//!   beyond the chain's own margin;
//! - **tip patch**, grasping fingers: the contact's margin on the patch
//!   beyond the hand's patch margin;
//! - **link clearance**: every link capsule off the object by the hand's
//!   clearance;
//! - **free tips** above the object (no outer shell: reach and clearance
//!   bound a chain's free tip);
//! - **finger gaps**: the parts of every two fingers apart by the hand's
//!   gap (capsules; a pair with a finger no branch reaches falls back to
//!   its tip centres, 2r + gap apart).
//!
//! The same limits as the plan check's kinematic part
//! (`crate::planner::chains::certify`), without the load (the torque box
//! solves a cone program: a planning-time check). Allocation-free.

use core::f64::consts::PI;

use nalgebra::Vector3;

use super::chain_hand::ChainHand;
use super::invariant_report::{Check, InvariantReport, PAIRS, Unit};
use crate::hand_state::{FINGERS, FingerMode, HandState};
use kinematics::ChainState;
use kinematics::workspace::object_clearance;

/// The chain hand's part of the per-tick check, and the joints of the
/// state it checked last (module docs).
#[derive(Debug, Clone)]
pub struct ChainLimits {
    hand: ChainHand,
    joints: [Option<Vector3<f64>>; FINGERS],
}

impl ChainLimits {
    /// The limits of `hand`; no branch chosen yet.
    pub fn new(hand: ChainHand) -> Self {
        Self {
            hand,
            joints: [None; FINGERS],
        }
    }

    /// The hand.
    pub fn hand(&self) -> &ChainHand {
        &self.hand
    }

    /// Each finger's joints in the state checked last (`None` where no
    /// branch reaches its tip, or before the first check).
    pub fn joints(&self) -> &[Option<Vector3<f64>>; FINGERS] {
        &self.joints
    }

    /// Replaces the fingertip limits of `report` (made for `state` by the
    /// fingertip checks, which keep force closure and contact) with the
    /// chain's (module docs).
    pub(super) fn apply(&mut self, state: &HandState, report: &mut InvariantReport) {
        let hand = &self.hand;
        let lim = hand.limits();
        let object = hand.object();
        let mut states: [Option<ChainState<3>>; FINGERS] = [None; FINGERS];
        for (k, f) in state.fingers.iter().enumerate() {
            let chain = hand.chain(k);
            let q = hand.follow(k, &f.center, self.joints[k].as_ref());
            let out = &mut report.fingers[k];
            out.roll = None;
            out.hemisphere = None;
            out.links = None;
            let height = f.center.norm() - object.radius - chain.tip_radius;
            out.shell = (f.mode == FingerMode::Free).then(|| Check::closed(height, Unit::Metre));
            let Some(q) = q else {
                // Out of reach: the best branch's margin says by how much
                // the limits are in the way; −π where nothing reaches.
                let best = hand.best_limit_margin(k, &f.center).unwrap_or(-PI);
                out.workspace = Check::closed(best, Unit::Radian);
                continue;
            };
            self.joints[k] = Some(q);
            out.workspace = Check::closed(chain.limit_margin(&q), Unit::Radian);
            let s = chain.forward(&q);
            if f.mode == FingerMode::Grasping {
                let n = f.center.normalize();
                let patch = chain.patch.margin(&s.tip.rotation, &n) - lim.margins.patch;
                out.hemisphere = Some(Check::closed(patch, Unit::Radian));
            }
            let clearance = object_clearance(chain, &s, object) - lim.margins.clearance;
            out.links = Some(Check::closed(clearance, Unit::Metre));
            states[k] = Some(s);
        }
        for (p, &(a, b)) in PAIRS.iter().enumerate() {
            let gap = match (&states[a], &states[b]) {
                (Some(sa), Some(sb)) => {
                    hand.gap(a, b).gap((hand.chain(a), sa), (hand.chain(b), sb))
                }
                _ => {
                    let tips = hand.chain(a).tip_radius + hand.chain(b).tip_radius;
                    (state.fingers[a].center - state.fingers[b].center).norm() - tips
                }
            };
            report.collisions[p] = Check::closed(gap - lim.finger_gap, Unit::Metre);
        }
        report.chains = true;
    }
}

//! The exact check of a plan on finger chains (SPEC §14.1, §14.2): every
//! sample of every step, each finger's joints from its tip centre by the
//! closed-form inverse kinematics (branch kept from the sample before),
//! against
//!
//! - **reach**: a branch inside the joint limits puts the tip there, and
//!   the joints do not jump between two samples (a jump is another branch:
//!   the finger could not follow);
//! - **joint limits** with the chain's margin;
//! - **the tip patch** of a grasping finger, with the hand's patch margin;
//! - **link clearance**: every link capsule of every finger off the object
//!   by the hand's clearance, a free finger's tip off the object;
//! - **finger gaps**: every two fingers apart by the hand's gap;
//! - **the load**: the grasping fingers hold the object's weight within
//!   their torque box ([`crate::grasp::torque_box`]): two fingers as soft
//!   contacts, three as hard ones; while the object turns, with the torque
//!   its angular acceleration needs at the limit, both signs. Evaluated
//!   where the contacts move (every sample of a carry) and once per step
//!   where they do not.
//!
//! It answers with the tightest margins of the plan ([`ChainMargins`]), or
//! the first violation ([`ChainViolation`]). It allocates (the torque box
//! builds a problem per call): a planning-time check, not a tick's.

use nalgebra::Vector3;

use super::ChainHand;
use crate::grasp::Contact;
use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::planner::plan::{Motion, Step};
use kinematics::workspace::object_clearance;

/// How finely a plan is sampled, and what a turn's load includes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckParams {
    /// Longest object turn between two samples of a carry \[rad\].
    pub carry_step: f64,
    /// Longest tip travel between two samples of a free motion \[m\].
    pub free_step: f64,
    /// Largest joint change between two samples that is still the same
    /// branch \[rad\].
    pub branch_jump: f64,
    /// The object's largest angular acceleration while it turns \[rad/s²\].
    pub max_acceleration: f64,
    /// The least normal force of a grasping contact \[N\].
    pub min_grip: f64,
}

/// The tightest margins of a checked plan (each ≥ 0 where it passed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainMargins {
    /// Joint-limit margin beyond the chain's own \[rad\].
    pub joint: f64,
    /// Tip-patch margin of a grasping finger, beyond the hand's \[rad\].
    pub patch: f64,
    /// Link clearance to the object, beyond the hand's \[m\].
    pub clearance: f64,
    /// Gap between two fingers, beyond the hand's \[m\].
    pub gap: f64,
    /// The largest share of a motor's torque limit the load needs (u* of
    /// the torque box; ≤ 1 where held).
    pub torque_share: f64,
    /// Samples checked.
    pub samples: usize,
}

impl ChainMargins {
    /// Nothing checked yet: every margin unbounded, no share used.
    const NONE: Self = Self {
        joint: f64::INFINITY,
        patch: f64::INFINITY,
        clearance: f64::INFINITY,
        gap: f64::INFINITY,
        torque_share: 0.0,
        samples: 0,
    };
}

/// What a sample broke.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ViolationKind {
    /// No branch inside the joint limits puts the tip there.
    Unreachable,
    /// The joints jumped between two samples by this much \[rad\].
    BranchJump(f64),
    /// Joint-limit margin \[rad\] below zero.
    JointLimit(f64),
    /// Tip-patch margin \[rad\] below the hand's.
    TipPatch(f64),
    /// A link (or a free tip) this close to the object \[m\].
    ObjectClearance(f64),
    /// This finger and `other` this close \[m\].
    FingerGap {
        /// The other finger.
        other: usize,
        /// Their gap \[m\].
        gap: f64,
    },
    /// The load needs this share of a motor's limit (> 1; +∞ where no
    /// forces in the friction cones balance it).
    Load(f64),
    /// A motion a chain finger cannot make (a free fingertip's rolling on
    /// the still object).
    Unsupported,
}

/// The first sample a plan breaks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChainViolation {
    /// Step index.
    pub step: usize,
    /// Fraction of the step's path \[0, 1\].
    pub at: f64,
    /// The finger (the first of two for a gap; `None` for the load).
    pub finger: Option<usize>,
    /// What broke.
    pub kind: ViolationKind,
}

/// Checks `steps` from `start` on `hand` (module docs).
pub fn check(
    hand: &ChainHand,
    start: &HandState,
    steps: &[Step],
    params: &CheckParams,
) -> Result<ChainMargins, ChainViolation> {
    let mut margins = ChainMargins::NONE;
    let mut joints: [Option<Vector3<f64>>; FINGERS] = [None; FINGERS];
    let mut at = Sample::new(hand, params);
    at.kinematics(start, &mut joints, &mut margins)?;
    at.steps(steps, &mut joints, &mut margins, true)?;
    Ok(margins)
}

/// The kinematic part of [`check`] (reach, branch, joint limits, tip
/// patch, clearance, gaps; not the load) over `steps`, every finger
/// starting on the branch `joints` gives (updated to where they end): what
/// a builder asks of a finger's way before it commits to it. Step indices
/// in a violation count from the first of `steps`.
pub fn check_way(
    hand: &ChainHand,
    steps: &[Step],
    joints: &mut [Option<Vector3<f64>>; FINGERS],
    params: &CheckParams,
) -> Result<(), ChainViolation> {
    let mut margins = ChainMargins::NONE;
    let mut at = Sample::new(hand, params);
    at.steps(steps, joints, &mut margins, false)
}

/// Where the check is, for its verdicts.
struct Sample<'a> {
    hand: &'a ChainHand,
    params: &'a CheckParams,
    step: usize,
    at: f64,
}

impl<'a> Sample<'a> {
    fn new(hand: &'a ChainHand, params: &'a CheckParams) -> Self {
        Self {
            hand,
            params,
            step: 0,
            at: 0.0,
        }
    }

    fn fail(&self, finger: Option<usize>, kind: ViolationKind) -> ChainViolation {
        ChainViolation {
            step: self.step,
            at: self.at,
            finger,
            kind,
        }
    }

    /// Every sample of `steps` (carries every `carry_step`, free motions
    /// every `free_step`), with the load where `load` says.
    fn steps(
        &mut self,
        steps: &[Step],
        joints: &mut [Option<Vector3<f64>>; FINGERS],
        margins: &mut ChainMargins,
        load: bool,
    ) -> Result<(), ChainViolation> {
        for (i, st) in steps.iter().enumerate() {
            self.step = i;
            let length = st.dofs().length;
            let (n, turning) = match st.motion {
                Motion::Carry { axis, angle, .. } => (
                    (angle / self.params.carry_step).ceil().max(1.0) as usize,
                    Some(axis),
                ),
                Motion::Free(m) => (
                    (m.path.length() / self.params.free_step).ceil().max(1.0) as usize,
                    None,
                ),
                Motion::Rotate { .. } | Motion::Roll { .. } | Motion::RollSegment { .. } => {
                    return Err(ChainViolation {
                        step: i,
                        at: 0.0,
                        finger: st.finger(),
                        kind: ViolationKind::Unsupported,
                    });
                }
            };
            for k in 0..=n {
                self.at = k as f64 / n as f64;
                let state = st.eval(&length.map(|l| l * self.at), &[0.0; 3]).state;
                self.kinematics(&state, joints, margins)?;
                // The contacts move only in a carry; otherwise once a step.
                if load && (turning.is_some() || k == 0) {
                    self.load(&state, joints, turning.as_ref(), margins)?;
                }
            }
        }
        Ok(())
    }

    /// Reach, joint limits, patch, clearance and gaps at `state`; `joints`
    /// carries each finger's branch from sample to sample.
    fn kinematics(
        &self,
        state: &HandState,
        joints: &mut [Option<Vector3<f64>>; FINGERS],
        m: &mut ChainMargins,
    ) -> Result<(), ChainViolation> {
        let hand = self.hand;
        let lim = hand.limits();
        let object = hand.object();
        let mut states = [None; FINGERS];
        m.samples += 1;
        for (k, f) in state.fingers.iter().enumerate() {
            let chain = hand.chain(k);
            // The branch the finger is on (the limits are checked below),
            // or at the start the admissible one with the most margin.
            let q = hand.follow(k, &f.center, joints[k].as_ref());
            let Some(q) = q else {
                let kind = hand
                    .best_limit_margin(k, &f.center)
                    .map_or(ViolationKind::Unreachable, ViolationKind::JointLimit);
                return Err(self.fail(Some(k), kind));
            };
            if let Some(before) = joints[k] {
                let jump = (q - before).amax();
                if jump > self.params.branch_jump {
                    return Err(self.fail(Some(k), ViolationKind::BranchJump(jump)));
                }
            }
            joints[k] = Some(q);
            let joint = chain.limit_margin(&q);
            m.joint = m.joint.min(joint);
            if joint < 0.0 {
                return Err(self.fail(Some(k), ViolationKind::JointLimit(joint)));
            }
            let s = chain.forward(&q);
            let n = f.center.normalize();
            if f.mode == FingerMode::Grasping {
                let patch = chain.patch.margin(&s.tip.rotation, &n) - lim.margins.patch;
                m.patch = m.patch.min(patch);
                if patch < 0.0 {
                    return Err(self.fail(Some(k), ViolationKind::TipPatch(patch)));
                }
            } else {
                let tip_gap = f.center.norm() - object.radius - chain.tip_radius;
                // (Touching down and lifting off start at the surface.)
                if tip_gap < -1e-9 {
                    return Err(self.fail(Some(k), ViolationKind::ObjectClearance(tip_gap)));
                }
            }
            let clearance = object_clearance(chain, &s, object);
            m.clearance = m.clearance.min(clearance - lim.margins.clearance);
            if clearance < lim.margins.clearance {
                return Err(self.fail(Some(k), ViolationKind::ObjectClearance(clearance)));
            }
            states[k] = Some(s);
        }
        for a in 0..FINGERS {
            for b in a + 1..FINGERS {
                let (Some(sa), Some(sb)) = (&states[a], &states[b]) else {
                    continue;
                };
                let gap = hand.gap(a, b).gap((hand.chain(a), sa), (hand.chain(b), sb));
                m.gap = m.gap.min(gap - lim.finger_gap);
                if gap < lim.finger_gap {
                    return Err(self.fail(Some(a), ViolationKind::FingerGap { other: b, gap }));
                }
            }
        }
        Ok(())
    }

    /// The grasp of `state` holding the load within the torque box (module
    /// docs), turning about `axis` or at rest.
    fn load(
        &self,
        state: &HandState,
        joints: &[Option<Vector3<f64>>; FINGERS],
        axis: Option<&Vector3<f64>>,
        m: &mut ChainMargins,
    ) -> Result<(), ChainViolation> {
        let share = grasp_share(self.hand, state, joints, axis, self.params);
        m.torque_share = m.torque_share.max(share);
        if share > 1.0 {
            return Err(self.fail(None, ViolationKind::Load(share)));
        }
        Ok(())
    }
}

/// The least share of the motors' torque limits with which the grasping
/// fingers of `state` (at `joints`) hold the load (module docs): u* of the
/// torque box, 0 without a load, +∞ where no forces in the friction
/// cones hold it or a grasping finger's joints are unknown.
pub fn grasp_share(
    hand: &ChainHand,
    state: &HandState,
    joints: &[Option<Vector3<f64>>; FINGERS],
    axis: Option<&Vector3<f64>>,
    params: &CheckParams,
) -> f64 {
    let (idx, count) = state.grasping();
    let weight = hand.gravity() * hand.object().mass;
    if count == 0 || weight.norm() == 0.0 && axis.is_none() {
        return 0.0;
    }
    let mut contacts = Vec::with_capacity(count);
    let mut statics = Vec::with_capacity(count);
    for &k in &idx[..count] {
        let n = state.fingers[k].center.normalize();
        contacts.push(if count == 3 {
            Contact::hard(n)
        } else {
            Contact::soft(n)
        });
        let Some(q) = joints[k] else {
            return f64::INFINITY;
        };
        statics.push(hand.statics(k, &q, &n));
    }
    let accel = axis.map_or(Vector3::zeros(), |a| {
        a * (hand.inertia() * params.max_acceleration)
    });
    let scenarios = if axis.is_some() {
        vec![(weight, accel), (weight, -accel)]
    } else {
        vec![(weight, Vector3::zeros())]
    };
    hand.torque_box()
        .solve(&contacts, &statics, &scenarios, params.min_grip)
        .map_or(f64::INFINITY, |s| s.utilisation)
}

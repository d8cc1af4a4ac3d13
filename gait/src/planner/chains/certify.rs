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
//!   where they do not; the closed-form forces first, the cone program
//!   where they do not prove it ([`super::quick_hold`]).
//!
//! The kinematic margins hold between two samples too, not only at them:
//! where the margins at two samples do not prove it (`held_between`: a
//! margin moves no faster than the parts it measures,
//! [`kinematics::parts_travel`]), the check samples the middle, and both
//! halves in turn.
//!
//! It answers with the tightest margins of the plan ([`ChainMargins`]), or
//! the first violation ([`ChainViolation`]). It allocates (the torque box
//! builds a problem per call): a planning-time check, not a tick's.

use nalgebra::Vector3;

use super::ChainHand;
use super::quick_hold::closed_form_share;
use crate::grasp::Contact;
use crate::hand::{PAIRS, SLACK_TOLERANCE};
use crate::hand_state::{FINGERS, FingerMode, HandState};
use crate::planner::plan::{Motion, Step};
use kinematics::workspace::object_clearance;
use kinematics::{ChainState, parts_travel};

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
    /// the torque box, or where the closed-form forces already hold it,
    /// their share, an upper bound of u*: [`super::quick_hold`]; ≤ 1 where
    /// held).
    pub torque_share: f64,
    /// Samples checked.
    pub samples: usize,
    /// Of those, samples checked between two of the even ones, where the
    /// margins at the two were too small to say they held between.
    pub refined: usize,
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
        refined: 0,
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
    joints = at.kinematics(start, &joints, &mut margins)?.joints;
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

/// How many times the check halves the way between two samples, at most,
/// before it takes the margins held there: 2⁻²⁰ of a sample's spacing,
/// under a nanometre for a free motion sampled every millimetre.
const MAX_REFINE: u32 = 20;

/// One sample's joints and margins (each beyond the hand's own; +∞ where
/// it does not apply), what the check needs between two samples.
#[derive(Debug, Clone, Copy)]
struct Local {
    /// Fraction of the step's path.
    at: f64,
    joints: [Option<Vector3<f64>>; FINGERS],
    states: [Option<ChainState<3>>; FINGERS],
    /// Each finger's contact normal (its tip centre's direction).
    normals: [Vector3<f64>; FINGERS],
    joint: [f64; FINGERS],
    patch: [f64; FINGERS],
    clearance: [f64; FINGERS],
    /// Per pair of [`PAIRS`].
    gap: [f64; 3],
}

/// Whether every margin provably holds between the samples `lo` and `hi`
/// of one step. A margin m that is 1-Lipschitz in some travel T between
/// the two stays at least (m_lo + m_hi − T)/2 all the way (the floor):
///
/// - joint limits: in the joints' largest change;
/// - the tip patch: in the tip's turn (at most Σ|Δq_i|) plus the normal's;
/// - link clearance and finger gaps: in the travel of the parts
///   involved ([`kinematics::parts_travel`]).
///
/// The floor must be ≥ 0 (to the invariants' slack tolerance).
fn held_between(hand: &ChainHand, lo: &Local, hi: &Local) -> bool {
    let floor = |a: f64, b: f64, travel: f64| (a + b - travel) / 2.0 >= -SLACK_TOLERANCE;
    let mut travel = [0.0; FINGERS];
    for (k, travel) in travel.iter_mut().enumerate() {
        let (Some(qa), Some(qb), Some(sa), Some(sb)) =
            (lo.joints[k], hi.joints[k], &lo.states[k], &hi.states[k])
        else {
            continue;
        };
        let dq = qb - qa;
        *travel = parts_travel(hand.chain(k), (&qa, sa), (&qb, sb));
        let turn = dq.abs().sum() + lo.normals[k].angle(&hi.normals[k]);
        if !floor(lo.joint[k], hi.joint[k], dq.amax())
            || !floor(lo.clearance[k], hi.clearance[k], *travel)
            || !floor(lo.patch[k], hi.patch[k], turn)
        {
            return false;
        }
    }
    PAIRS
        .iter()
        .enumerate()
        .all(|(p, &(a, b))| floor(lo.gap[p], hi.gap[p], travel[a] + travel[b]))
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
    /// every `free_step`), refined between two samples until the margins
    /// provably hold between them ([`Self::between`]), with the load where
    /// `load` says.
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
            let eval = |at: f64| st.eval(&length.map(|l| l * at), &[0.0; 3]).state;
            let mut before: Option<Local> = None;
            for k in 0..=n {
                self.at = k as f64 / n as f64;
                let state = eval(self.at);
                let here = self.kinematics(&state, joints, margins)?;
                if let Some(before) = &before {
                    self.between(&eval, before, &here, 0, margins)?;
                    self.at = here.at;
                }
                *joints = here.joints;
                // The contacts move only in a carry; otherwise once a step.
                if load && (turning.is_some() || k == 0) {
                    self.load(&state, joints, turning.as_ref(), margins)?;
                }
                before = Some(here);
            }
        }
        Ok(())
    }

    /// Between the samples `lo` and `hi` of the step `eval` evaluates: the
    /// margins hold all the way if each stays above its floor
    /// ([`held_between`]); else the middle is checked and both halves in
    /// turn, at most [`MAX_REFINE`] halvings deep.
    fn between(
        &mut self,
        eval: &impl Fn(f64) -> HandState,
        lo: &Local,
        hi: &Local,
        depth: u32,
        m: &mut ChainMargins,
    ) -> Result<(), ChainViolation> {
        if depth >= MAX_REFINE || held_between(self.hand, lo, hi) {
            return Ok(());
        }
        self.at = 0.5 * (lo.at + hi.at);
        let mid = self.kinematics(&eval(self.at), &lo.joints, m)?;
        m.refined += 1;
        self.between(eval, lo, &mid, depth + 1, m)?;
        self.between(eval, &mid, hi, depth + 1, m)
    }

    /// Reach, joint limits, patch, clearance and gaps at `state`, each
    /// finger following on from the branch `joints` gives; the sample's
    /// joints and margins.
    fn kinematics(
        &self,
        state: &HandState,
        joints: &[Option<Vector3<f64>>; FINGERS],
        m: &mut ChainMargins,
    ) -> Result<Local, ChainViolation> {
        let hand = self.hand;
        let lim = hand.limits();
        let object = hand.object();
        let mut here = Local {
            at: self.at,
            joints: *joints,
            states: [None; FINGERS],
            normals: [Vector3::zeros(); FINGERS],
            joint: [f64::INFINITY; FINGERS],
            patch: [f64::INFINITY; FINGERS],
            clearance: [f64::INFINITY; FINGERS],
            gap: [f64::INFINITY; PAIRS.len()],
        };
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
            here.joints[k] = Some(q);
            let joint = chain.limit_margin(&q);
            here.joint[k] = joint;
            m.joint = m.joint.min(joint);
            if joint < 0.0 {
                return Err(self.fail(Some(k), ViolationKind::JointLimit(joint)));
            }
            let s = chain.forward(&q);
            let n = f.center.normalize();
            here.normals[k] = n;
            if f.mode == FingerMode::Grasping {
                let patch = chain.patch.margin(&s.tip.rotation, &n) - lim.margins.patch;
                here.patch[k] = patch;
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
            here.clearance[k] = clearance - lim.margins.clearance;
            m.clearance = m.clearance.min(clearance - lim.margins.clearance);
            if clearance < lim.margins.clearance {
                return Err(self.fail(Some(k), ViolationKind::ObjectClearance(clearance)));
            }
            here.states[k] = Some(s);
        }
        for (p, &(a, b)) in PAIRS.iter().enumerate() {
            let (Some(sa), Some(sb)) = (&here.states[a], &here.states[b]) else {
                continue;
            };
            let gap = hand.gap(a, b).gap((hand.chain(a), sa), (hand.chain(b), sb));
            here.gap[p] = gap - lim.finger_gap;
            m.gap = m.gap.min(gap - lim.finger_gap);
            if gap < lim.finger_gap {
                return Err(self.fail(Some(a), ViolationKind::FingerGap { other: b, gap }));
            }
        }
        Ok(here)
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
        // The closed forms' share where it proves the grasp (an upper
        // bound of u*), else the cone program's.
        let share = match closed_form_share(self.hand, state, joints, axis, self.params) {
            Some(s) if s <= 1.0 => s,
            _ => grasp_share(self.hand, state, joints, axis, self.params),
        };
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

//! The boundary between the search and the hand (SPEC §4.2, §14).
//!
//! The search ([`super::search`]) knows a grasp only as which fingers
//! touch the object and where: unit contact normals n in the hand frame.
//! Whatever depends on a finger's own body (how two contacts sit apart,
//! which load a pair holds) is asked with the finger named ([`At`]): a
//! chain finger's posture, and so its reach and its torques, are its own.
//! Everything else — where a finger can touch, how the fingers move when
//! the object turns, how far they can carry it, which forces the contacts
//! can give, what collides, how long a motion takes, and what a finger can
//! do on the still object — it asks a [`HandModel`]. The paper's free
//! fingertips implement it ([`super::fingertips::Fingertips`]), and so
//! does a hand of finger chains ([`super::chains::model::ChainModel`]),
//! which declares what sets it apart: its pairs do not turn the object
//! ([`HandModel::pairs_turn`]) and it makes no regrasp on the still
//! object ([`HandModel::offers_regrasps`]).

use nalgebra::Vector3;

use super::budget::Stop;
use super::plan::Step;
use super::timing::DurationModel;
use crate::hand_state::HandState;

/// What the object turns for (the plan's route names it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Turn {
    /// About the axis of the rotation still to do.
    Toward,
    /// Three fingers tilt the object about the chord of a pair, so that
    /// the pair holds the weight with less opening (SPEC §1.3 I1').
    Tilt,
    /// About another axis, because that makes the rest quicker or gaits
    /// possible at all (paper Theory 1, SPEC §4.3).
    Detour,
}

/// One action of a plan, as the search chose it (SPEC §4.2).
pub enum Action<H: HandModel + ?Sized> {
    /// The grasping fingers carry the object about the unit `axis` by
    /// `angle` ≥ 0.
    Rotate {
        /// Unit axis, hand frame.
        axis: Vector3<f64>,
        /// Angle \[rad\].
        angle: f64,
        /// Why.
        why: Turn,
    },
    /// A free finger touches down at `contact`.
    Place {
        /// Finger.
        finger: usize,
        /// Unit contact normal, hand frame.
        contact: Vector3<f64>,
        /// How it touches (hand-specific).
        touch: H::Touch,
    },
    /// A grasping finger leaves the object.
    Lift {
        /// Finger.
        finger: usize,
    },
    /// A hand-specific motion on the still object.
    Regrasp {
        /// The motion.
        regrasp: H::Regrasp,
        /// What it was asked for.
        why: RegraspFor,
    },
}

// (By hand: derived impls would ask the hand itself to be Clone, …)
impl<H: HandModel + ?Sized> Clone for Action<H> {
    fn clone(&self) -> Self {
        match self {
            Self::Rotate { axis, angle, why } => Self::Rotate {
                axis: *axis,
                angle: *angle,
                why: *why,
            },
            Self::Place {
                finger,
                contact,
                touch,
            } => Self::Place {
                finger: *finger,
                contact: *contact,
                touch: *touch,
            },
            Self::Lift { finger } => Self::Lift { finger: *finger },
            Self::Regrasp { regrasp, why } => Self::Regrasp {
                regrasp: regrasp.clone(),
                why: *why,
            },
        }
    }
}

impl<H: HandModel + ?Sized> std::fmt::Debug for Action<H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rotate { axis, angle, why } => f
                .debug_struct("Rotate")
                .field("axis", axis)
                .field("angle", angle)
                .field("why", why)
                .finish(),
            Self::Place {
                finger,
                contact,
                touch,
            } => f
                .debug_struct("Place")
                .field("finger", finger)
                .field("contact", contact)
                .field("touch", touch)
                .finish(),
            Self::Lift { finger } => f.debug_struct("Lift").field("finger", finger).finish(),
            Self::Regrasp { regrasp, why } => f
                .debug_struct("Regrasp")
                .field("regrasp", regrasp)
                .field("why", why)
                .finish(),
        }
    }
}

/// A regrasp the hand offers, with where it ends and what it costs.
#[derive(Debug, Clone)]
pub struct Offer<R> {
    /// The motion.
    pub regrasp: R,
    /// The state after it.
    pub end: HandState,
    /// Its execution time \[s\].
    pub cost: f64,
}

/// Why a regrasp is asked for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RegraspFor {
    /// Three fingers grasp and no pair of them holds on its own: open the
    /// pair that keeps finger `keep_out` out of it so that `keep_out` can
    /// lift (paper Fig. 4 frames 1–2).
    OpenPair {
        /// The finger that will lift.
        lift: usize,
    },
    /// A grasp no gait may leave (two fingers: paper Theory 1 fails, or
    /// the pair is at its limits; three: their rolls are): change it on
    /// the still object.
    Unstick,
}

/// Finger k touching the object at the unit normal n (hand frame).
pub type At<'a> = (usize, &'a Vector3<f64>);

/// The hand as the planner sees it (module docs). Implementations are
/// pure and deterministic.
pub trait HandModel {
    /// How a free finger touches down (e.g. a fingertip's roll preset).
    type Touch: Copy + std::fmt::Debug + PartialEq;
    /// A hand-specific motion on the still object (e.g. rolling).
    type Regrasp: Clone + std::fmt::Debug + PartialEq;
    /// What the exact check of a plan found wrong.
    type Violation: std::fmt::Debug;

    /// Motion durations (SPEC §5).
    fn timing(&self) -> &DurationModel;

    /// Candidate contact normals of finger `k` (its workspace, gridded).
    fn candidates(&self, k: usize) -> &[Vector3<f64>];
    /// Indices into `candidates(b)` of the candidates that make a pair the
    /// planner may use with `candidates(a)[i]` (force closure with margin).
    fn partners(&self, a: usize, b: usize, i: usize) -> &[u16];
    /// Whether two contacts of a two-finger grasp are force-closure with
    /// the planning margin.
    fn good_pair(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> bool;
    /// Whether two fingers touching at these contacts are clear of each
    /// other.
    fn apart(&self, a: At<'_>, b: At<'_>) -> bool;
    /// Whether three contacts are force-closure as hard contacts.
    fn fc_triple(&self, c: &[Vector3<f64>; 3]) -> bool;

    /// Whether a pair of grasping fingers turns the object (else only three
    /// do, and a two-finger node is expanded by
    /// [`super::alternatives::STILL_PAIR_ACTIONS`]).
    fn pairs_turn(&self) -> bool {
        true
    }
    /// Whether the hand makes any regrasp on the still object (else the
    /// search asks for none).
    fn offers_regrasps(&self) -> bool {
        true
    }
    /// How far the grasping `fingers` of `hand` can carry the object about
    /// the unit `axis`: each inside its workspace and the finger's own
    /// limits (not the load). The caller needs no more than `limit`: a
    /// hand may stop looking there (and answer `limit`).
    fn carry_range(
        &self,
        hand: &HandState,
        fingers: &[usize],
        axis: &Vector3<f64>,
        limit: f64,
    ) -> f64;
    /// Turns the object about `axis` by `angle`, the grasping fingers with it.
    fn carry(&self, hand: &mut HandState, axis: &Vector3<f64>, angle: f64);
    /// How finger `k` would touch down at `contact` to carry about `axis`
    /// next, and how far it could then carry on its own limits.
    fn touch_for(
        &self,
        k: usize,
        contact: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> (Self::Touch, f64);
    /// Puts free finger `k` down at `contact`.
    fn place(&self, hand: &mut HandState, k: usize, contact: &Vector3<f64>, touch: Self::Touch);
    /// Lifts grasping finger `k` to where it waits.
    fn lift(&self, hand: &mut HandState, k: usize);
    /// Whether grasping finger `k` of `hand` has a clear way out to where
    /// it waits (a hand whose fingers cannot block one another's lift
    /// says yes).
    fn can_lift(&self, _hand: &HandState, _k: usize) -> bool {
        true
    }
    /// Unit direction from the object centre of a free finger.
    fn hover_dir(&self, hand: &HandState, k: usize) -> Vector3<f64>;
    /// The part of grasping finger `k`'s state, beyond its contact, that
    /// tells two search nodes apart (quantised), turning about `axis`.
    fn key(&self, hand: &HandState, k: usize, axis: &Vector3<f64>) -> [i64; 2];

    /// Whether there is a load to hold (SPEC §1.3 I1').
    fn load_active(&self) -> bool;
    /// The unit direction of the weight in the hand frame (−z without one).
    fn weight_direction(&self) -> Vector3<f64>;
    /// Calls `f` with each candidate (index into `candidates(z)`) of free
    /// finger `z` that makes with grasping finger `x`'s contact `cx` a good
    /// pair holding the load at rest, until `f` returns false. May round
    /// `cx` to a fine grid (it steers the search); `f`'s second argument
    /// says whether this candidate was decided where `cx` really is, with
    /// [`HandModel::good_pair`] and [`HandModel::pair_holds`]: where it was
    /// not, check what is chosen with them.
    fn resting_partners(
        &self,
        x: usize,
        cx: &Vector3<f64>,
        z: usize,
        f: &mut dyn FnMut(usize, bool) -> bool,
    );
    /// Whether the soft pair of fingers at `a`, `b` holds the load: at
    /// rest (`None`) or turning about the axis.
    fn pair_holds(&self, a: At<'_>, b: At<'_>, axis: Option<&Vector3<f64>>) -> bool;
    /// How far (≤ `limit`) the pair can turn about `axis` and still hold.
    fn pair_hold_range(&self, a: At<'_>, b: At<'_>, axis: &Vector3<f64>, limit: f64) -> f64;
    /// Whether the grasp of `hand` holds the load at rest.
    fn holds_at_rest(&self, hand: &HandState) -> bool;
    /// Whether the grasp of `hand` holds the load at every sample of a
    /// turn about `axis` by `angle` (deferred by the search: may cost).
    fn holds_along(&self, hand: &HandState, axis: &Vector3<f64>, angle: f64) -> bool;

    /// The regrasps the hand offers from `hand` (deferred by the search:
    /// may cost; `stop` is polled inside long computations). They do not
    /// depend on the goal, so a hand may keep what it found.
    fn regrasps(
        &self,
        hand: &HandState,
        why: RegraspFor,
        stop: &mut dyn Stop,
    ) -> Vec<Offer<Self::Regrasp>>;
    /// A short name of a regrasp (e.g. "open in legs"), for the route.
    fn regrasp_name(&self, r: &Self::Regrasp) -> &'static str;
    /// A lower bound of the time of any regrasp `why` from `hand` \[s\].
    fn regrasp_bound(&self, hand: &HandState, why: RegraspFor) -> f64;

    /// The steps that execute `actions` from `start` (SPEC §4.2), or the
    /// finger that cannot move clear of the others.
    fn build(&self, start: &HandState, actions: &[Action<Self>]) -> Result<Vec<Step>, usize>;
    /// The exact check of built steps (SPEC §1.3 at every sample).
    fn check(&self, start: &HandState, steps: &[Step]) -> Result<(), Self::Violation>;
}

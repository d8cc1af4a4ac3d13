//! What the planner tries, and in which order — the whole list, as data.
//!
//! Planning is one A* search ([`super::search`]) run as the [`PASSES`] of
//! a small portfolio under one budget: a pass that finds a plan; only when
//! it proves that it finds none, for a later piece of a long turn, one
//! that lets that piece first turn about another axis; then one that also
//! lets contacts spin under load. (An
//! improving pass — a less greedy search pruned by the plan in hand and
//! capped at a multiple of the effort so far — is a [`Role`] the list may
//! hold.) A budget spent ends planning wherever it is, with the best plan
//! found so far.
//!
//! In a pass, a node's children are generated in the order of
//! [`PAIR_ACTIONS`] (two fingers grasp, the third is free; on a hand whose
//! pairs do not turn, [`STILL_PAIR_ACTIONS`]) or [`TRIPLE_ACTIONS`]
//! (three grasp); the search expands them cheapest
//! first (execution time so far plus a weighted estimate of the rest),
//! ties in that order. The fractions below are the turn lengths offered.

use super::hand_model::Turn;

/// When a pass runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Role {
    /// While no plan is in hand.
    Find,
    /// When a plan is in hand: only quicker ones count, and the pass stops
    /// after `effort` times the expansions spent before it, or
    /// `at_least` expansions if that is more.
    Improve {
        /// Its cap, in multiples of the effort so far.
        effort: u32,
        /// Its least cap (a plan found at once leaves time to improve it).
        at_least: u32,
    },
}

/// One pass of the portfolio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pass {
    /// When it runs.
    pub role: Role,
    /// Weight of the time-to-go estimate (1: A*; more: greedier). 1.5
    /// plans as quickly as a greedier search for the same execution time.
    pub weight: f64,
    /// Whether contacts may spin on the object under load (a spinning
    /// contact has no torsion to spare; the last resort).
    pub spins: bool,
    /// Whether a later piece of a long turn ([`TURN_PIECE`]) may first
    /// turn about another axis. The first piece, and an orientation goal,
    /// always may; a later one goes on about the turn's axis unless that
    /// finds nothing.
    pub later_detours: bool,
    /// Whether a walk whose end turns offers that turn at once, weighed by
    /// its own cost rather than the estimate's: long plans are found far
    /// sooner, though not always the quickest of them.
    pub eager_walks: bool,
}

/// The passes, in order. (A pass that would search as one before it did
/// — detours where every piece may detour anyway, spins without a load —
/// is skipped.)
pub const PASSES: [Pass; 3] = [
    Pass {
        role: Role::Find,
        weight: 1.5,
        spins: false,
        later_detours: false,
        eager_walks: false,
    },
    Pass {
        role: Role::Find,
        weight: 1.5,
        spins: false,
        later_detours: true,
        eager_walks: false,
    },
    Pass {
        role: Role::Find,
        weight: 1.5,
        spins: true,
        later_detours: true,
        eager_walks: false,
    },
];

/// The least cap of an Improve pass, in expansions: a plan found in a
/// dozen expansions leaves the improving pass more than three dozen.
pub const IMPROVE_AT_LEAST: u32 = 60;

/// The passes on a hand whose pairs do not turn (finger chains), in order.
/// Only three fingers turn there, and every segment costs fingers walked
/// to new contacts: the time-to-go estimate, which counts a segment as one
/// gait, is far below the truth, and a search at the fingertips' weight
/// spends its budget on the cheap alternatives before any long one (the
/// figures: docs/design/14-finger-chains.md). The improving pass wins back
/// much of what the greedier search loses in plan length.
pub const STILL_PAIR_PASSES: [Pass; 2] = [
    Pass {
        role: Role::Find,
        weight: 3.0,
        spins: false,
        later_detours: false,
        eager_walks: true,
    },
    Pass {
        role: Role::Improve {
            effort: 3,
            at_least: IMPROVE_AT_LEAST,
        },
        weight: 1.5,
        spins: false,
        later_detours: false,
        eager_walks: true,
    },
];

/// A pass's search turns greedier as it runs long: after this many
/// expansions (and deferred evaluations) of the pass, the estimate's
/// weight becomes this (never lower than the pass's own). A plan found
/// early is found as the pass's weight would find it; a hard request
/// still ends in a plan rather than a timeout.
pub const GREEDIER: [(u32, f64); 2] = [(4000, 3.0), (12_000, 6.0)];

/// A turn goal is planned as equal consecutive pieces no longer than this,
/// each as the orientation it must reach, from where the last ends
/// \[rad\] (90°): shorter than half a turn, a piece's shortest rotation is
/// the turn's own, so the object turns that far, that way; where two
/// pieces meet with the same pair turning on, the two turns are one.
pub const TURN_PIECE: f64 = std::f64::consts::FRAC_PI_2;

/// On chains, a piece of a turn whose search is exhausted from where the
/// last piece ended (no plan, not out of budget) is not the end: the rest
/// of the turn is cut into one piece more — other orientations to pass
/// through, other grasps to rest in between — at most this many times
/// per goal.
pub const CHAIN_TURN_RECUTS: usize = 3;

/// The kinds of children a node gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ActionKind {
    /// The grasping fingers turn the object about the axis of the rotation
    /// still to do, by each of the fractions offered (a pair:
    /// [`PAIR_TURN_FRACTIONS`] of its range, shortened until a gait can
    /// follow; three fingers: [`TRIPLE_TURN_FRACTIONS`]), or to the goal.
    Toward,
    /// Substitution (paper §2.1): the free finger is placed force-closure
    /// with one grasping finger, the other lifts. The best
    /// `planner.branching` placements per side by the rotation they allow
    /// and the travel to them, plus the quickest to reach.
    Substitute,
    /// The free finger is placed and three fingers grasp (the three hold
    /// the load where no pair would): the best `planner.branching` by how
    /// far the three could turn towards the goal and the travel.
    Place,
    /// A grasping finger lifts, the other two holding (three grasp; not
    /// the finger just placed).
    Lift,
    /// Three fingers tilt the object about the chord of a pair, both ways,
    /// by [`TILT_FRACTIONS`] of how far they can (only under a weight,
    /// only before a first lift).
    Tilt,
    /// Under a weight, a turn about the weight's direction by the rotation
    /// left's twist about it (swing–twist decomposition), or as far as the
    /// pair can: a turn about the weight leaves every grasp's load as it
    /// is.
    Twist,
    /// A turn about another axis: before the object has turned at all (in a
    /// turn goal's first piece only), `planner.detour_axes` directions by
    /// their range and half of it; from a node where no gait
    /// can follow (paper Theory 1), the least turn about each of
    /// `planner.escape_axes` directions after which one can. On a hand
    /// whose pairs do not turn, from three fingers none of which can lift
    /// (at a root, or where a turn ended): [`TRIPLE_ESCAPE_FRACTIONS`] of
    /// how far the three carry the object about each of
    /// [`TRIPLE_ESCAPE_AXES`] directions, so that a pair holds after.
    Detour,
    /// On a hand whose pairs do not turn, from three fingers that cannot
    /// turn as far as the goal (at a root, or after a turn as far as they
    /// could): fingers lifted
    /// and placed anew one at a time, each placement among those with the
    /// longest own range about the axis, until every finger can follow the
    /// object far enough (or as far as any walk found gets):
    /// [`super::search::walk`] (up to `WALK_DEPTH` moves, the shortest
    /// sequence first).
    Walk,
    /// A hand-specific motion on the still object: with three fingers (at
    /// a root, after a tilt or a placement) a pair rolled apart so that the
    /// third can lift where it cannot yet, and at a root whatever unsticks
    /// the grasp; with two fingers, at a root or where no other child is,
    /// whatever unsticks the grasp.
    Regrasp,
}

/// The children of a two-finger node, in order.
pub const PAIR_ACTIONS: [ActionKind; 6] = [
    ActionKind::Toward,
    ActionKind::Twist,
    ActionKind::Substitute,
    ActionKind::Place,
    ActionKind::Detour,
    ActionKind::Regrasp,
];

/// The children of a two-finger node of a hand whose pairs do not turn
/// ([`super::hand_model::HandModel::pairs_turn`]: finger chains, whose
/// pairs would spin): the free finger placed, so that three turn.
pub const STILL_PAIR_ACTIONS: [ActionKind; 1] = [ActionKind::Place];

/// The children of a three-finger node, in order.
pub const TRIPLE_ACTIONS: [ActionKind; 6] = [
    ActionKind::Lift,
    ActionKind::Toward,
    ActionKind::Tilt,
    ActionKind::Regrasp,
    ActionKind::Walk,
    ActionKind::Detour,
];

/// Directions (a Fibonacci sphere) three fingers none of which can lift
/// turn the object about ([`ActionKind::Detour`]).
pub const TRIPLE_ESCAPE_AXES: usize = 16;

/// Those turns, in fractions of how far the three carry the object (at
/// most [`MAX_TILT`]).
pub const TRIPLE_ESCAPE_FRACTIONS: [f64; 2] = [0.5, 1.0];

/// A pair's turn towards the goal: as far as it can, and half as far
/// (stopping early can keep a better gait possible).
pub const PAIR_TURN_FRACTIONS: [f64; 2] = [1.0, 0.5];

/// Three fingers' turn towards the goal, in fractions of how far all
/// three can carry the object (no pair has to hold the load meanwhile).
pub const TRIPLE_TURN_FRACTIONS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// A tilt about a pair's chord, in fractions of how far the three can
/// (at most [`MAX_TILT`]).
pub const TILT_FRACTIONS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// Longest tilt \[rad\] (90°): beyond it the pair's plane tilts past the
/// vertical again.
pub const MAX_TILT: f64 = std::f64::consts::FRAC_PI_2;

/// Turns shorter than this are not worth a step \[rad\] (2°); a pair's
/// turn is never shorter than [`MIN_PAIR_TURN`].
pub const MIN_TURN: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// A pair's shortest turn worth a segment \[rad\].
pub const MIN_PAIR_TURN: f64 = 1e-3;

/// A detour's shortest turn \[rad\] (~10°).
pub const MIN_DETOUR: f64 = 0.17;

/// Longest escape turn \[rad\] (90°), and its step (5°).
pub const MAX_ESCAPE: f64 = std::f64::consts::FRAC_PI_2;
/// Step of the escape turn's scan \[rad\].
pub const ESCAPE_STEP: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// Why a turn is offered, for each kind that turns.
pub fn turn_of(kind: ActionKind) -> Option<Turn> {
    match kind {
        ActionKind::Toward => Some(Turn::Toward),
        ActionKind::Tilt => Some(Turn::Tilt),
        ActionKind::Detour => Some(Turn::Detour),
        _ => None,
    }
}

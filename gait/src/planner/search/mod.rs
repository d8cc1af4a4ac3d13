//! The one search: A* over grasps and the rotation still to do (SPEC §4,
//! "The search").
//!
//! A node is a grasp — two fingers (the third waits above the object) or
//! three — with the rotation still to do ([`super::goal::Remaining`]). Its
//! children are the actions of [`super::alternatives`]: turns of the
//! object by the grasping fingers, gaits (placements, lifts,
//! substitutions), detours about other axes and the hand's regrasps on the
//! still object. Costs are execution times under the motion limits; nodes
//! are expanded cheapest first by g + w·h, h an optimistic time to go, ties
//! in the order the children were made: deterministic.
//!
//! Costly actions — a turn checked against the load at every sample, a
//! roll apart — are *deferred*: queued with their cost (or a lower bound)
//! and evaluated only when they come up, so only promising ones cost.
//!
//! The search asks the hand everything through
//! [`super::hand_model::HandModel`] and knows contacts only as unit normals.
//! The first goal node whose plan builds and passes the exact check
//! (SPEC §1.3 at every sample) is the answer; a plan the check refuses is
//! counted and the search goes on.

mod expand;
mod fresh;
mod node;
mod placing;
pub mod walk;

use std::collections::{BinaryHeap, HashSet};
use std::hash::BuildHasherDefault;

use nalgebra::Vector3;

use super::alternatives::{GREEDIER, Pass, Role};
use super::budget::{Budget, Effort, Halt};
use super::goal::Remaining;
use super::hand_model::{self, Action, HandModel};
use super::plan::Step;
use crate::hand_state::HandState;
use fresh::Fresh;
use node::{Edge, Key, KeyHasher, Last, NONE, Node, Open};

pub use expand::{others, split};
pub use node::Deferred;

/// The search's parameters (configuration and [`super::alternatives`]).
#[derive(Debug, Clone)]
pub struct Params {
    /// Best placements kept per substitution side.
    pub branching: usize,
    /// Axes a root may first turn about.
    pub detour_axes: Vec<Vector3<f64>>,
    /// Axes a node where no gait can follow may turn about.
    pub escape_axes: Vec<Vector3<f64>>,
}

/// A pair that can turn this far about some probe axis is not cramped
/// \[rad\] (30°).
const ROOMY: f64 = std::f64::consts::PI / 6.0;

/// What a cramped end costs the next plan: about a relocation of both
/// grasping fingers \[s\].
const CRAMPED_COST: f64 = 3.0;

/// The axes a plan's end grasp is probed about: the 12 vertices of an
/// icosahedron (both senses of 6 directions, 63° apart).
fn probe_axes() -> [Vector3<f64>; 12] {
    crate::grasp::hold::icosahedron().map(|v| v.normalize())
}

/// How one pass searches.
#[derive(Debug, Clone, Copy)]
pub struct Mode {
    /// Weight of the time-to-go estimate.
    pub weight: f64,
    /// Only plans quicker than this count \[s\]; nodes that cannot lead to
    /// one (g + h ≥ it) are dropped.
    pub bound: f64,
    /// Most expansions of this pass.
    pub cap: u32,
    /// Whether a first turn may be about another axis (a detour). Off for
    /// the later pieces of a long turn: they go on about its axis (and
    /// escape only where no gait can follow).
    pub detours: bool,
    /// Whether the plan must end with two fingers grasping: for a piece of
    /// a turn that goes on after it. Three fingers turned as far as they
    /// can may leave no roll to a pair for the next piece.
    pub ends_in_pair: bool,
    /// Whether walks offer their end's turn at once ([`Pass::eager_walks`]).
    pub eager_walks: bool,
}

impl Mode {
    /// How `pass` searches, given the duration of the plan in hand (if
    /// any) and the expansions spent so far: a Find pass while no plan is
    /// in hand, an Improve pass (bounded by that plan, capped at a multiple
    /// of the effort) once one is; `None` when the pass does not run.
    pub fn for_pass(
        pass: &Pass,
        found: Option<f64>,
        used: u32,
        detours: bool,
        ends_in_pair: bool,
    ) -> Option<Self> {
        let (bound, cap) = match (pass.role, found) {
            (Role::Find, None) => (f64::INFINITY, u32::MAX),
            (Role::Improve { effort, at_least }, Some(duration)) => {
                (duration, (effort * used.max(1)).max(at_least))
            }
            _ => return None,
        };
        Some(Self {
            weight: pass.weight,
            bound,
            cap,
            detours,
            ends_in_pair,
            eager_walks: pass.eager_walks,
        })
    }
}

/// A plan the search found.
#[derive(Debug, Clone)]
pub struct Found<H: HandModel> {
    /// Its actions, in order.
    pub actions: Vec<Action<H>>,
    /// The built steps (checked).
    pub steps: Vec<Step>,
    /// Their execution time \[s\].
    pub duration: f64,
}

/// How a search ended without a plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NotFound {
    /// Every reachable node was expanded (no plan at this resolution);
    /// `blocked`: some plan was dropped because this finger could not
    /// move clear of the others; `refused`: some because the exact load
    /// check failed.
    Exhausted {
        /// A finger that blocked a plan, if any.
        blocked: Option<usize>,
        /// Whether a plan failed the exact load check.
        refused: bool,
        /// Whether any two-finger grasp was reached.
        pairs: bool,
    },
    /// Stopped by the budget or the caller.
    Halted(Halt),
    /// The pass used up its own cap.
    Capped,
}

/// Runs one search from `start` for the rotation `rem`.
pub fn run<H: HandModel>(
    hand: &H,
    params: &Params,
    mode: Mode,
    start: &HandState,
    rem: Remaining,
    budget: &mut Budget<'_>,
    effort: &mut Effort,
) -> Result<Found<H>, NotFound> {
    let mut s = Search {
        hand,
        params,
        weight: mode.weight,
        mode,
        spent: 0,
        start: *start,
        nodes: Vec::with_capacity(4096),
        actions: Vec::with_capacity(4096),
        open: BinaryHeap::new(),
        closed: HashSet::default(),
        fresh: Vec::new(),
        seq: 0,
        effort,
        blocked: None,
        refused: false,
        pairs: false,
        holds_memo: Default::default(),
        walk_memo: Default::default(),
    };
    s.root(rem);
    s.run(budget)
}

/// One search's state.
struct Search<'a, 'e, H: HandModel> {
    hand: &'a H,
    params: &'a Params,
    mode: Mode,
    /// The estimate's weight now (it grows, [`GREEDIER`]).
    weight: f64,
    /// Expansions of this pass.
    spent: u32,
    start: HandState,
    nodes: Vec<Node>,
    actions: Vec<Action<H>>,
    open: BinaryHeap<Open>,
    closed: HashSet<Key, BuildHasherDefault<KeyHasher>>,
    /// Fresh-placement tables by axis (the goal's first).
    fresh: Vec<Fresh<H::Touch>>,
    seq: u32,
    effort: &'e mut Effort,
    blocked: Option<usize>,
    refused: bool,
    pairs: bool,
    /// Pair hold ranges asked so far (by the exact bits of the question).
    holds_memo: std::cell::RefCell<
        std::collections::HashMap<[u64; 12], f64, BuildHasherDefault<KeyHasher>>,
    >,
    /// Load verdicts of the walks so far, by the contacts tested.
    walk_memo: std::cell::RefCell<std::collections::HashMap<Vec<u64>, bool>>,
}

impl<H: HandModel> Search<'_, '_, H> {
    fn root(&mut self, rem: Remaining) {
        self.fresh.push(Fresh::new(self.hand, &rem.axis, true));
        let node = Node {
            hand: self.start,
            rem,
            g: 0.0,
            prev_turn: 0.0,
            parent: NONE,
            edge: Edge::Root,
            last: Last::Root,
            range: 0.0,
            unturned: true,
            h: 0.0,
        };
        self.push(node);
    }

    fn run(&mut self, budget: &mut Budget<'_>) -> Result<Found<H>, NotFound> {
        while let Some(Open { idx, .. }) = self.open.pop() {
            let node = self.nodes[idx as usize];
            if let Edge::Deferred(d) = node.edge {
                self.take(budget)?;
                self.effort.evaluated += 1;
                self.evaluate(idx, d, budget);
                continue;
            }
            if node.rem.reached() {
                if self.mode.ends_in_pair && node.hand.grasping().1 != 2 {
                    continue;
                }
                if let Some(found) = self.finish(idx) {
                    return Ok(found);
                }
                continue;
            }
            if !self.closed.insert(node::key(self.hand, &node)) {
                continue;
            }
            self.take(budget)?;
            self.effort.expansions += 1;
            self.expand(idx);
        }
        Err(NotFound::Exhausted {
            blocked: self.blocked,
            refused: self.refused,
            pairs: self.pairs,
        })
    }

    /// Queues `node` (its range about the remaining axis filled in, on the
    /// fingers' own limits: the load's limit is asked only when the node
    /// is expanded).
    fn push(&mut self, mut node: Node) {
        if !matches!(node.edge, Edge::Deferred(_)) {
            node.range = self.range(&node.hand, &node.rem);
            self.pairs |= node.hand.grasping().1 == 2;
        }
        let h = self.heuristic(&node);
        if node.g + h >= self.mode.bound {
            return;
        }
        node.h = h;
        let f = node.g + self.weight * h;
        self.nodes.push(node);
        self.open.push(Open {
            f,
            seq: self.seq,
            idx: (self.nodes.len() - 1) as u32,
        });
        self.seq += 1;
        self.effort.generated += 1;
    }

    /// One expansion from the budget and from this pass's cap; past each
    /// step of [`GREEDIER`] the search turns greedier.
    fn take(&mut self, budget: &mut Budget<'_>) -> Result<(), NotFound> {
        if self.spent >= self.mode.cap {
            return Err(NotFound::Capped);
        }
        budget.take().map_err(NotFound::Halted)?;
        self.spent += 1;
        if let Some(&(_, w)) = GREEDIER.iter().find(|(after, _)| *after == self.spent)
            && w > self.weight
        {
            self.reweigh(w);
        }
        Ok(())
    }

    /// The open list keyed again with the estimate's weight `w`.
    fn reweigh(&mut self, w: f64) {
        self.weight = w;
        let open = std::mem::take(&mut self.open).into_vec();
        self.open = open
            .into_iter()
            .map(|o| {
                let n = &self.nodes[o.idx as usize];
                Open {
                    f: n.g + w * n.h,
                    ..o
                }
            })
            .collect();
    }

    /// Stores an action, returning its index.
    fn act(&mut self, a: Action<H>) -> u32 {
        self.actions.push(a);
        (self.actions.len() - 1) as u32
    }

    /// The fresh table about `axis`, built on first use.
    fn fresh_index(&mut self, axis: &Vector3<f64>) -> usize {
        if let Some(i) = self.fresh.iter().position(|f| f.axis == *axis) {
            return i;
        }
        self.fresh.push(Fresh::new(self.hand, axis, false));
        self.fresh.len() - 1
    }

    /// Optimistic time to go: the rest of the rotation in one move, plus a
    /// substitution per further segment the best fresh range implies.
    fn heuristic(&self, node: &Node) -> f64 {
        let rem = node.rem.angle;
        if node.rem.reached() {
            return self.cramped(node);
        }
        let t = self.hand.timing();
        let mut h = t.rotate(rem);
        // Three fingers turn only so far: unless they reach the goal, one
        // lifts first, after rolling its pair apart if it is not one yet.
        if node.hand.grasping().1 == 3 && node.range < rem {
            let open = (0..3)
                .map(|lift| {
                    self.hand
                        .regrasp_bound(&node.hand, hand_model::RegraspFor::OpenPair { lift })
                })
                .fold(f64::INFINITY, f64::min);
            h += open + t.vertical + t.handover;
        }
        if node.range < rem {
            // A table for this axis if one was built, else the goal's (the
            // detours' axes are near it in the cases that matter).
            let best = self
                .fresh
                .iter()
                .find(|f| f.axis == node.rem.axis)
                .unwrap_or(&self.fresh[0])
                .best;
            let segments = ((rem - node.range) / best.max(1e-3)).ceil();
            h += segments * (2.0 * t.vertical + t.handover);
        }
        h
    }

    /// A goal node's cost to the goal after this one: the grasp a plan
    /// leaves is where the next plan starts, and a pair pinned at its
    /// limits (it can turn less than [`ROOMY`] about every axis of
    /// [`probe_axes`]) may leave it no way on. Such an end counts as a
    /// relocation more ([`CRAMPED_COST`]): a plan that ends roomier wins
    /// unless it is longer by more than that.
    fn cramped(&self, node: &Node) -> f64 {
        let (idx, n) = node.hand.grasping();
        if n != 2 {
            return 0.0;
        }
        let pair = [idx[0], idx[1]];
        let (a, b) = (
            node.hand.fingers[pair[0]].contact_normal(),
            node.hand.fingers[pair[1]].contact_normal(),
        );
        let roomy = probe_axes().iter().any(|e| {
            let r = self
                .hand
                .carry_range(&node.hand, &pair, e, ROOMY)
                .min(ROOMY);
            r >= ROOMY
                && self
                    .hand
                    .pair_hold_range((pair[0], &a), (pair[1], &b), e, r)
                    >= ROOMY
        });
        if roomy { 0.0 } else { CRAMPED_COST }
    }

    /// Evaluates a deferred node: a checked turn becomes a node, a regrasp
    /// request becomes one child per offer.
    fn evaluate(&mut self, idx: u32, d: Deferred, budget: &mut Budget<'_>) {
        let node = self.nodes[idx as usize];
        match d {
            Deferred::Turn { axis, angle, why } => {
                if !self.hand.holds_along(&node.hand, &axis, angle) {
                    return;
                }
                let mut hand = node.hand;
                self.hand.carry(&mut hand, &axis, angle);
                let first = self.act(Action::Rotate { axis, angle, why });
                self.push(Node {
                    hand,
                    edge: Edge::Actions {
                        first,
                        second: None,
                    },
                    ..node
                });
            }
            Deferred::Place {
                finger,
                cand,
                fresh,
            } => {
                let contact = self.hand.candidates(finger)[cand as usize];
                let touch = self.fresh[fresh as usize].touch[finger][cand as usize];
                let mut hand = node.hand;
                self.hand.place(&mut hand, finger, &contact, touch);
                if !self.hand.holds_at_rest(&hand) {
                    return;
                }
                let first = self.act(Action::Place {
                    finger,
                    contact,
                    touch,
                });
                self.push(Node {
                    hand,
                    prev_turn: 0.0,
                    edge: Edge::Actions {
                        first,
                        second: None,
                    },
                    ..node
                });
            }
            Deferred::Walk => {
                let parent = self.nodes[node.parent as usize];
                let fi = self.fresh_index(&parent.rem.axis);
                let axis = parent.rem.axis;
                let walk = self.walk(&parent.hand, &axis, parent.rem.angle, fi, budget.stop);
                if let Some(walk) = walk {
                    self.walk_children(node.parent, &parent, &walk);
                }
            }
            Deferred::Regrasp(why) => {
                let parent = self.nodes[node.parent as usize];
                let offers = self.hand.regrasps(&parent.hand, why, budget.stop);
                for o in offers {
                    let first = self.act(Action::Regrasp {
                        regrasp: o.regrasp,
                        why,
                    });
                    self.push(Node {
                        hand: o.end,
                        rem: parent.rem,
                        g: parent.g + o.cost,
                        prev_turn: 0.0,
                        parent: node.parent,
                        edge: Edge::Actions {
                            first,
                            second: None,
                        },
                        last: Last::Regrasp,
                        range: 0.0,
                        unturned: parent.unturned,
                        h: 0.0,
                    });
                }
            }
        }
    }

    /// The actions from the root to `idx`, built and checked; `None` (the
    /// reason noted) if either fails.
    fn finish(&mut self, idx: u32) -> Option<Found<H>> {
        let mut ids = Vec::new();
        let mut i = idx;
        while i != NONE {
            let n = &self.nodes[i as usize];
            if let Edge::Actions { first, second } = n.edge {
                ids.extend(second);
                ids.push(first);
            }
            i = n.parent;
        }
        ids.reverse();
        let actions: Vec<Action<H>> = ids
            .iter()
            .map(|&a| self.actions[a as usize].clone())
            .collect();
        self.effort.built += 1;
        let steps = match self.hand.build(&self.start, &actions) {
            Ok(s) => s,
            Err(finger) => {
                self.blocked = Some(finger);
                self.effort.refused += 1;
                return None;
            }
        };
        if self.hand.check(&self.start, &steps).is_err() {
            self.refused = true;
            self.effort.refused += 1;
            return None;
        }
        let duration = steps.iter().map(|s| s.duration).sum();
        if duration >= self.mode.bound {
            return None;
        }
        Some(Found {
            actions,
            steps,
            duration,
        })
    }
}

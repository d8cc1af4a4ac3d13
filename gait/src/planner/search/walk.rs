//! Walks, on a hand whose pairs do not turn (finger chains): fingers lifted
//! and placed anew one at a time on the still object until the three
//! reach a grasp that turns further about the rotation's axis (SPEC §4,
//! "The search"; §14).
//!
//! Three fingers turn only as far as the least of their own ranges, and a
//! finger lifts only while the other two hold the load as a pair. A finger
//! stuck where no pair of the others holds can be freed only by moving
//! the others first, sometimes twice each (they take turns until the two
//! of them hold without it): single gaits ranked one at a time do not find
//! such sequences. A walk tries the sequences of moves shortest first (no
//! finger moved twice in a row), each move's placement among the
//! candidates with the longest own range about the axis, and keeps the
//! first that brings every finger's own range to the target (or the one
//! that raises the least of them most), each end's reach cut to how far
//! the three carry the object together (their gaps and limits along the
//! way, which their own ranges leave out). Every state on the way is what a
//! lift and a placement of the search would check: the pair left holds
//! the load at rest, the lifted finger's way out is clear, the new contact
//! is apart from the others, the three are force-closure and hold the load
//! at rest. Where the pass asks ([`Pass::eager_walks`]), a walk's end
//! offers its turns at once, each weighed by its own cost: the estimate
//! counts a segment as one gait, so an end five moves away would otherwise
//! wait behind every cheap alternative.

use std::collections::HashMap;

use nalgebra::Vector3;

use super::super::alternatives::MIN_TURN;
#[cfg(doc)]
use super::super::alternatives::Pass;
use super::super::budget::Stop;
use super::super::geometry::angle_between;
use super::super::hand_model::{Action, At, HandModel};
use super::Search;
use super::expand::others;
use super::node::{Edge, Last, Node};
use crate::hand_state::HandState;

/// Most moves in one walk: a finger stuck between two that do not hold as
/// a pair is freed after the two have moved twice each.
pub const WALK_DEPTH: usize = 5;

/// Placements tried per move, the longest own ranges first.
pub const WALK_BEAM: usize = 2;

/// Most load tests (a pair or a grasp at rest) and carry ranges (an end's
/// reach) one walk may spend: it bounds the walk's cost where no sequence
/// exists.
pub const WALK_TESTS: u32 = 400;

/// A walk ends when every finger's own range is the rotation left or this
/// share of the longest any placement of the slowest finger has (the
/// longest of all three at once is rare).
pub const ENOUGH: f64 = 0.9;

/// A walk found: its moves (finger, candidate index) and where it ends.
pub(super) struct Walk {
    /// Each move: the finger and its new candidate contact.
    pub moves: Vec<(usize, usize)>,
    /// The least of the fingers' own ranges at its end \[rad\].
    pub reach: f64,
}

/// One walk's search state.
struct Walker<'a, H: HandModel> {
    hand: &'a H,
    /// Per finger, per candidate: its own range about the axis.
    ranges: &'a [Vec<f64>; 3],
    /// Per finger, per candidate: how it touches down.
    touch: &'a [Vec<H::Touch>; 3],
    /// Per finger: candidate indices, the longest range first.
    order: [Vec<usize>; 3],
    target: f64,
    /// The rotation's axis.
    axis: Vector3<f64>,
    /// Load tests and carry ranges run (the memos' misses).
    tests: u32,
    /// The caller's clock and cancel flag.
    stop: &'a mut dyn Stop,
    /// Whether `stop` said stop.
    halted: bool,
    /// Load verdicts by the contacts tested (the search's: sequences
    /// share their first moves, and walks their candidates).
    memo: &'a mut HashMap<Vec<u64>, bool>,
    /// Verdicts of [`HandModel::can_lift`] in this walk.
    lift_memo: HashMap<(usize, [[u64; 3]; 3]), bool>,
    /// Carry ranges of the ends reached in this walk, by their tips.
    carries: HashMap<[[u64; 3]; 3], f64>,
    /// Verdicts of [`HandModel::apart`] in this walk.
    apart_memo: HashMap<(usize, usize, [u64; 3], [u64; 3]), bool>,
    moves: Vec<(usize, usize)>,
    best: Option<Walk>,
}

impl<H: HandModel> Search<'_, '_, H> {
    /// The walk from the three-finger grasp `hand` towards a grasp whose
    /// fingers can each follow the object `angle` about `axis` (as far as
    /// the fresh table `fi` allows), if one raises the least own range.
    /// `stop` is polled before every load test: a walk stopped returns
    /// none.
    pub(super) fn walk(
        &self,
        hand: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
        fi: usize,
        stop: &mut dyn Stop,
    ) -> Option<Walk> {
        let h = self.hand;
        let (ranges, touch) = (&self.fresh[fi].range, &self.fresh[fi].touch);
        let own: [f64; 3] =
            std::array::from_fn(|k| h.touch_for(k, &hand.fingers[k].contact_normal(), axis).1);
        let best_of = |k: usize| ranges[k].iter().copied().fold(0.0, f64::max);
        let target = angle.min(ENOUGH * best_of(0).min(best_of(1)).min(best_of(2)));
        let now = own.iter().copied().fold(f64::INFINITY, f64::min);
        if now >= target {
            return None;
        }
        let order = std::array::from_fn(|k| {
            let mut o: Vec<usize> = (0..ranges[k].len()).collect();
            o.sort_by(|&i, &j| ranges[k][j].total_cmp(&ranges[k][i]));
            o
        });
        let mut w = Walker {
            hand: h,
            ranges,
            touch,
            order,
            target,
            axis: *axis,
            tests: 0,
            stop,
            halted: false,
            memo: &mut self.walk_memo.borrow_mut(),
            apart_memo: HashMap::new(),
            carries: HashMap::new(),
            lift_memo: HashMap::new(),
            moves: Vec::with_capacity(WALK_DEPTH),
            best: None,
        };
        'lengths: for len in 1..=WALK_DEPTH {
            for seq in sequences(len) {
                w.step(hand, &seq[..len], own, true);
                if w.tests >= WALK_TESTS
                    || w.halted
                    || w.best.as_ref().is_some_and(|b| b.reach >= target)
                {
                    break 'lengths;
                }
            }
        }
        w.best.filter(|b| !w.halted && b.reach > now)
    }

    /// Appends the walk's moves from node `idx` (each a lift and a
    /// placement) and queues where it ends.
    pub(super) fn walk_children(&mut self, idx: u32, node: &Node, walk: &Walk) {
        let t = *self.hand.timing();
        let fi = self.fresh_index(&node.rem.axis);
        let (mut parent, mut at) = (idx, *node);
        for (n, &(f, i)) in walk.moves.iter().enumerate() {
            let mut hand = at.hand;
            self.hand.lift(&mut hand, f);
            let from = self.hand.hover_dir(&hand, f);
            let contact = self.hand.candidates(f)[i];
            let touch = self.fresh[fi].touch[f][i];
            self.hand.place(&mut hand, f, &contact, touch);
            let travel = t.transfer(angle_between(&from, &contact));
            let cost = travel + 2.0 * (t.vertical + t.handover);
            let lift = self.act(Action::Lift { finger: f });
            let place = self.act(Action::Place {
                finger: f,
                contact,
                touch,
            });
            let next = Node {
                hand,
                g: at.g + cost,
                prev_turn: 0.0,
                parent,
                edge: Edge::Actions {
                    first: lift,
                    second: Some(place),
                },
                last: Last::Place,
                range: 0.0,
                h: 0.0,
                ..at
            };
            if n + 1 == walk.moves.len() {
                let before = self.nodes.len();
                self.push(next);
                // Where the pass asks, the end offers its turns at once,
                // each weighed by its own cost rather than the estimate's.
                if self.mode.eager_walks && self.nodes.len() > before {
                    let end = self.nodes[before];
                    if end.range >= MIN_TURN {
                        self.triple_turns(before as u32, &end);
                    }
                }
            } else {
                // On the way: kept for the plan, never expanded.
                self.nodes.push(next);
                parent = (self.nodes.len() - 1) as u32;
            }
            at = next;
        }
    }
}

impl<H: HandModel> Walker<'_, H> {
    /// Moves `seq[0]` from `state` (whose fingers' own ranges are `own`),
    /// then the rest of `seq`; `untested`: whether the pair left when
    /// `seq[0]` lifts is still to be tested (a previous move tests it
    /// before placing).
    fn step(&mut self, state: &HandState, seq: &[usize], own: [f64; 3], untested: bool) {
        let Some((&f, rest)) = seq.split_first() else {
            let own_reach = own.iter().copied().fold(f64::INFINITY, f64::min);
            if self.best.as_ref().is_some_and(|b| own_reach <= b.reach) {
                return;
            }
            let h = self.hand;
            let (axis, target) = (self.axis, self.target);
            let reach = own_reach
                .min(self.carry(state, || h.carry_range(state, &[0, 1, 2], &axis, target)));
            if self.best.as_ref().is_none_or(|b| reach > b.reach) {
                self.best = Some(Walk {
                    moves: self.moves.clone(),
                    reach,
                });
            }
            return;
        };
        let h = self.hand;
        let c: [Vector3<f64>; 3] = std::array::from_fn(|k| state.fingers[k].contact_normal());
        let (g, k) = others(f);
        let mut lifted = *state;
        h.lift(&mut lifted, f);
        if untested && !(h.good_pair(&c[g], &c[k]) && self.pair_holds((g, &c[g]), (k, &c[k]))) {
            return;
        }
        if !self.can_lift(state, f) {
            return;
        }
        let mut taken = 0;
        for n in 0..self.order[f].len() {
            if taken == WALK_BEAM || self.tests >= WALK_TESTS || self.halted {
                return;
            }
            let i = self.order[f][n];
            // The walk's end is no further than this move's range: past
            // the best end so far, no later candidate can beat it.
            if self
                .best
                .as_ref()
                .is_some_and(|b| self.ranges[f][i] <= b.reach)
            {
                return;
            }
            let cand = h.candidates(f)[i];
            let mut t = c;
            t[f] = cand;
            // The cheap tests first: force closure, and the pair the next
            // finger leaves force-closure.
            let next_pair = rest.first().map(|&nf| others(nf));
            if !h.fc_triple(&t) || next_pair.is_some_and(|(p, q)| !h.good_pair(&t[p], &t[q])) {
                continue;
            }
            if !(self.apart((f, &cand), (g, &c[g])) && self.apart((f, &cand), (k, &c[k]))) {
                continue;
            }
            // The next finger must be able to lift: the two it leaves hold.
            if let Some((p, q)) = next_pair
                && !self.pair_holds((p, &t[p]), (q, &t[q]))
            {
                continue;
            }
            let mut placed = lifted;
            h.place(&mut placed, f, &cand, self.touch[f][i]);
            let key = t
                .iter()
                .flat_map(|v| v.iter().map(|x| x.to_bits()))
                .collect();
            if !self.test(key, || h.holds_at_rest(&placed)) {
                continue;
            }
            taken += 1;
            let mut next = own;
            next[f] = self.ranges[f][i];
            self.moves.push((f, i));
            self.step(&placed, rest, next, false);
            self.moves.pop();
            if self.best.as_ref().is_some_and(|b| b.reach >= self.target) {
                return;
            }
        }
    }

    /// [`HandModel::can_lift`], remembered (a state recurs as sequences
    /// share their first moves).
    fn can_lift(&mut self, state: &HandState, f: usize) -> bool {
        let key = (f, state.fingers.map(|x| bits(&x.center)));
        if let Some(&v) = self.lift_memo.get(&key) {
            return v;
        }
        let v = self.hand.can_lift(state, f);
        self.lift_memo.insert(key, v);
        v
    }

    /// [`HandModel::apart`], remembered (the contacts recur from sequence
    /// to sequence).
    fn apart(&mut self, a: At<'_>, b: At<'_>) -> bool {
        let key = (a.0, b.0, bits(a.1), bits(b.1));
        if let Some(&v) = self.apart_memo.get(&key) {
            return v;
        }
        let v = self.hand.apart(a, b);
        self.apart_memo.insert(key, v);
        v
    }

    /// How far the three of `state` carry the object about the axis
    /// together (the fingers' clearance and limits along the way, which
    /// their own ranges leave out): remembered, counted as a test.
    fn carry(&mut self, state: &HandState, f: impl FnOnce() -> f64) -> f64 {
        let key = state.fingers.map(|x| bits(&x.center));
        if let Some(&v) = self.carries.get(&key) {
            return v;
        }
        if self.stop.poll().is_some() {
            self.halted = true;
            return 0.0;
        }
        self.tests += 1;
        let v = f();
        self.carries.insert(key, v);
        v
    }

    /// Whether the pair at `a`, `b` holds the load at rest (the pair left
    /// when the third lifts).
    fn pair_holds(&mut self, a: At<'_>, b: At<'_>) -> bool {
        let key = [
            a.0 as u64,
            a.1.x.to_bits(),
            a.1.y.to_bits(),
            a.1.z.to_bits(),
        ]
        .into_iter()
        .chain([
            b.0 as u64,
            b.1.x.to_bits(),
            b.1.y.to_bits(),
            b.1.z.to_bits(),
        ])
        .collect();
        let h = self.hand;
        self.test(key, || h.pair_holds(a, b, None))
    }

    /// The verdict of the load test `f` on the contacts `key`: remembered,
    /// or run and counted.
    fn test(&mut self, key: Vec<u64>, f: impl FnOnce() -> bool) -> bool {
        if let Some(&v) = self.memo.get(&key) {
            return v;
        }
        if self.stop.poll().is_some() {
            // Not held: nothing more is built on it, and the walk ends.
            self.halted = true;
            return false;
        }
        self.tests += 1;
        let v = f();
        self.memo.insert(key, v);
        v
    }
}

/// The bits of a unit vector (a memo key).
fn bits(v: &Vector3<f64>) -> [u64; 3] {
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

/// The sequences of `len` fingers with no finger twice in a row, in order.
fn sequences(len: usize) -> impl Iterator<Item = [usize; WALK_DEPTH]> {
    let count = 3usize * (1 << (len - 1));
    (0..count).map(move |n| {
        let mut s = [0usize; WALK_DEPTH];
        s[0] = n / (1 << (len - 1));
        for d in 1..len {
            // Bit d−1 (from the top) picks the lesser or greater of the
            // two fingers other than the last.
            let bit = (n >> (len - 1 - d)) & 1;
            let (a, b) = others(s[d - 1]);
            s[d] = if bit == 0 { a } else { b };
        }
        s
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequences_never_repeat_a_finger_and_cover_every_walk() {
        for len in 1..=WALK_DEPTH {
            let all: Vec<_> = sequences(len).map(|s| s[..len].to_vec()).collect();
            assert_eq!(all.len(), 3 * (1 << (len - 1)));
            let mut seen = std::collections::HashSet::new();
            for s in &all {
                assert!(s.windows(2).all(|w| w[0] != w[1]), "{s:?}");
                assert!(seen.insert(s.clone()), "{s:?} twice");
            }
        }
    }
}

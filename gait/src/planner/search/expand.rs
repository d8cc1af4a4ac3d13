//! A node's children, kind by kind, in the order of
//! [`super::super::alternatives`] (where a free finger goes down:
//! [`super::placing`]).

use nalgebra::Vector3;

use super::super::alternatives::{
    ActionKind, ESCAPE_STEP, MAX_ESCAPE, MAX_TILT, MIN_DETOUR, MIN_PAIR_TURN, MIN_TURN,
    PAIR_ACTIONS, PAIR_TURN_FRACTIONS, STILL_PAIR_ACTIONS, TILT_FRACTIONS, TRIPLE_ACTIONS,
    TRIPLE_ESCAPE_AXES, TRIPLE_ESCAPE_FRACTIONS, TRIPLE_TURN_FRACTIONS,
};
use super::super::goal::Remaining;
use super::super::hand_model::{Action, At, HandModel, RegraspFor, Turn};
use super::Search;
use super::node::{Deferred, Edge, Last, NONE, Node};
use crate::hand_state::HandState;
use crate::planner::fibonacci_sphere;

/// Step by which a pair's turn is shortened until a gait can follow it.
const THEORY1_BACKOFF: f64 = 0.035;

/// Escape turns kept per node (the least turns first).
const ESCAPES_KEPT: usize = 8;

/// The grasping pair and the free finger, if exactly two fingers grasp.
pub fn split(hand: &HandState) -> Option<([usize; 2], usize)> {
    let (idx, n) = hand.grasping();
    if n != 2 {
        return None;
    }
    let free = (0..3).find(|k| !idx[..2].contains(k))?;
    Some(([idx[0], idx[1]], free))
}

impl<H: HandModel> Search<'_, '_, H> {
    /// How far the grasping fingers of `hand` can turn about the remaining
    /// axis: a pair within its limits and holding the load (only as far as
    /// it is worth knowing), three within their limits (their load is
    /// checked when a turn comes up).
    pub(super) fn range(&self, hand: &HandState, rem: &Remaining) -> f64 {
        let (idx, n) = hand.grasping();
        let r = self
            .hand
            .carry_range(hand, &idx[..n], &rem.axis, rem.angle.max(MIN_PAIR_TURN));
        if n != 2 {
            return r;
        }
        let limit = r.min(rem.angle.max(MIN_PAIR_TURN));
        self.pair_hold(hand, [idx[0], idx[1]], &rem.axis, limit, r)
    }

    /// [`HandModel::pair_hold_range`], remembered for the search (the kept
    /// finger of a substitution is asked about again with every candidate
    /// at the next node).
    pub(super) fn hold_range(&self, a: At<'_>, b: At<'_>, axis: &Vector3<f64>, limit: f64) -> f64 {
        let ((fa, a), (fb, b)) = (a, b);
        let key = [
            fa as f64, a.x, a.y, a.z, fb as f64, b.x, b.y, b.z, axis.x, axis.y, axis.z, limit,
        ]
        .map(f64::to_bits);
        if let Some(&r) = self.holds_memo.borrow().get(&key) {
            return r;
        }
        let r = self.hand.pair_hold_range((fa, a), (fb, b), axis, limit);
        self.holds_memo.borrow_mut().insert(key, r);
        r
    }

    /// `range` cut where the pair of `hand` stops holding the load about
    /// `axis` (asked up to `limit`).
    fn pair_hold(
        &self,
        hand: &HandState,
        pair: [usize; 2],
        axis: &Vector3<f64>,
        limit: f64,
        range: f64,
    ) -> f64 {
        let (a, b) = contacts(hand, pair);
        let held = self.hold_range((pair[0], &a), (pair[1], &b), axis, limit);
        if held < limit { held } else { range }
    }

    /// Appends the children of node `idx`.
    pub(super) fn expand(&mut self, idx: u32) {
        let node = self.nodes[idx as usize];
        match node.hand.grasping().1 {
            2 => self.expand_pair(idx, &node),
            3 => self.expand_triple(idx, &node),
            _ => {}
        }
    }

    fn expand_pair(&mut self, idx: u32, node: &Node) {
        let Some((pair, z)) = split(&node.hand) else {
            return;
        };
        let before = self.nodes.len();
        let mut goal = false;
        let mut gaits = 0;
        let actions: &[ActionKind] = if self.hand.pairs_turn() {
            &PAIR_ACTIONS
        } else {
            &STILL_PAIR_ACTIONS
        };
        for &kind in actions {
            match kind {
                ActionKind::Toward if node.last != Last::Turn(Turn::Toward) => {
                    goal = self.pair_turns(idx, node, pair, z);
                }
                ActionKind::Twist
                    if self.hand.load_active() && !matches!(node.last, Last::Turn(_)) =>
                {
                    self.twist(idx, node, pair);
                }
                ActionKind::Substitute => {
                    let n = self.nodes.len();
                    self.substitutions(idx, node, pair, z);
                    gaits = self.nodes.len() - n;
                }
                ActionKind::Place if !goal && gaits == 0 => {
                    self.places(idx, node, pair, z);
                }
                ActionKind::Detour => {
                    if node.unturned && self.mode.detours {
                        self.detours(idx, node, pair, z);
                    }
                    if !goal && gaits == 0 {
                        self.escapes(idx, node, pair, z);
                    }
                }
                ActionKind::Regrasp
                    if self.hand.offers_regrasps()
                        && (self.nodes.len() == before || node.parent == NONE) =>
                {
                    self.defer(idx, node, Deferred::Regrasp(RegraspFor::Unstick), 0.0);
                }
                _ => {}
            }
        }
    }

    fn expand_triple(&mut self, idx: u32, node: &Node) {
        let mut lifted = [false; 3];
        // The finger just placed does not lift again at once.
        let placed = match (node.last, node.edge) {
            (Last::Place, Edge::Actions { first, .. }) => match self.actions[first as usize] {
                Action::Place { finger, .. } => Some(finger),
                _ => None,
            },
            _ => None,
        };
        for kind in TRIPLE_ACTIONS {
            match kind {
                ActionKind::Lift => lifted = self.lifts(idx, node, placed),
                ActionKind::Toward
                    if matches!(node.last, Last::Root | Last::Regrasp | Last::Place) =>
                {
                    self.triple_turns(idx, node);
                }
                ActionKind::Tilt if node.last == Last::Root && self.hand.load_active() => {
                    self.tilts(idx, node);
                }
                ActionKind::Tilt if self.hand.load_active() => {
                    if let Some(z) = placed {
                        self.pair_tilts(idx, node, z);
                    }
                }
                ActionKind::Detour
                    if !self.hand.pairs_turn()
                        && self.hand.load_active()
                        && lifted == [false; 3]
                        && node.last == Last::Root =>
                {
                    self.triple_escapes(idx, node);
                }
                ActionKind::Walk
                    if !self.hand.pairs_turn()
                        && node.range < node.rem.angle
                        && (node.last == Last::Root
                            || matches!(node.last, Last::Turn(_)) && node.range < MIN_TURN) =>
                {
                    // At least one finger lifted and placed anew.
                    let t = self.hand.timing();
                    let bound = 2.0 * (t.vertical + t.handover);
                    self.defer(idx, node, Deferred::Walk, bound);
                }
                ActionKind::Regrasp
                    if self.hand.offers_regrasps()
                        && matches!(
                            node.last,
                            Last::Root | Last::Turn(Turn::Tilt) | Last::Place
                        ) =>
                {
                    for lift in (0..3).filter(|&k| !lifted[k]) {
                        let why = RegraspFor::OpenPair { lift };
                        let bound = self.hand.regrasp_bound(&node.hand, why);
                        self.defer(idx, node, Deferred::Regrasp(why), bound);
                    }
                    if node.parent == NONE {
                        let unstick = Deferred::Regrasp(RegraspFor::Unstick);
                        self.defer(idx, node, unstick, 0.0);
                    }
                }
                _ => {}
            }
        }
    }

    /// A child of `parent` reached by `actions` (one or two).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn child(
        &mut self,
        parent: u32,
        from: &Node,
        hand: HandState,
        rem: Remaining,
        cost: f64,
        prev_turn: f64,
        last: Last,
        actions: (Action<H>, Option<Action<H>>),
    ) {
        let first = self.act(actions.0);
        let second = actions.1.map(|a| self.act(a));
        self.push(Node {
            hand,
            rem,
            g: from.g + cost,
            prev_turn,
            parent,
            edge: Edge::Actions { first, second },
            last,
            range: 0.0,
            unturned: from.unturned && !matches!(last, Last::Turn(_)),
            h: 0.0,
        });
    }

    /// A deferred child: evaluated when it comes up ([`Deferred`]);
    /// `cost` is its cost, or a lower bound of it.
    pub(super) fn defer(&mut self, parent: u32, from: &Node, d: Deferred, cost: f64) {
        let (rem, last) = match d {
            Deferred::Turn { axis, angle, why } => (from.rem.after(&axis, angle), Last::Turn(why)),
            Deferred::Regrasp(_) => (from.rem, Last::Regrasp),
            Deferred::Place { .. } | Deferred::Walk => (from.rem, Last::Place),
        };
        self.push(Node {
            hand: from.hand,
            rem,
            g: from.g + cost,
            prev_turn: cost,
            parent,
            edge: Edge::Deferred(d),
            last,
            range: from.range,
            unturned: from.unturned && !matches!(d, Deferred::Turn { .. }),
            h: 0.0,
        });
    }

    /// A turn by the grasping fingers as a child (`check`: its load is
    /// checked when it comes up).
    fn turn(
        &mut self,
        parent: u32,
        node: &Node,
        axis: Vector3<f64>,
        t: f64,
        why: Turn,
        check: bool,
    ) {
        let time = self.hand.timing().rotate(t);
        if check && self.hand.load_active() {
            let d = Deferred::Turn {
                axis,
                angle: t,
                why,
            };
            self.defer(parent, node, d, time);
            return;
        }
        let mut hand = node.hand;
        self.hand.carry(&mut hand, &axis, t);
        let rem = node.rem.after(&axis, t);
        let a = Action::Rotate {
            axis,
            angle: t,
            why,
        };
        self.child(
            parent,
            node,
            hand,
            rem,
            time,
            time,
            Last::Turn(why),
            (a, None),
        );
    }

    /// The pair's turns towards the goal; whether one reaches it.
    fn pair_turns(&mut self, idx: u32, node: &Node, pair: [usize; 2], z: usize) -> bool {
        let rem = node.rem.angle;
        let full = node.range.min(rem);
        let axis = node.rem.axis;
        if full >= rem - 1e-12 {
            self.turn(idx, node, axis, rem, Turn::Toward, false);
            return true;
        }
        for f in PAIR_TURN_FRACTIONS {
            if let Some(t) = self.viable(node, pair, z, f * full) {
                self.turn(idx, node, axis, t, Turn::Toward, false);
            }
        }
        false
    }

    /// The largest turn ≤ `t` after which a gait is still possible (paper
    /// Theory 1), if any is worth a segment.
    fn viable(&self, node: &Node, pair: [usize; 2], z: usize, t: f64) -> Option<f64> {
        let ok = |s: f64| {
            let mut h = node.hand;
            self.hand.carry(&mut h, &node.rem.axis, s);
            self.theory1(&h, pair, z)
        };
        if ok(t) {
            return Some(t);
        }
        // Coarse steps back to the first turn that keeps a gait possible,
        // then bisection down to the backoff step.
        let coarse = 5.0 * THEORY1_BACKOFF;
        let mut bad = t;
        let mut good = None;
        let mut s = t - coarse;
        while s >= MIN_PAIR_TURN {
            if ok(s) {
                good = Some(s);
                break;
            }
            bad = s;
            s -= coarse;
        }
        let mut good = match good {
            Some(g) => g,
            None if MIN_PAIR_TURN < bad && ok(MIN_PAIR_TURN) => MIN_PAIR_TURN,
            None => return None,
        };
        while bad - good > THEORY1_BACKOFF {
            let mid = 0.5 * (good + bad);
            if ok(mid) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        Some(good)
    }

    /// Paper Theory 1: some placement of the free finger `z` makes, with
    /// one of the grasping pair, a pair that holds (and is clear of both).
    pub(super) fn theory1(&self, hand: &HandState, pair: [usize; 2], z: usize) -> bool {
        let (ca, cb) = contacts(hand, pair);
        let h = self.hand;
        let cand = h.candidates(z);
        // (The hand's resting partners may be tabulated: this only steers
        // the search, the gaits it makes are checked where they are.)
        let mut found = false;
        for (x, cx) in [(pair[0], &ca), (pair[1], &cb)] {
            h.resting_partners(x, cx, z, &mut |i, _| {
                let c = &cand[i];
                found = h.apart((z, c), (pair[0], &ca))
                    && h.apart((z, c), (pair[1], &cb))
                    && h.good_pair(c, cx);
                !found
            });
            if found {
                return true;
            }
        }
        false
    }

    /// The remaining rotation's twist about the weight's direction, as far
    /// as the pair can turn about it.
    fn twist(&mut self, idx: u32, node: &Node, pair: [usize; 2]) {
        let up = -self.hand.weight_direction();
        let (sin, cos) = (0.5 * node.rem.angle).sin_cos();
        let along = up.dot(&node.rem.axis) * sin;
        // The twist's quaternion is (cos, along·up), normalised.
        let (axis, angle) = if along >= 0.0 {
            (up, 2.0 * along.atan2(cos))
        } else {
            (-up, 2.0 * (-along).atan2(cos))
        };
        if angle < MIN_DETOUR {
            return;
        }
        let r = self.hand.carry_range(&node.hand, &pair, &axis, angle);
        let t = self
            .pair_hold(&node.hand, pair, &axis, r.min(angle), r)
            .min(angle);
        if t >= MIN_DETOUR {
            self.turn(idx, node, axis, t, Turn::Detour, false);
        }
    }

    /// After a placement: for each force-closure pair of the finger just
    /// placed with another, the least tilt of the three about the pair's
    /// chord (either way, in steps) after which that pair holds the load.
    fn pair_tilts(&mut self, idx: u32, node: &Node, placed: usize) {
        let cz = node.hand.fingers[placed].contact_normal();
        for x in (0..3).filter(|&k| k != placed) {
            let cx = node.hand.fingers[x].contact_normal();
            if !self.hand.good_pair(&cz, &cx) {
                continue;
            }
            let chord = (cz - cx).normalize();
            for axis in [chord, -chord] {
                let range = self
                    .hand
                    .carry_range(&node.hand, &[0, 1, 2], &axis, MAX_TILT)
                    .min(MAX_TILT);
                let mut t = ESCAPE_STEP;
                while t <= range {
                    // Where the pair's contacts are after the tilt: turned
                    // with the object, or rolled (a chain's).
                    let (az, ax) = if self.hand.pairs_turn() {
                        let q = super::super::geometry::rotation(&axis, t);
                        (q * cz, q * cx)
                    } else {
                        let mut h = node.hand;
                        self.hand.carry(&mut h, &axis, t);
                        (
                            h.fingers[placed].contact_normal(),
                            h.fingers[x].contact_normal(),
                        )
                    };
                    if self.hand.pair_holds((placed, &az), (x, &ax), None) {
                        self.turn(idx, node, axis, t, Turn::Tilt, true);
                        break;
                    }
                    t += ESCAPE_STEP;
                }
            }
        }
    }

    /// From a root: a first turn about each detour axis, as far as the
    /// pair can and half as far, when a gait can follow it.
    fn detours(&mut self, idx: u32, node: &Node, pair: [usize; 2], z: usize) {
        let axes = self.params.detour_axes.clone();
        for e in &axes {
            let r = self
                .hand
                .carry_range(&node.hand, &pair, e, std::f64::consts::PI);
            let limit = r.min(std::f64::consts::PI);
            let range = self.pair_hold(&node.hand, pair, e, limit, limit);
            for t in [range, 0.5 * range] {
                if t < MIN_DETOUR {
                    continue;
                }
                let mut h = node.hand;
                self.hand.carry(&mut h, e, t);
                if self.theory1(&h, pair, z) {
                    self.turn(idx, node, *e, t, Turn::Detour, false);
                }
            }
        }
    }

    /// From a node where no gait can follow: the least turn about each
    /// escape axis (in steps) after which one can; the least few.
    fn escapes(&mut self, idx: u32, node: &Node, pair: [usize; 2], z: usize) {
        let mut found: Vec<(Vector3<f64>, f64)> = Vec::new();
        for e in &self.params.escape_axes {
            let r = self
                .hand
                .carry_range(&node.hand, &pair, e, MAX_ESCAPE)
                .min(MAX_ESCAPE);
            let range = self.pair_hold(&node.hand, pair, e, r, r);
            let mut t = ESCAPE_STEP;
            while t <= range {
                let mut h = node.hand;
                self.hand.carry(&mut h, e, t);
                if self.theory1(&h, pair, z) {
                    found.push((*e, t));
                    break;
                }
                t += ESCAPE_STEP;
            }
        }
        found.sort_by(|a, b| a.1.total_cmp(&b.1));
        for (e, t) in found.into_iter().take(ESCAPES_KEPT) {
            self.turn(idx, node, e, t, Turn::Detour, false);
        }
    }

    /// Lifts from three fingers: a finger may lift when the other two are
    /// a pair that holds (turning about the remaining axis next, or at
    /// least at rest). Returns which fingers could.
    fn lifts(&mut self, idx: u32, node: &Node, placed: Option<usize>) -> [bool; 3] {
        let mut lifted = [false; 3];
        let t = *self.hand.timing();
        for lose in (0..3).filter(|&k| Some(k) != placed) {
            let (i, j) = others(lose);
            let (ci, cj) = contacts(&node.hand, [i, j]);
            if !self.hand.good_pair(&ci, &cj) {
                continue;
            }
            if !self.hand.can_lift(&node.hand, lose) {
                continue;
            }
            let mut hand = node.hand;
            self.hand.lift(&mut hand, lose);
            if !(self
                .hand
                .pair_holds((i, &ci), (j, &cj), Some(&node.rem.axis))
                || self.hand.holds_at_rest(&hand))
            {
                continue;
            }
            lifted[lose] = true;
            let a = Action::Lift { finger: lose };
            let cost = t.vertical + t.handover;
            self.child(idx, node, hand, node.rem, cost, 0.0, Last::Gait, (a, None));
        }
        lifted
    }

    /// Three fingers' turns towards the goal.
    pub(super) fn triple_turns(&mut self, idx: u32, node: &Node) {
        let rem = node.rem.angle;
        let axis = node.rem.axis;
        let range = node.range.min(rem);
        if range >= rem - 1e-12 {
            self.turn(idx, node, axis, rem, Turn::Toward, true);
            return;
        }
        for f in TRIPLE_TURN_FRACTIONS {
            let t = f * range;
            if t >= MIN_TURN {
                self.turn(idx, node, axis, t, Turn::Toward, true);
            }
        }
    }

    /// Three fingers none of which can lift turn the object about other
    /// axes ([`ActionKind::Detour`] on a hand whose pairs do not turn).
    fn triple_escapes(&mut self, idx: u32, node: &Node) {
        for axis in fibonacci_sphere(TRIPLE_ESCAPE_AXES) {
            let range = self
                .hand
                .carry_range(&node.hand, &[0, 1, 2], &axis, MAX_TILT)
                .min(MAX_TILT);
            for f in TRIPLE_ESCAPE_FRACTIONS {
                let t = f * range;
                if t >= MIN_TURN {
                    self.turn(idx, node, axis, t, Turn::Detour, true);
                }
            }
        }
    }

    /// Tilts about each pair's chord, both ways.
    fn tilts(&mut self, idx: u32, node: &Node) {
        let c = node.hand.fingers.map(|f| f.contact_normal());
        for (i, j) in [(0, 1), (1, 2), (0, 2)] {
            let Some(chord) = (c[j] - c[i]).try_normalize(1e-9) else {
                continue;
            };
            for axis in [chord, -chord] {
                let range = self
                    .hand
                    .carry_range(&node.hand, &[0, 1, 2], &axis, MAX_TILT)
                    .min(MAX_TILT);
                for f in TILT_FRACTIONS {
                    let t = f * range;
                    if t >= MIN_TURN {
                        self.turn(idx, node, axis, t, Turn::Tilt, true);
                    }
                }
            }
        }
    }
}

/// The contact normals of two fingers.
pub(super) fn contacts(hand: &HandState, pair: [usize; 2]) -> (Vector3<f64>, Vector3<f64>) {
    (
        hand.fingers[pair[0]].contact_normal(),
        hand.fingers[pair[1]].contact_normal(),
    )
}

/// The two fingers other than `k`.
pub fn others(k: usize) -> (usize, usize) {
    match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

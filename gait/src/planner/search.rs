//! A* over gaits and rotation segments (PLANNER-NOTES "The search that
//! worked", generalised).
//!
//! The object turns about one fixed axis k by the angle Φ still to do. A node
//! is a two-finger force-closure grasp with the third finger hovering, plus
//! the rotation about k done so far. Edges are
//! - a substitution (paper §2.1): place the free finger force-closure with
//!   one grasping finger, lift the other (two gaits). Chains of them make the
//!   paper's finger rewind and the relocation patterns of PLANNER-NOTES
//!   (move one finger, fresh pair, full rewind);
//! - a rotation about k as far as the pair allows (or to the goal), or half
//!   as far (stopping early can keep later gaits possible).
//!
//! Cost is execution time; nodes are expanded cheapest-first with an
//! optimistic time-to-go. Ties break by insertion order: deterministic.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

use nalgebra::Vector3;

use super::candidates::Candidates;
use super::geometry::{
    BOUNDARY_EPS, Geometry, angle_between, cone_exit, fresh_range, roll_exit, rotation,
};
use super::load::PairLoad;
use super::timing::DurationModel;
use crate::state::{FingerMode, HandState};

/// Rotations shorter than this are not worth a segment.
const MIN_SEGMENT: f64 = 1e-3;

/// Step by which a segment is shortened until its end state allows a gait.
const THEORY1_BACKOFF: f64 = 0.035;

/// Most children kept per substitution side (`planner.branching` ≤ this).
pub const MAX_BRANCHING: usize = 16;

/// Seconds of travel one radian of usable rotation range is worth when
/// ranking placements (a longer segment saves later gaits).
const RANGE_WEIGHT: f64 = 2.0;

/// A cheap deterministic hasher for the closed set's integer keys
/// (multiply–rotate; SipHash's DoS resistance buys nothing here).
#[derive(Default)]
struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x517c_c1b7_2722_0a95);
    }
    fn write_i64(&mut self, v: i64) {
        self.write_u64(v as u64);
    }
}

/// One gait (SPEC §4.2): a Place or a Lift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gait {
    /// A free finger touches down at `contact` with roll preset `roll`.
    Place {
        /// Finger index.
        finger: usize,
        /// Unit contact normal (hand frame).
        contact: Vector3<f64>,
        /// Roll τ at touchdown.
        roll: f64,
    },
    /// A grasping finger leaves the object.
    Lift {
        /// Finger index.
        finger: usize,
    },
}

/// Gaits then a rotation about the search axis.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Segment {
    /// The gaits, in order.
    pub gaits: Vec<Gait>,
    /// Rotation about the search axis after the gaits \[rad\] (0 for none).
    pub rotate: f64,
}

/// Read-only inputs of one search.
pub struct Problem<'a> {
    /// Model constants.
    pub geom: &'a Geometry,
    /// Durations.
    pub timing: &'a DurationModel,
    /// Contact candidates.
    pub cand: &'a Candidates,
    /// The load test (SPEC §1.3 I1'): every pair the search makes holds
    /// the load, and rotations end before a pair would stop holding it.
    pub load: &'a PairLoad,
    /// Unit rotation axis k.
    pub axis: Vector3<f64>,
    /// Angle Φ to rotate about k.
    pub total: f64,
    /// Children kept per substitution side.
    pub branching: usize,
    /// Expansion budget.
    pub max_expansions: usize,
    /// Weight of the time-to-go estimate (1 = A*; more is greedier).
    pub heuristic_weight: f64,
}

/// A starting point of the search: a pair grasps, one finger is free.
#[derive(Debug, Clone, Copy)]
pub struct Root {
    /// Hand state (object orientation irrelevant here).
    pub hand: HandState,
    /// Cost already spent reaching it \[s\].
    pub cost: f64,
    /// Caller's tag, returned with the result.
    pub tag: usize,
}

/// The search's answer.
#[derive(Debug, Clone)]
pub struct Found {
    /// Tag of the root it started from.
    pub tag: usize,
    /// Segments in order (the last may have no rotation only if Φ = 0).
    pub segments: Vec<Segment>,
    /// Estimated execution time including the root's cost \[s\].
    pub cost: f64,
    /// Nodes expanded.
    pub expansions: usize,
}

/// The edge that led to a node.
#[derive(Debug, Clone, Copy)]
enum Edge {
    Root,
    /// Place `finger` at candidate `cand`, then lift `lift`.
    Substitute {
        finger: usize,
        contact: Vector3<f64>,
        roll: f64,
        lift: usize,
    },
    Rotate(f64),
}

#[derive(Debug, Clone, Copy)]
struct Node {
    hand: HandState,
    pair: [usize; 2],
    free: usize,
    done: f64,
    g: f64,
    /// Duration of the rotation edge that led here (0 otherwise): the free
    /// finger can travel meanwhile.
    prev_rotation: f64,
    parent: usize,
    edge: Edge,
    root: usize,
    /// How far the pair can rotate about the axis (computed once, when the
    /// node is queued).
    range: f64,
}

#[derive(PartialEq)]
struct Open {
    f: f64,
    seq: usize,
    idx: usize,
}
impl Eq for Open {}
impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        // Min-heap on f, then FIFO on insertion order: deterministic.
        other
            .f
            .total_cmp(&self.f)
            .then_with(|| other.seq.cmp(&self.seq))
    }
}
impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Precomputed per-search candidate data: fresh range and roll preset.
struct Fresh {
    range: [Vec<f64>; 3],
    preset: [Vec<f64>; 3],
    best: f64,
}

impl<'a> Problem<'a> {
    fn fresh(&self) -> Fresh {
        let mut best: f64 = 0.0;
        let mut range: [Vec<f64>; 3] = Default::default();
        let mut preset: [Vec<f64>; 3] = Default::default();
        for k in 0..3 {
            for c in &self.cand.points[k] {
                let (tau, r) = fresh_range(self.geom, k, &self.axis, c);
                let r = (r - BOUNDARY_EPS).max(0.0);
                best = best.max(r);
                range[k].push(r);
                preset[k].push(tau);
            }
        }
        // The longest segment any force-closure pair of fresh placements
        // allows: a tighter bound for the time-to-go than the best single
        // contact.
        let mut best_pair: f64 = 0.0;
        for a in 0..3 {
            for b in a + 1..3 {
                for (i, partners) in self.cand.partners[a][b].iter().enumerate() {
                    let ra = range[a][i];
                    if ra <= best_pair {
                        continue;
                    }
                    let rb = partners
                        .iter()
                        .map(|&j| range[b][j as usize])
                        .fold(0.0, f64::max);
                    best_pair = best_pair.max(ra.min(rb));
                }
            }
        }
        let best = if best_pair > 0.0 { best_pair } else { best };
        Fresh {
            range,
            preset,
            best,
        }
    }

    /// How far the grasping pair of `hand` can rotate about the axis: in
    /// its cones, within its roll limits, holding the load.
    pub fn pair_range(&self, hand: &HandState, pair: [usize; 2]) -> f64 {
        let range = grasp_range(self.geom, hand, &pair, &self.axis);
        let (ca, cb) = (
            hand.fingers[pair[0]].contact_normal(),
            hand.fingers[pair[1]].contact_normal(),
        );
        // Only as far as it is worth going: the rest of a turn at most.
        let limit = range.min(self.total.max(MIN_SEGMENT));
        let held = self.load.exit(&ca, &cb, &self.axis, limit);
        if held < limit { held } else { range }
    }

    /// Paper Theory 1: some placement of the free finger is force-closure
    /// with one of the grasping fingers (and clear of both).
    pub fn theory1(&self, hand: &HandState, pair: [usize; 2], free: usize) -> bool {
        super::escape::theory1(
            self.geom,
            self.cand,
            self.load,
            None,
            free,
            &hand.fingers[pair[0]].contact_normal(),
            &hand.fingers[pair[1]].contact_normal(),
        )
    }

    /// Optimistic time to go: the rest of the rotation in one move, plus a
    /// substitution (two vertical moves) per further segment the best fresh
    /// range implies.
    fn heuristic(&self, fresh: &Fresh, rem: f64, range_now: f64) -> f64 {
        if rem <= 0.0 {
            return 0.0;
        }
        let mut h = self.timing.rotate(rem);
        if range_now < rem {
            let segments = ((rem - range_now) / fresh.best.max(1e-3)).ceil();
            h += segments * (2.0 * self.timing.vertical + self.timing.handover);
        }
        h
    }

    /// Runs A* from the roots; `None` if no plan is found within budget.
    pub fn solve(&self, roots: &[Root]) -> Option<Found> {
        let fresh = self.fresh();
        let mut nodes: Vec<Node> = Vec::with_capacity(4096);
        let mut open = BinaryHeap::new();
        let mut closed: HashSet<[i64; 13], BuildHasherDefault<KeyHasher>> = HashSet::default();
        let mut seq = 0;
        let mut push = |nodes: &mut Vec<Node>, open: &mut BinaryHeap<Open>, mut node: Node| {
            let range = self.pair_range(&node.hand, node.pair);
            node.range = range;
            let f = node.g
                + self.heuristic_weight * self.heuristic(&fresh, self.total - node.done, range);
            nodes.push(node);
            open.push(Open {
                f,
                seq,
                idx: nodes.len() - 1,
            });
            seq += 1;
        };
        for (ri, root) in roots.iter().enumerate() {
            let Some((pair, free)) = split(&root.hand) else {
                continue;
            };
            let node = Node {
                hand: root.hand,
                pair,
                free,
                done: 0.0,
                g: root.cost,
                prev_rotation: 0.0,
                parent: usize::MAX,
                edge: Edge::Root,
                root: ri,
                range: 0.0,
            };
            push(&mut nodes, &mut open, node);
        }
        let mut expansions = 0;
        let mut children = Vec::with_capacity(64);
        while let Some(Open { idx, .. }) = open.pop() {
            let node = nodes[idx];
            if node.done >= self.total - 1e-12 {
                return Some(self.trace(&nodes, idx, roots, expansions));
            }
            if !closed.insert(self.key(&node)) {
                continue;
            }
            expansions += 1;
            if expansions > self.max_expansions {
                return None;
            }
            children.clear();
            self.expand(&node, idx, &fresh, &mut children);
            for child in children.drain(..) {
                push(&mut nodes, &mut open, child);
            }
        }
        None
    }

    fn trace(&self, nodes: &[Node], mut idx: usize, roots: &[Root], expansions: usize) -> Found {
        let cost = nodes[idx].g;
        let mut edges = Vec::new();
        while nodes[idx].parent != usize::MAX {
            edges.push(nodes[idx].edge);
            idx = nodes[idx].parent;
        }
        edges.reverse();
        let mut segments = Vec::new();
        let mut cur = Segment::default();
        for e in edges {
            match e {
                Edge::Substitute {
                    finger,
                    contact,
                    roll,
                    lift,
                } => {
                    cur.gaits.push(place(finger, contact, roll));
                    cur.gaits.push(Gait::Lift { finger: lift });
                }
                Edge::Rotate(t) => {
                    cur.rotate = t;
                    segments.push(std::mem::take(&mut cur));
                }
                Edge::Root => {}
            }
        }
        if !cur.gaits.is_empty() {
            segments.push(cur);
        }
        Found {
            tag: roots[nodes[idx].root].tag,
            segments,
            cost,
            expansions,
        }
    }

    /// Quantised identity of a node for the closed set.
    fn key(&self, n: &Node) -> [i64; 13] {
        let q = |x: f64, s: f64| (x * s).round() as i64;
        let (a, b) = (n.pair[0].min(n.pair[1]), n.pair[0].max(n.pair[1]));
        let ca = n.hand.fingers[a].contact_normal();
        let cb = n.hand.fingers[b].contact_normal();
        [
            (a * 3 + b) as i64,
            matches!(n.edge, Edge::Rotate(_)) as i64,
            q(n.done, 30.0),
            q(ca.x, 15.0),
            q(ca.y, 15.0),
            q(ca.z, 15.0),
            q(cb.x, 15.0),
            q(cb.y, 15.0),
            q(cb.z, 15.0),
            q(n.hand.fingers[a].roll, 50.0),
            q(n.hand.fingers[b].roll, 50.0),
            q(n.hand.fingers[a].pole_axis().dot(&self.axis), 50.0),
            q(n.hand.fingers[b].pole_axis().dot(&self.axis), 50.0),
        ]
    }

    /// Appends the children of `node`.
    fn expand(&self, node: &Node, idx: usize, fresh: &Fresh, out: &mut Vec<Node>) {
        let rem = self.total - node.done;
        if !matches!(node.edge, Edge::Rotate(_)) {
            self.rotate_children(node, idx, out);
        }
        let z = node.free;
        let z_from = hover_dir(&node.hand, z);
        for keep_i in 0..2 {
            let keep = node.pair[keep_i];
            let lose = node.pair[1 - keep_i];
            let c_keep = node.hand.fingers[keep].contact_normal();
            let c_lose = node.hand.fingers[lose].contact_normal();
            let chosen = self.placements(fresh, rem, z, lose, &c_keep, &c_lose, &z_from);
            for &i in chosen.iter().flatten() {
                let contact = self.cand.points[z][i];
                let roll = fresh.preset[z][i];
                self.substitute_child(node, idx, z, contact, roll, lose, out);
            }
        }
    }

    /// The placements of the free finger `z` (force-closure with `c_keep`,
    /// clear of both contacts) to expand, in one pass without allocating:
    /// the best `branching` by score (rotation allowed, then travel) among
    /// those after which `lose` (then free) could come back force-closure
    /// with the new contact and so replace `keep` next; the best overall;
    /// and the quickest to reach (a good temporary holder).
    #[allow(clippy::too_many_arguments)]
    fn placements(
        &self,
        fresh: &Fresh,
        rem: f64,
        z: usize,
        lose: usize,
        c_keep: &Vector3<f64>,
        c_lose: &Vector3<f64>,
        from: &Vector3<f64>,
    ) -> [Option<usize>; MAX_BRANCHING + 2] {
        let sep = self.geom.cos_sep_contact - BOUNDARY_EPS;
        let k = self.branching.min(MAX_BRANCHING);
        let flexible = |i: usize| {
            self.cand.partners[z][lose][i]
                .iter()
                .any(|&j| self.cand.points[lose][j as usize].dot(c_keep) <= sep)
        };
        let mut top = [(f64::INFINITY, usize::MAX); MAX_BRANCHING];
        let mut n_top = 0;
        let mut best = (f64::INFINITY, usize::MAX);
        let mut quick = (f64::NEG_INFINITY, usize::MAX);
        for (i, c) in self.cand.points[z].iter().enumerate() {
            if !(self.geom.is_good_pair(c, c_keep) && c.dot(c_keep) <= sep && c.dot(c_lose) <= sep)
            {
                continue;
            }
            // The new pair must hold the load at rest (SPEC §1.3 I1'); its
            // rotation range then ends where it stops holding it.
            if !self.load.holds(c_keep, c, None) {
                continue;
            }
            let d = from.dot(c);
            // Rotation beyond what is left is worth nothing.
            let mut range = fresh.range[z][i].min(rem);
            let travel = self.timing.transfer_cos(d);
            // The load may end the rotation first; worth knowing only for
            // a candidate that could make the lists.
            let could = -range * RANGE_WEIGHT + travel < best.0
                || n_top < k
                || -range * RANGE_WEIGHT + travel < top[n_top - 1].0;
            if could && self.load.active() {
                range = self.load.exit(c_keep, c, &self.axis, range);
            }
            let score = -range * RANGE_WEIGHT + travel;
            if score < best.0 {
                best = (score, i);
            }
            if d > quick.0 {
                quick = (d, i);
            }
            if (n_top < k || score < top[n_top - 1].0) && flexible(i) {
                let pos = top[..n_top].partition_point(|(s, _)| *s <= score);
                let end = (n_top + 1).min(k);
                top.copy_within(pos..end - 1, pos + 1);
                top[pos] = (score, i);
                n_top = end;
            }
        }
        let mut out = [None; MAX_BRANCHING + 2];
        for (o, t) in out.iter_mut().zip(&top[..n_top]) {
            *o = Some(t.1);
        }
        let mut n = n_top;
        for extra in [best.1, quick.1] {
            if extra != usize::MAX && !out[..n].contains(&Some(extra)) {
                out[n] = Some(extra);
                n += 1;
            }
        }
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn substitute_child(
        &self,
        node: &Node,
        idx: usize,
        finger: usize,
        contact: Vector3<f64>,
        roll: f64,
        lift: usize,
        out: &mut Vec<Node>,
    ) {
        let mut hand = node.hand;
        let from = hover_dir(&hand, finger);
        // Travelled during the previous rotation, if there was one.
        let travel =
            (self.timing.transfer(angle_between(&from, &contact)) - node.prev_rotation).max(0.0);
        place_finger_pose(self.geom, &mut hand, finger, &contact, roll);
        lift_finger(self.geom, &mut hand, lift);
        let Some((pair, free)) = split(&hand) else {
            return;
        };
        out.push(Node {
            hand,
            pair,
            free,
            done: node.done,
            g: node.g + travel + 2.0 * self.timing.vertical + self.timing.handover,
            prev_rotation: 0.0,
            parent: idx,
            edge: Edge::Substitute {
                finger,
                contact,
                roll,
                lift,
            },
            root: node.root,
            range: 0.0,
        });
    }

    /// Rotation children: as far as the pair allows (or to the goal), and
    /// half as far.
    fn rotate_children(&self, node: &Node, idx: usize, out: &mut Vec<Node>) {
        let rem = self.total - node.done;
        let full = node.range.min(rem);
        if full >= rem - 1e-12 {
            self.rotate_child(node, idx, rem, out);
            return;
        }
        for t in [full, 0.5 * full] {
            if let Some(t) = self.viable(node, t) {
                self.rotate_child(node, idx, t, out);
            }
        }
    }

    /// The largest rotation ≤ `t` after which a gait is still possible
    /// (paper Theory 1), if any is worth a segment.
    fn viable(&self, node: &Node, t: f64) -> Option<f64> {
        let ok = |s: f64| {
            let mut h = node.hand;
            rotate_hand(&mut h, &self.axis, s);
            self.theory1(&h, node.pair, node.free)
        };
        if ok(t) {
            return Some(t);
        }
        // Coarse steps back to the first rotation that keeps a gait
        // possible, then refine to the backoff step by bisection.
        let coarse = 5.0 * THEORY1_BACKOFF;
        let mut bad = t;
        let mut good = None;
        let mut s = t - coarse;
        while s >= MIN_SEGMENT {
            if ok(s) {
                good = Some(s);
                break;
            }
            bad = s;
            s -= coarse;
        }
        let mut good = match good {
            Some(g) => g,
            None if MIN_SEGMENT < bad && ok(MIN_SEGMENT) => MIN_SEGMENT,
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

    fn rotate_child(&self, node: &Node, idx: usize, t: f64, out: &mut Vec<Node>) {
        let rem = self.total - node.done;
        let t = if rem - t < 1e-12 { rem } else { t };
        let mut hand = node.hand;
        rotate_hand(&mut hand, &self.axis, t);
        let time = self.timing.rotate(t);
        out.push(Node {
            hand,
            pair: node.pair,
            free: node.free,
            done: node.done + t,
            g: node.g + time,
            prev_rotation: time,
            parent: idx,
            edge: Edge::Rotate(t),
            root: node.root,
            range: 0.0,
        });
    }
}

fn place(finger: usize, contact: Vector3<f64>, roll: f64) -> Gait {
    Gait::Place {
        finger,
        contact,
        roll,
    }
}

/// The grasping pair and the free finger, if exactly two fingers grasp.
pub fn split(hand: &HandState) -> Option<([usize; 2], usize)> {
    let (idx, n) = hand.grasping();
    if n != 2 {
        return None;
    }
    let free = (0..3).find(|k| !idx[..2].contains(k))?;
    Some(([idx[0], idx[1]], free))
}

/// Direction of a finger's centre from O.
pub fn hover_dir(hand: &HandState, finger: usize) -> Vector3<f64> {
    hand.fingers[finger].center.normalize()
}

/// Puts a free finger down at `contact` with its pole, swinging and
/// twisting its orientation (SPEC §1.1: swing leaves τ alone, the twist
/// about the pole changes τ to `roll`).
pub fn place_finger(
    g: &Geometry,
    hand: &mut HandState,
    finger: usize,
    contact: &Vector3<f64>,
    roll: f64,
) {
    let f = &mut hand.fingers[finger];
    let pole = -contact;
    let turn = super::plan::Reorientation::towards(&f.orientation, &pole, roll - f.roll);
    f.orientation = turn.at(&f.orientation, 1.0);
    f.center = contact * g.contact_radius;
    f.roll = roll;
    f.mode = FingerMode::Grasping;
}

/// What the search needs of a placement: contact, pole axis −c and roll.
/// The fingertip orientation about its pole is whichever is cheapest (the
/// plan builder makes the real one with [`place_finger`]); this takes the
/// minimal rotation e_z → −c from its half-way quaternion, without trig.
pub fn place_finger_pose(
    g: &Geometry,
    hand: &mut HandState,
    finger: usize,
    contact: &Vector3<f64>,
    roll: f64,
) {
    let f = &mut hand.fingers[finger];
    let pole = -contact;
    // q = (1 + e_z·p, e_z × p) normalised rotates e_z onto p (p ≠ −e_z).
    let w = 1.0 + pole.z;
    f.orientation = if w > 1e-9 {
        nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(w, -pole.y, pole.x, 0.0))
    } else {
        rotation(&Vector3::x(), std::f64::consts::PI)
    };
    f.center = contact * g.contact_radius;
    f.roll = roll;
    f.mode = FingerMode::Grasping;
}

/// Lifts a grasping finger straight up to the transfer height.
pub fn lift_finger(g: &Geometry, hand: &mut HandState, finger: usize) {
    let f = &mut hand.fingers[finger];
    f.center = f.center.normalize() * g.transfer_radius;
    f.mode = FingerMode::Free;
}

/// How far the grasping `fingers` of `hand` can carry the object about
/// `axis`: each contact in its cone, each roll within its limit (less
/// [`BOUNDARY_EPS`]).
pub fn grasp_range(g: &Geometry, hand: &HandState, fingers: &[usize], axis: &Vector3<f64>) -> f64 {
    let mut range = f64::INFINITY;
    for &k in fingers {
        let f = &hand.fingers[k];
        range = range
            .min(cone_exit(g, k, axis, &f.contact_normal()))
            .min(roll_exit(g, axis, &f.pole_axis(), f.roll));
    }
    (range - BOUNDARY_EPS).max(0.0)
}

/// Rotates the object and every grasping finger about `axis` by `angle`.
pub fn rotate_hand(hand: &mut HandState, axis: &Vector3<f64>, angle: f64) {
    let q = rotation(axis, angle);
    hand.object = q * hand.object;
    for f in hand.fingers.iter_mut() {
        if f.mode == FingerMode::Grasping {
            let pole = f.pole_axis();
            f.roll += angle * axis.dot(&pole);
            f.center = q * f.center;
            f.orientation = q * f.orientation;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_placement_points_the_pole_at_the_object() {
        let cfg = crate::HandConfig::default();
        let g = Geometry::new(&cfg);
        let mut hand = HandState::paper_start(&cfg);
        for i in 0..200 {
            let a = i as f64 * 0.1;
            let c = Vector3::new(
                a.cos() * (a * 0.3).sin(),
                a.sin() * (a * 0.3).sin(),
                (a * 0.3).cos(),
            );
            place_finger_pose(&g, &mut hand, 0, &c, 0.1);
            let f = hand.fingers[0];
            assert!((f.pole_axis() + c).norm() < 1e-12, "{c:?}");
            assert!((f.fingertip_contact() - Vector3::z()).norm() < 1e-12);
        }
    }
}

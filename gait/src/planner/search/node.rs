//! Search nodes, the edges between them and the closed set's key.

use std::cmp::Ordering;
use std::hash::Hasher;

use nalgebra::Vector3;

use super::super::goal::Remaining;
use super::super::hand_model::{HandModel, RegraspFor, Turn};
use crate::hand_state::HandState;

/// Index of no node (a root's parent).
pub const NONE: u32 = u32::MAX;

/// What kind of edge led to a node (some actions are not repeated back to
/// back: a turn after a turn about the same axis is one turn).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Last {
    /// A root.
    Root,
    /// A turn by the grasping fingers, and why.
    Turn(Turn),
    /// A finger placed (three grasp now).
    Place,
    /// A finger lifted, or a substitution (placed, then another lifted).
    Gait,
    /// A regrasp on the still object.
    Regrasp,
}

/// An action the search has chosen but not yet paid to check: it is
/// evaluated when its node comes up, so only the promising ones cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Deferred {
    /// A turn whose load must be checked at every sample.
    Turn {
        /// Unit axis.
        axis: Vector3<f64>,
        /// Angle \[rad\].
        angle: f64,
        /// Why.
        why: Turn,
    },
    /// The hand's regrasps for this purpose (each offer a child).
    Regrasp(RegraspFor),
    /// A walk of the fingers on the still object ([`super::walk`]).
    Walk,
    /// A free finger placed; the three must hold the load at rest.
    Place {
        /// Finger.
        finger: usize,
        /// Its candidate contact (index).
        cand: u32,
        /// The fresh table its touch comes from (index).
        fresh: u32,
    },
}

/// How a node was reached from its parent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Edge {
    /// A root.
    Root,
    /// One or two actions (indices into the search's action arena).
    Actions {
        /// First action.
        first: u32,
        /// Second action, if any (a substitution: place, then lift).
        second: Option<u32>,
    },
    /// Not evaluated yet: the node's state is its parent's.
    Deferred(Deferred),
}

/// One search node.
#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// The hand (the object's orientation is carried along for the plan).
    pub hand: HandState,
    /// The rotation still to do.
    pub rem: Remaining,
    /// Execution time so far \[s\].
    pub g: f64,
    /// Duration of the turn that led here (a free finger travels meanwhile).
    pub prev_turn: f64,
    /// Parent node.
    pub parent: u32,
    /// The edge from the parent.
    pub edge: Edge,
    /// Its kind.
    pub last: Last,
    /// How far the grasping fingers can turn about `rem.axis` (set when
    /// queued).
    pub range: f64,
    /// Whether the object has not turned yet on the way here (only gaits
    /// and regrasps): a first turn may still be a detour.
    pub unturned: bool,
    /// Its time-to-go estimate \[s\] (set when queued).
    pub h: f64,
}

/// An entry of the open list: cheapest f first, then first queued.
#[derive(PartialEq)]
pub struct Open {
    /// g + w·h \[s\].
    pub f: f64,
    /// Queue order (ties).
    pub seq: u32,
    /// Node index.
    pub idx: u32,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
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

/// The closed set's key: which fingers grasp, where, their hand-specific
/// state, the rotation left, and whether a turn led here — quantised, in
/// integers (deterministic hashing).
pub type Key = [i64; 21];

/// The key of `node` (contacts to ~4°, the rotation left to ~2°).
pub fn key<H: HandModel>(hand: &H, node: &Node) -> Key {
    let q = |x: f64, s: f64| (x * s).round() as i64;
    let mut k = [0i64; 21];
    let (idx, n) = node.hand.grasping();
    let mut mask = 0;
    for &f in &idx[..n] {
        mask |= 1 << f;
    }
    k[0] = mask;
    k[1] = matches!(node.last, Last::Turn(_)) as i64;
    k[2] = q(node.rem.angle, 30.0);
    k[3] = q(node.rem.axis.x, 15.0);
    k[4] = q(node.rem.axis.y, 15.0);
    k[5] = q(node.rem.axis.z, 15.0);
    for (slot, &f) in idx[..n].iter().enumerate() {
        let c = node.hand.fingers[f].contact_normal();
        let extra = hand.key(&node.hand, f, &node.rem.axis);
        let b = 6 + 5 * slot;
        k[b] = q(c.x, 15.0);
        k[b + 1] = q(c.y, 15.0);
        k[b + 2] = q(c.z, 15.0);
        k[b + 3] = extra[0];
        k[b + 4] = extra[1];
    }
    k
}

/// A cheap deterministic hasher for the closed set's integer keys
/// (multiply–rotate; SipHash's DoS resistance buys nothing here).
#[derive(Default)]
pub struct KeyHasher(u64);

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

//! The load test along the three fingers' turns, kept per start and axis.
//!
//! The search offers several turns from one grasp about one axis (fractions
//! of how far the three can carry the object), and asks each whether the
//! grasp holds the load all along it. Each sample costs a torque-box SOCP
//! (§14.1), and a longer turn passes through the shorter ones' states: so
//! what was learnt is kept — how far the load test passed (and the state
//! there), and where it failed — and a longer turn is tested on from there,
//! at the same spacing. A turn within what passed holds; one reaching a
//! failure does not.

use std::collections::HashMap;
use std::sync::Mutex;

use nalgebra::Vector3;

use super::ChainHand;
use super::steps::along_carry;
use crate::hand_state::HandState;

/// Most carries remembered (each about 400 bytes) before the memo is
/// emptied.
const ENTRIES: usize = 20_000;

/// A carry's start (object and tip centres) and axis, bit for bit.
type Key = [u64; 16];

/// What the load test found along one carry.
#[derive(Debug, Clone, Copy)]
struct Progress {
    /// Every sample up to this angle passed \[rad\].
    held_to: f64,
    /// The state there.
    at: HandState,
    /// A sample at this angle failed (+∞: none yet) \[rad\].
    fails_at: f64,
}

/// The memo of load tests along carries (module docs); clones of the
/// planner share it.
#[derive(Debug, Default)]
pub struct CarryLoads {
    found: Mutex<HashMap<Key, Progress>>,
}

fn key(state: &HandState, axis: &Vector3<f64>) -> Key {
    let o = state.object.quaternion();
    let mut k = [0u64; 16];
    let values = [o.w, o.i, o.j, o.k]
        .into_iter()
        .chain(
            state
                .fingers
                .iter()
                .flat_map(|f| [f.center.x, f.center.y, f.center.z]),
        )
        .chain([axis.x, axis.y, axis.z]);
    for (slot, v) in k.iter_mut().zip(values) {
        *slot = v.to_bits();
    }
    k
}

impl CarryLoads {
    /// Whether `holds` passes at samples at most `step` apart along the
    /// carry of `state`'s grasping fingers by `angle` about `axis` (the
    /// rolling law of [`along_carry`]), continuing what an earlier ask
    /// about the same start and axis found.
    pub fn holds_along(
        &self,
        hand: &ChainHand,
        state: &HandState,
        axis: &Vector3<f64>,
        angle: f64,
        step: f64,
        holds: &mut dyn FnMut(&HandState) -> bool,
    ) -> bool {
        let k = key(state, axis);
        let known = self.found.lock().ok().and_then(|m| m.get(&k).copied());
        let mut p = known.unwrap_or(Progress {
            held_to: 0.0,
            at: *state,
            fails_at: f64::INFINITY,
        });
        if angle <= p.held_to && known.is_some() {
            return true;
        }
        if angle >= p.fails_at {
            return false;
        }
        let rest = angle - p.held_to;
        let n = (rest / step).ceil().max(1.0) as usize;
        let piece = rest / n as f64;
        let mut i = 0;
        let (from, start) = (p.held_to, p.at);
        let ok = along_carry(hand, &start, axis, rest, n, &mut |s| {
            // The first sample is where the last ask left off, and passed.
            let first_known = i == 0 && known.is_some();
            let passed = first_known || holds(s);
            if passed {
                p.held_to = from + piece * i as f64;
                p.at = *s;
            } else {
                p.fails_at = p.fails_at.min(from + piece * i as f64);
            }
            i += 1;
            passed
        });
        if !ok && p.fails_at.is_infinite() {
            // The carry itself stopped (the rolling law failed): no
            // sample beyond here can pass.
            p.fails_at = from + piece * i as f64;
        }
        if let Ok(mut m) = self.found.lock() {
            if m.len() >= ENTRIES {
                m.clear();
            }
            m.insert(k, p);
        }
        ok
    }
}

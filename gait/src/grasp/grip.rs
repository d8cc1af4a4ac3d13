//! Grip forces for the grasping fingers, every tick (SPEC §3.3, §1.3 I1').
//!
//! The forces are the closed forms of [`crate::grasp::hold`] (checked
//! against the SOCP [`crate::grasp::forces::LoadSolver`] in
//! `gait/tests/grip_vs_socp.rs`): they balance the weight and the torque
//! I α that accelerates the object (α known each tick), with the least
//! squeeze that also holds every disturbance of the configured size; the
//! commanded normals are those of the weight, the *peak* the largest
//! normal force over all disturbances (I1': peak ≤ `load.max_grip`).
//!
//! Which fingers carry the load is the executor's *carrying set*: two
//! fingers are two soft contacts, three are three hard contacts (or, if
//! the three cannot, the best pair among them with the third at zero). A
//! grasping finger outside the set touches without force: a finger just
//! placed, before its grip ramps in, or one about to lift, after its grip
//! ramped out. A finger marked spinning in the set ([`spin_bit`]) pushes
//! along its normal only while the other two carry the rest
//! ([`HoldModel::spinning`]). During a handover (`load.handover_time`, the object still)
//! the forces pass from one set to the next as the convex combination
//! (1 − λ) f_from + λ f_to, λ a C² ramp from 0 to 1: every load scenario
//! stays held throughout, because each end holds it and the cones and the
//! equilibrium equations are convex; the peak of the mix is at most the
//! mix of the peaks. Nothing allocates.

use nalgebra::Vector3;

use crate::HandConfig;
use crate::grasp::hold::{Accel, Hold, HoldModel};
use crate::hand_state::{FingerMode, HandState};

/// Grip forces for one state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grip {
    /// Commanded normal force per finger (0 for fingers that carry
    /// nothing) \[N\].
    pub normal: [f64; 3],
    /// Full contact force on the object per finger, weight-only load \[N\].
    pub force: [Vector3<f64>; 3],
    /// Torsional moment about the inward normal per finger [N·m].
    pub torsion: [f64; 3],
    /// Largest normal force over the load scenarios (F*, an upper bound;
    /// +∞ when no grip holds the load) \[N\].
    pub peak: f64,
    /// Whether the carrying fingers hold the load within `load.max_grip`
    /// (SPEC §1.3 I1').
    pub feasible: bool,
    /// Whether the squeeze had to be lowered to keep the commanded normals
    /// within `load.max_grip` (the grasp cannot hold the load).
    pub capped: bool,
}

impl Default for Grip {
    fn default() -> Self {
        Self {
            normal: [0.0; 3],
            force: [Vector3::zeros(); 3],
            torsion: [0.0; 3],
            peak: f64::INFINITY,
            feasible: false,
            capped: false,
        }
    }
}

/// The carrying bits of a carrying set (fingers 0–2).
pub const CARRY_BITS: u8 = 0b111;

/// The bit of a carrying set that marks finger `k` as spinning on the
/// object: it pushes along its normal only ([`HoldModel::spinning`]).
pub const fn spin_bit(k: usize) -> u8 {
    1 << (3 + k)
}

/// What a grip depends on (the key of the executor's grip memo): the
/// fingertip centres, which fingers grasp, the torque and the carrying
/// set — not the fingertips' orientations or rolls, so a fingertip
/// spinning in place keeps its grip from tick to tick.
pub type GripKey = ([Vector3<f64>; 3], u8, Vector3<f64>, u8);

/// The [`GripKey`] of `state` with `torque` and `carrying`.
pub fn grip_key(state: &HandState, torque: &Vector3<f64>, carrying: u8) -> GripKey {
    (
        state.fingers.map(|f| f.center),
        grasp_mask(state),
        *torque,
        carrying,
    )
}

/// Bit mask of the grasping fingers of `state`.
pub fn grasp_mask(state: &HandState) -> u8 {
    state
        .fingers
        .iter()
        .enumerate()
        .filter(|(_, f)| f.mode == FingerMode::Grasping)
        .fold(0, |m, (k, _)| m | (1 << k))
}

/// The C² ramp 6x⁵ − 15x⁴ + 10x³ of a handover, x clamped to [0, 1].
pub fn ramp(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (x * (6.0 * x - 15.0) + 10.0)
}

/// The grip model of one configuration.
#[derive(Debug, Clone, Copy)]
pub struct GripModel {
    hold: HoldModel,
}

impl GripModel {
    /// From a validated configuration.
    pub fn new(c: &HandConfig) -> Self {
        Self {
            hold: HoldModel::new(c),
        }
    }

    /// The closed-form hold model.
    pub fn hold(&self) -> &HoldModel {
        &self.hold
    }

    /// The same model with no commanded normal above `max_grip` where that
    /// is lower than `load.max_grip` ([`HoldModel::within`]).
    pub fn within(&self, max_grip: f64) -> Self {
        Self {
            hold: self.hold.within(max_grip),
        }
    }

    /// Grip forces when every grasping finger of `state` carries the load
    /// and the object must also be given the torque `torque` [N·m] (I α).
    pub fn grip(&self, state: &HandState, torque: &Vector3<f64>) -> Grip {
        self.carried(state, torque, grasp_mask(state))
    }

    /// Grip forces when the grasping fingers in the bit mask `carrying`
    /// carry the load (module docs).
    pub fn carried(&self, state: &HandState, torque: &Vector3<f64>, carrying: u8) -> Grip {
        self.carried_with(state, Accel::Known(*torque), carrying)
    }

    /// [`GripModel::carried`] for any acceleration model (the planner's
    /// bound ±α_max along a rotation axis).
    pub fn carried_with(&self, state: &HandState, accel: Accel, carrying: u8) -> Grip {
        let set = carrying & CARRY_BITS & grasp_mask(state);
        let spinning = (carrying >> 3) & set;
        if set == CARRY_BITS && spinning != 0 {
            // One finger spins, the other two carry (SPEC §1.3 I1').
            let n = state.fingers.map(|f| f.center.normalize());
            let k = spinning.trailing_zeros() as usize;
            let h = self.hold.spinning(&n, k, &self.hold.loads(accel));
            return self.spread(&h, &[0, 1, 2]);
        }
        let mut idx = [0usize; 3];
        let mut k = 0;
        for (i, slot) in (0..3).filter(|i| set & (1 << i) != 0).zip(0..) {
            idx[slot] = i;
            k += 1;
        }
        let n = |i: usize| state.fingers[i].center.normalize();
        let loads = self.hold.loads(accel);
        match k {
            2 => self.spread(&self.hold.pair(&[n(idx[0]), n(idx[1])], &loads), &idx[..2]),
            3 => {
                let t = self.hold.triple(&[n(0), n(1), n(2)], &loads);
                if t.feasible {
                    return self.spread(&t, &[0, 1, 2]);
                }
                // The best pair that holds on its own, the third at zero.
                let mut best = self.spread(&t, &[0, 1, 2]);
                for (a, b) in [(0, 1), (0, 2), (1, 2)] {
                    let p = self.hold.pair(&[n(a), n(b)], &loads);
                    if p.max_peak < best.peak || (p.feasible && !best.feasible) {
                        best = self.spread(&p, &[a, b]);
                    }
                }
                best
            }
            _ => Grip::default(),
        }
    }

    /// The three grasping fingers of `state` as hard contacts (no pair
    /// fallback: what rolling or spinning contacts can do).
    pub fn triple(&self, state: &HandState, accel: Accel) -> Grip {
        if grasp_mask(state) != 0b111 {
            return Grip::default();
        }
        let n = state.fingers.map(|f| f.center.normalize());
        self.spread(&self.hold.triple(&n, &self.hold.loads(accel)), &[0, 1, 2])
    }

    /// Forces during a handover from the grip `from` (of the set before)
    /// to the grip `to` (of the set after) at ramp value `lambda` ∈ [0, 1]
    /// (module docs).
    pub fn blend(from: &Grip, to: &Grip, lambda: f64) -> Grip {
        let l = lambda.clamp(0.0, 1.0);
        let mut g = Grip {
            normal: [0.0; 3],
            force: [Vector3::zeros(); 3],
            torsion: [0.0; 3],
            peak: 0.0,
            feasible: from.feasible && to.feasible,
            capped: from.capped || to.capped,
        };
        for i in 0..3 {
            // Never above either end, not even by rounding: a plant
            // refuses a grip over `load.max_grip`.
            let top = from.normal[i].max(to.normal[i]);
            g.normal[i] = ((1.0 - l) * from.normal[i] + l * to.normal[i]).min(top);
            g.force[i] = from.force[i] * (1.0 - l) + to.force[i] * l;
            g.torsion[i] = (1.0 - l) * from.torsion[i] + l * to.torsion[i];
        }
        // Peak of the mix ≤ mix of the peaks (per finger, both ends).
        g.peak = if from.peak.is_finite() && to.peak.is_finite() {
            (1.0 - l) * from.peak + l * to.peak
        } else {
            f64::INFINITY
        };
        g
    }

    fn spread(&self, h: &Hold, idx: &[usize]) -> Grip {
        let mut g = Grip {
            normal: [0.0; 3],
            force: [Vector3::zeros(); 3],
            torsion: [0.0; 3],
            peak: h.max_peak,
            feasible: h.feasible,
            capped: h.capped,
        };
        // No commanded normal above the fingertip's limit, not even by the
        // rounding of the cap (a plant refuses it).
        let limit = self.hold.max_grip();
        for (j, &i) in idx.iter().enumerate() {
            g.normal[i] = h.normal[j].min(limit);
            g.force[i] = h.force[j];
            g.torsion[i] = h.torsion[j];
        }
        g
    }
}

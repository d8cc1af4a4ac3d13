//! The grip forces of the setpoint (SPEC §1.3 I1', §6.1): the normal forces
//! the carrying fingers press with to hold the load at the object's
//! acceleration, blended across a handover, each computed once per
//! (state, torque, carrying set) — a held setpoint costs a lookup.

use super::memo::Memo;
use crate::grasp::FingerStatics;
use crate::grasp::grip::{self, Grip, GripKey, GripModel};
use crate::grasp::hold::Accel;
use crate::hand_state::HandState;
use nalgebra::Vector3;

/// A chain hand's motors where its grasping fingers are (SPEC §14.1
/// "Forces"): each grasping finger's statics at the joints it is
/// commanded. The grip a joint-level plant is sent is fed forward as
/// torques J_pᵀ F + g, F the whole contact force (the load's share and the
/// squeeze): the grip is chosen so that those stay within every motor's
/// effort.
#[derive(Debug, Clone, Copy)]
pub(super) struct Motors {
    /// Per finger (`None`: not grasping, or no joints reach its tip).
    pub(super) statics: [Option<FingerStatics>; 3],
}

/// Halvings of the grip's cap when its forces need more than the motors
/// give (the cap then within 1/64 of the strongest that fits).
const CAP_HALVINGS: usize = 6;

impl Motors {
    /// The strongest normal push every grasping finger's motors give
    /// ([`FingerStatics::push_limit`]) \[N\]; +∞ with none grasping.
    pub(super) fn push_cap(&self, state: &HandState) -> f64 {
        (0..3)
            .filter_map(|k| {
                let s = self.statics[k]?;
                Some(s.push_limit(&state.fingers[k].center.normalize()))
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether every grasping finger's motors give `g`'s force with the
    /// links' weight.
    fn fits(&self, g: &Grip) -> bool {
        (0..3).all(|k| self.statics[k].is_none_or(|s| s.share(&g.force[k]) <= 1.0))
    }

    /// The grip of `set` for a chain hand: with three fingers carrying,
    /// the three as hard contacts (never a pair with the third at zero: a
    /// grasping finger that does not press loses its contact); its
    /// commanded normals capped at the strongest push of the motors, and
    /// lower where the whole forces still need more (`capped` then).
    fn grip(&self, model: &GripModel, state: &HandState, torque: &Vector3<f64>, set: u8) -> Grip {
        let three = set == grip::CARRY_BITS && grip::grasp_mask(state) == grip::CARRY_BITS;
        let at = |cap: f64| {
            let m = model.within(cap);
            if three {
                m.triple(state, Accel::Known(*torque))
            } else {
                m.carried(state, torque, set)
            }
        };
        let cap = self.push_cap(state);
        let g = at(cap);
        if self.fits(&g) {
            return g;
        }
        let (mut lo, mut hi) = (0.0, cap.min(model.hold().max_grip()));
        let mut best = None;
        for _ in 0..CAP_HALVINGS {
            let mid = 0.5 * (lo + hi);
            let g = at(mid);
            if self.fits(&g) {
                lo = mid;
                best = Some(g);
            } else {
                hi = mid;
            }
        }
        let mut g = best.unwrap_or_else(|| at(lo));
        g.capped = true;
        g
    }
}

/// The grip model and the last grips it gave.
#[derive(Debug)]
pub(super) struct Grips {
    model: GripModel,
    /// Of the carrying set.
    from: Memo<GripKey, Grip>,
    /// Of the set a handover goes to.
    to: Memo<GripKey, Grip>,
}

impl Grips {
    /// With `model`, nothing computed yet.
    pub(super) fn new(model: GripModel) -> Self {
        Self {
            model,
            from: Memo::new(),
            to: Memo::new(),
        }
    }

    /// The grip of `state` turning with `torque` \[N·m\] (the object's
    /// inertia times its acceleration), carried by the fingers of
    /// `carrying`; during a handover to the set `to`, a fraction `elapsed`
    /// of the way, the two blended. `motors`: a chain hand's, whose effort
    /// the grip's forces keep within ([`Motors`]; they depend on the tips'
    /// places, which the memo's key holds).
    pub(super) fn at(
        &mut self,
        state: &HandState,
        torque: &Vector3<f64>,
        carrying: u8,
        handover: Option<(u8, f64)>,
        motors: Option<&Motors>,
    ) -> Grip {
        let model = &self.model;
        let capped = |set: u8| match motors {
            Some(m) => m.grip(model, state, torque, set),
            None => model.carried(state, torque, set),
        };
        let from = self.from.get(grip::grip_key(state, torque, carrying), |_| {
            capped(carrying)
        });
        match handover {
            Some((to, elapsed)) => {
                let to = self
                    .to
                    .get(grip::grip_key(state, torque, to), |_| capped(to));
                GripModel::blend(&from, &to, grip::ramp(elapsed))
            }
            None => from,
        }
    }

    /// The largest grip the load model allows \[N\].
    pub(super) fn max_grip(&self) -> f64 {
        self.model.hold().max_grip()
    }
}

//! The grip forces of the setpoint (SPEC §1.3 I1', §6.1): the normal forces
//! the carrying fingers press with to hold the load at the object's
//! acceleration, blended across a handover, each computed once per
//! (state, torque, carrying set) — a held setpoint costs a lookup.

use super::memo::Memo;
use crate::grasp::grip::{self, Grip, GripKey, GripModel};
use crate::hand_state::HandState;
use nalgebra::Vector3;

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
    /// of the way, the two blended. `cap`: no commanded normal above it
    /// (a chain hand's motors; it depends on the tips' places, which the
    /// memo's key holds).
    pub(super) fn at(
        &mut self,
        state: &HandState,
        torque: &Vector3<f64>,
        carrying: u8,
        handover: Option<(u8, f64)>,
        cap: Option<f64>,
    ) -> Grip {
        let model = &self.model;
        let capped = |set: u8| match cap {
            Some(c) => model.within(c).carried(state, torque, set),
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

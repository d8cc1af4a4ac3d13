//! An external plant (SPEC §6.2): the
//! executor waits for it, starts from what it measures, and takes the
//! faults the plant's link detects (lost, lying, out of sequence, its own
//! fault) through the one fault policy.
//!
//! The embedded kinematic hand starts where the executor was told; an
//! external one starts wherever the hand really is. Until a valid
//! measurement arrives the executor is in safe hold with
//! [`FaultKind::PlantWaiting`] and nothing moves; the first valid one
//! ([`Executor::start_from`]) becomes the start state if it satisfies
//! every invariant of SPEC §1.3, else the fault names the broken
//! invariant and the hand stays still until a reset finds a valid state.

use super::policy::{Cause, Source};
use super::*;

impl Executor {
    /// Nothing is known of the hand yet: safe hold with
    /// [`FaultKind::PlantWaiting`] (nothing to brake; the setpoint is still)
    /// until [`Executor::start_from`] succeeds.
    pub fn await_plant(&mut self) {
        self.enter_fault(FaultKind::PlantWaiting, NOT_A_FINGER);
        self.braking = false;
    }

    /// Whether the executor is waiting for a plant's first valid state.
    pub fn awaiting_plant(&self) -> bool {
        matches!(self.fault, Some((FaultKind::PlantWaiting, _)))
    }

    /// A fault the plant's link detected (the plant is lost, lies, went out
    /// of sequence or reports its own fault), through the fault policy.
    pub fn plant_fault(&mut self, kind: FaultKind, finger: u8) {
        self.handle(Cause::new(kind, Source::Plant), finger, None);
    }

    /// Starts from the state `m` measures, if the executor is waiting for
    /// a plant: grasping fingertips (measured in contact) are put on the
    /// contact sphere |p| = R + r (what is left is the fingertip's
    /// compliance), then every invariant is checked. On success the hand
    /// holds there (`FaultCleared`); otherwise the fault becomes the
    /// broken invariant's and nothing moves. Returns whether it started.
    pub fn start_from(&mut self, m: &Measurement) -> bool {
        if !self.awaiting_plant() {
            return false;
        }
        self.prev_measurement = Some(*m);
        self.measured_at = self.tick;
        let state = self.measured_hand(m);
        match self.checker.check(&state) {
            Ok(r) if r.ok() => {
                self.resume_from(state);
                true
            }
            other => {
                let (kind, finger) = match other {
                    Ok(r) => r
                        .first_violation()
                        .map_or((FaultKind::Contact, NOT_A_FINGER), invariant_fault),
                    Err(_) => (FaultKind::Contact, NOT_A_FINGER),
                };
                // Still nothing moves; the fault now says why.
                self.fault = Some((kind, finger));
                self.events.push(ExecutorEvent::Fault { kind, finger });
                false
            }
        }
    }

    /// The hand state `m` describes, as the model holds it: modes from the
    /// contact flags, rolls as measured, grasping fingertips on the contact
    /// sphere.
    pub(super) fn measured_hand(&self, m: &Measurement) -> HandState {
        let mut state = m.hand_state(&self.setpoint.state);
        for f in state.fingers.iter_mut() {
            let n = f.center.norm();
            if f.mode == crate::FingerMode::Grasping && n > 0.0 {
                f.center *= self.contact_radius / n;
            }
        }
        state
    }
}

//! Contact drift (SPEC §6.3): "contact drift beyond tolerance stops the
//! motion smoothly and replans from the measured state".
//!
//! When a grasping contact has drifted over the object surface (the object
//! slipped in the grasp), the executor
//! 1. remembers the offset of the measured object from the commanded one
//!    (object frame, so it stays valid while the grasp keeps rolling the
//!    object) and checks later measurements against that — a drift that
//!    goes on during the stop is a fault;
//! 2. brings the motion to rest as for a preemption (a finger in flight
//!    completes its placement first);
//! 3. at rest, re-bases its estimate of the object on the measured
//!    orientation (the state must still satisfy every invariant, else:
//!    fault, safe hold) and starts a new estimate epoch
//!    ([`Setpoint::estimate_epoch`](crate::planner::Setpoint));
//! 4. plans the goal again from there: to the same end orientation, and for
//!    a turn goal with the full turns it still had to make.
//!
//! At rest (no motion), step 3 happens at once. At most
//! `feedback.max_replans` drifts are recovered per goal; the next one is a
//! fault. An invariant near its limit in the measured state ([`super::guard`])
//! is recovered from the same way, from the same budget.

use core::f64::consts::TAU;

use nalgebra::{UnitQuaternion, Vector3};

use super::*;

/// A drift being recovered from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Drift {
    /// What it is as a fault: `ContactDrift`, or the invariant near its
    /// limit.
    pub cause: FaultKind,
    /// The finger whose contact drifted (or that is near the limit).
    pub finger: u8,
    /// Object-frame offset of the measured object from the commanded one
    /// (true ≈ commanded · offset); later measurements are checked against
    /// it.
    pub offset: UnitQuaternion<f64>,
}

impl Executor {
    /// Stops and replans after `cause`, seen in `m`: a contact drift
    /// (`ContactDrift`) or, while moving, the invariant `cause` stands for
    /// near its limit ([`super::guard`]). Only on the [`super::policy`]'s
    /// decision (which refuses a second recovery under way or one past the
    /// budget).
    pub(super) fn recover(&mut self, cause: FaultKind, finger: u8, m: &Measurement) {
        self.replans += 1;
        self.drift = Some(Drift {
            cause,
            finger,
            offset: self.setpoint.state.object.inverse() * m.object,
        });
        let id = self
            .goals
            .active()
            .or(self.goals.pending())
            .map_or(0, |g| g.id);
        let replan = self.replans;
        self.events.push(if cause == FaultKind::ContactDrift {
            ExecutorEvent::Drift { id, finger, replan }
        } else {
            ExecutorEvent::NearLimit {
                id,
                kind: cause,
                finger,
                replan,
            }
        });
        match self.phase {
            Mode::Moving => self.request_stop(AfterStop::Recover),
            // Already braking: `finish_stop` re-bases before going on.
            Mode::Stopping => {}
            // Re-bases and plans again when the plan in the making arrives
            // (`deliver_plan`).
            Mode::Planning => {}
            Mode::Holding => {
                self.prev_measurement = Some(*m);
                self.measured_at = self.tick;
                self.rebase();
            }
            Mode::SafeHold => {}
        }
    }

    /// Re-bases the estimate on the last measurement (at rest): the object
    /// where it was measured. The commanded fingertips stay (a slip moves
    /// the object, not the fingers; copying a real hand's fingertip
    /// tracking error in would break the contact invariant). Enters the
    /// fault and returns false if the state breaks an invariant.
    pub(super) fn rebase(&mut self) -> bool {
        let (cause, finger) = self
            .drift
            .take()
            .map_or((FaultKind::ContactDrift, NOT_A_FINGER), |d| {
                (d.cause, d.finger)
            });
        // The fingertips stay where they were commanded (with the
        // correction folded in, which the re-base then clears).
        let commanded = self.correction.apply(&self.setpoint).state;
        let state = self.prev_measurement.map(|m| {
            let mut s = commanded;
            s.object = m.object;
            s
        });
        match state.map(|s| (s, self.checker.check(&s))) {
            Some((s, Ok(r))) if r.ok() => {
                self.adopt(s);
                true
            }
            _ => {
                self.handle(Cause::new(cause, Source::Rebase), finger, None);
                // At rest already: nothing to brake.
                self.braking = false;
                false
            }
        }
    }

    /// The state last measured, as the model holds it (reset after a
    /// fault): object and fingertips where measured, modes from the contact
    /// flags, rolls as measured (an external plant may have been restarted
    /// in another grasp).
    pub(super) fn measured_state(&self) -> Option<HandState> {
        self.prev_measurement.map(|m| self.measured_hand(&m))
    }

    /// Takes `state` as the new estimate, at rest, in a new epoch.
    pub(super) fn adopt(&mut self, state: HandState) {
        self.epoch = self.epoch.wrapping_add(1);
        self.setpoint = rest(state);
        self.setpoint.estimate_epoch = self.epoch;
        self.prev_setpoint = self.setpoint;
        self.reset_written(state);
        self.drift = None;
    }

    /// After a drift: the active goal is planned again from the re-based
    /// state, `left` being the object rotation its plan still had to make
    /// \[rad\] (`None`: no plan had started, all of the turn is left).
    pub(super) fn replan_after_drift(&mut self, left: Option<f64>) {
        let from = self.setpoint.state.object;
        let Some(g) = self.goals.active_mut() else {
            self.phase = Mode::Holding;
            return;
        };
        if let GoalTarget::Rotation { axis, angle } = g.target {
            // Plans turn about the signed axis (`Planner::plan_rotation`).
            let hint = if angle < 0.0 { -axis } else { axis };
            let left = left.unwrap_or(angle.abs());
            let (axis, angle) = remaining_turn(&from, &g.end, &hint, left);
            g.target = GoalTarget::Rotation { axis, angle };
        }
        self.begin_planning();
    }
}

/// The rotation from `from` to `end` whose angle about (roughly) `hint` is
/// closest to `left`: the same end orientation, with the full turns a turn
/// goal still had to make. Returns (unit axis, angle ≥ 0).
pub(super) fn remaining_turn(
    from: &UnitQuaternion<f64>,
    end: &UnitQuaternion<f64>,
    hint: &Vector3<f64>,
    left: f64,
) -> (Vector3<f64>, f64) {
    let hint = hint.normalize();
    let (axis, angle) = (end * from.inverse())
        .axis_angle()
        .map_or((hint, 0.0), |(a, t)| (a.into_inner(), t));
    // Signed about the hint, then the equivalent angle nearest `left`.
    let (axis, signed) = if axis.dot(&hint) >= 0.0 {
        (axis, angle)
    } else {
        (-axis, -angle)
    };
    let total = signed + TAU * ((left - signed) / TAU).round();
    if total >= 0.0 {
        (axis, total)
    } else {
        (-axis, -total)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn about(axis: &Vector3<f64>, angle: f64) -> UnitQuaternion<f64> {
        UnitQuaternion::from_scaled_axis(axis.normalize() * angle)
    }

    #[test]
    fn remaining_turn_keeps_full_turns_and_the_end() {
        let from = about(&Vector3::new(0.2, 0.5, -0.3), 0.7);
        let z = Vector3::z();
        // A small slip off the axis between the plan and the measurement.
        let slip = about(&Vector3::new(1.0, 0.3, 0.0), 0.01);
        for left in [0.3, 2.5, 3.5, 5.9, 6.6, 13.0, 4.0 * TAU - 0.2] {
            let end = about(&z, left) * slip * from;
            let (axis, angle) = remaining_turn(&from, &end, &z, left);
            assert!((angle - left).abs() < 0.05, "{left}: {angle}");
            assert!(axis.dot(&z) > 0.99);
            let reached = about(&axis, angle) * from;
            assert!(reached.angle_to(&end) < 1e-12, "{left}");
        }
        // Nothing left: no turn.
        let (_, angle) = remaining_turn(&from, &from, &z, 0.0);
        assert!(angle < 1e-12, "{angle}");
    }
}

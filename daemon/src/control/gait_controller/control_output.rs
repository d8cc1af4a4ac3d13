//! The tick's report → the controller output the status is made from:
//! phase, goal progress, per-finger state, grip forces, force closure, and
//! the measurement beside the command.

use super::GaitController;
use super::codes::{fault_code, goal_reason, goal_state};
use crate::control::controller::{ControlOutput, FingerOutput, GoalReport};
use gait::executor::{self, Reason, TickReport};
use gait::planner::{Motion, StepKind};
use gait::{FINGERS, FingerMode};
use shm_schema::{FaultCode, FingerPhase, GoalState, GraspState, Phase};

/// The status phase of the executor's phase and step.
fn phase(r: &TickReport) -> Phase {
    match (r.phase, r.step_kind) {
        (executor::Mode::Moving, Some(StepKind::Roll)) => Phase::Roll,
        (executor::Mode::Moving, Some(StepKind::Rotate)) => Phase::Rotate,
        (executor::Mode::Moving, Some(StepKind::Place | StepKind::Transfer)) => Phase::Place,
        (executor::Mode::Moving, Some(StepKind::Lift)) => Phase::Lift,
        (executor::Mode::Stopping, _) => Phase::Stopping,
        (executor::Mode::SafeHold, _) => Phase::SafeHold,
        _ => Phase::Hold,
    }
}

impl GaitController {
    /// Fills `out` from this tick's report.
    pub(super) fn output(&self, r: &TickReport, out: &mut ControlOutput) {
        let hand = r.setpoint.state;
        let active = self.exec.plan().and_then(|p| {
            matches!(r.phase, executor::Mode::Moving | executor::Mode::Stopping)
                .then(|| p.steps.get(self.exec.step_index()))
                .flatten()
        });
        let active_finger = active.and_then(|s| match s.motion {
            Motion::Free(m) => Some(m.finger),
            Motion::RollSegment { finger, .. } => Some(finger),
            Motion::Roll { rolls, .. } => rolls[0].map(|r| r.finger),
            Motion::Rotate { .. } | Motion::Carry { .. } => None,
        });
        out.hand = hand;
        out.object_omega = r.setpoint.object_rate;
        out.measured = self.measured;
        out.phase = phase(r);
        out.fault = r.fault.map_or(FaultCode::None, |(k, _)| fault_code(k));
        let (goal_id, state, reason) = r
            .goal
            .map_or((0, None, Reason::None), |(id, s, why)| (id, Some(s), why));
        let (client_id, wire_goal) = self.ids.wire(goal_id);
        out.goal = GoalReport {
            goal_id: wire_goal,
            client_id,
            state: state.map_or(GoalState::None, goal_state),
            reason: goal_reason(state, reason),
            remaining_angle: r.remaining_angle,
            eta: matches!(r.phase, executor::Mode::Moving | executor::Mode::Stopping)
                .then_some(r.eta),
            gaits_done: r.gaits.0,
            gaits_planned: r.gaits.1,
            active_finger,
        };
        for k in 0..FINGERS {
            let f = &hand.fingers[k];
            let phase = match (f.mode, active.map(|s| s.kind), active_finger == Some(k)) {
                (FingerMode::Grasping, Some(StepKind::Roll), true) => FingerPhase::Rolling,
                // A finger still touching while the grip passes to or from
                // it (the handover at rest before a lift, after a
                // placement) is grasping: it presses with its share.
                (FingerMode::Free, Some(StepKind::Lift), true) => FingerPhase::Lifting,
                (FingerMode::Free, Some(StepKind::Place), true) => FingerPhase::Placing,
                (FingerMode::Grasping, _, _) => FingerPhase::Grasping,
                (FingerMode::Free, _, _) => FingerPhase::Free,
            };
            out.fingers[k] = FingerOutput {
                phase,
                // The executor's invariant check measured it this tick
                // against β − margin; the status reports it against β (on
                // a chain hand: against the limits less their margin).
                workspace_margin: r.workspace_slack[k] + self.workspace_margin,
                normal_force: r.grip[k],
                joints: r.joints[k],
                tip_margin: r.tip_slack[k],
                link_clearance: r.link_slack[k],
            };
        }
        out.chains = self.chains;
        out.grasp = if r.force_closure.0 {
            GraspState::ForceClosure
        } else {
            GraspState::NotForceClosure
        };
        out.grasp_margin = r.force_closure.1;
        out.load_grip = r.grip_peak;
        out.load_margin = r.load_margin;
    }
}

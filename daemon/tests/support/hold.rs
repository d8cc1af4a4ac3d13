//! A still stand-in controller for tests: holds the paper's start grasp.
//!
//! Test support only (the daemon runs the gait controller). Tests of the
//! loop, the command intake and the status conversion use it where a
//! planner thread would only add noise: it publishes the paper's initial
//! grasp (SPEC §4.3, paper Fig. 4 frame 1) every tick, answers Hold, Cancel
//! and Reset, and rejects every reorientation goal with
//! [`ReasonCode::PlannerUnavailable`] — it never pretends to move. It
//! computes no grasp forces, so force closure is reported as
//! [`GraspState::Unknown`] and normal forces as 0.
//!
//! Included by the integration tests (`mod support`) and by the crate's own
//! unit tests (`#[path]`, with `gaitd` naming the crate itself).

use gait::{FINGERS, FingerMode, HandConfig, HandState};
use gaitd::control::controller::{
    ControlCommand, ControlOutput, Controller, FingerOutput, GoalReport, TickContext,
};
use nalgebra::Vector3;
use shm_schema::{EventKind, FaultCode, FingerPhase, GraspState, Phase, ReasonCode, Verdict};

/// Holds the paper's start grasp; see the module docs.
#[derive(Debug, Clone)]
pub struct HoldController {
    out: ControlOutput,
}

/// Angle from the contact direction of `finger` to the boundary of its
/// workspace cone W_k (SPEC §1.1), positive inside \[rad\].
pub fn workspace_margin(config: &HandConfig, hand: &HandState, finger: usize) -> f64 {
    let m = &config.model;
    let phi = m.finger_azimuth_deg[finger].to_radians();
    let d = Vector3::new(phi.cos(), phi.sin(), 0.0);
    let c = hand.fingers[finger].center.normalize();
    m.workspace_half_angle_deg.to_radians() - c.dot(&d).clamp(-1.0, 1.0).acos()
}

impl HoldController {
    /// Holds [`HandState::paper_start`] for `config`.
    pub fn new(config: &HandConfig) -> Self {
        let hand = HandState::paper_start(config);
        let fingers: [FingerOutput; FINGERS] = std::array::from_fn(|k| FingerOutput {
            phase: match hand.fingers[k].mode {
                FingerMode::Grasping => FingerPhase::Grasping,
                FingerMode::Free => FingerPhase::Free,
            },
            workspace_margin: workspace_margin(config, &hand, k),
            ..FingerOutput::bare(FingerPhase::Free)
        });
        Self {
            out: ControlOutput {
                hand,
                object_omega: Vector3::zeros(),
                measured: None,
                phase: Phase::Hold,
                fault: FaultCode::None,
                goal: GoalReport::default(),
                fingers,
                chains: false,
                grasp: GraspState::Unknown,
                grasp_margin: 0.0,
                load_grip: 0.0,
                load_margin: 0.0,
                plant_command: None,
            },
        }
    }
}

impl Controller for HoldController {
    fn command(&mut self, cmd: &ControlCommand, ctx: &mut TickContext<'_>) -> Verdict {
        match *cmd {
            ControlCommand::Goal(_) => Verdict::Rejected(ReasonCode::PlannerUnavailable),
            // Nothing ever runs, so there is nothing to cancel.
            ControlCommand::Cancel { .. } => Verdict::Rejected(ReasonCode::NoActiveGoal),
            ControlCommand::Hold { client_id } => {
                let mut e = shm_schema::Event::new(EventKind::Hold);
                e.client_id = client_id;
                e.reason = ReasonCode::HoldRequested.code();
                ctx.events.push(e);
                Verdict::Accepted
            }
            // Never faulted: reset is a no-op that leaves the hand in hold.
            ControlCommand::Reset { .. } => Verdict::Accepted,
        }
    }

    fn tick(&mut self, _ctx: &mut TickContext<'_>, out: &mut ControlOutput) {
        *out = self.out;
    }

    fn begin_safe_hold(&mut self, _ctx: &mut TickContext<'_>) {}

    fn at_rest(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gaitd::control::controller::{ClientTarget, Goal};
    use gaitd::control::tick_events::TickEvents;
    use nalgebra::UnitQuaternion;

    #[test]
    fn holds_the_paper_start_and_refuses_goals() {
        let cfg = HandConfig::default();
        let mut c = HoldController::new(&cfg);
        let mut events = TickEvents::new();
        let mut ctx = TickContext {
            now: 0,
            tick: 1,
            events: &mut events,
        };
        let goal = ControlCommand::Goal(Goal {
            client_id: 1,
            goal_id: 1,
            target: ClientTarget::Absolute(UnitQuaternion::identity()),
            limits: cfg.limits,
        });
        assert_eq!(
            c.command(&goal, &mut ctx),
            Verdict::Rejected(ReasonCode::PlannerUnavailable)
        );
        assert_eq!(
            c.command(&ControlCommand::Hold { client_id: 1 }, &mut ctx),
            Verdict::Accepted
        );
        let mut out = c.out;
        c.tick(&mut ctx, &mut out);
        assert_eq!(out.hand, HandState::paper_start(&cfg));
        assert_eq!(out.phase, Phase::Hold);
        for f in &out.fingers {
            // Contacts sit on d_k: the whole cone half-angle β is margin.
            assert!((f.workspace_margin - 60f64.to_radians()).abs() < 1e-12);
        }
        assert_eq!(events.as_slice().len(), 1);
        assert!(c.at_rest());
    }
}

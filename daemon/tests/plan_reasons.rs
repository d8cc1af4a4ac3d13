//! Typed planning failures reach the client (SPEC §4.1): whatever reason
//! the planner gives, the goal ends Aborted with that reason's own wire
//! code — in the goal-transition event and in the status — through the
//! daemon's real path (planner thread, link, executor, event translation,
//! status conversion, iceoryx2 ports) on the mock clock. The expected codes
//! are LAYOUT.md's.

#[path = "support/ipc_rig.rs"]
mod ipc_rig;

use gait::planner::{Plan, PlanError};
use gaitd::control::gait_controller::GoalPlanRequest;
use gaitd::control::plan_thread::{BackgroundPlanner, Wanted};
use ipc_rig::{Namespace, gait_loop_with};
use shm_schema::{Command, EventKind, GoalFrame, GoalState, NO_FINGER, ReasonCode};

/// A planner that always fails with one reason.
struct Failing(PlanError);

impl BackgroundPlanner for Failing {
    type Request = GoalPlanRequest;
    type Plan = Plan;
    type Error = PlanError;
    fn plan(&mut self, _: &GoalPlanRequest, _: &Wanted) -> Result<Plan, PlanError> {
        Err(self.0)
    }
}

#[test]
fn each_planner_reason_reaches_the_event_and_the_status() {
    // (planner's reason, LAYOUT.md code, finger named by the event)
    let table = [
        (PlanError::InvalidGoal, 32, NO_FINGER),
        (PlanError::InvalidLimits, 10, NO_FINGER),
        (PlanError::NonFiniteState, 29, NO_FINGER),
        (PlanError::NoGrasp, 28, NO_FINGER),
        (PlanError::NoTwoFingerGrasp, 30, NO_FINGER),
        (PlanError::SearchExhausted, 19, NO_FINGER),
        (PlanError::Blocked { finger: 2 }, 31, 2),
        (PlanError::LoadInfeasible { start: true }, 34, NO_FINGER),
        (PlanError::Timeout, 35, NO_FINGER),
        (PlanError::LoadInfeasible { start: false }, 34, NO_FINGER),
    ];
    for (i, (error, code, finger)) in table.into_iter().enumerate() {
        let ns = Namespace::new(&format!("pr{i}"));
        let mut g = gait_loop_with(&ns, 60 + i as u64, Failing(error), |_| {});
        g.client.send(Command::goal(
            5,
            1,
            GoalFrame::AxisAngle,
            [1.0, 0.0, 0.0, 1.0],
        ));
        let mut aborted = None;
        let mut status_reason = None;
        for _ in 0..100_000 {
            let (statuses, events) = g.tick();
            for e in events {
                if e.kind() == Ok(EventKind::GoalTransition) && e.state == GoalState::Aborted.code()
                {
                    aborted = Some(e);
                }
            }
            if let Some(s) = statuses.last()
                && s.goal_state() == Ok(GoalState::Aborted)
            {
                status_reason = Some(s.goal.reason);
            }
            if aborted.is_some() && status_reason.is_some() {
                break;
            }
            g.yield_to_planner();
        }
        let e = aborted.unwrap_or_else(|| panic!("{error:?}: never aborted"));
        assert_eq!(
            (e.goal_id, e.client_id, e.reason, e.finger),
            (1, 5, code, finger),
            "{error:?}: {:?}",
            ReasonCode::try_from(e.reason)
        );
        assert_eq!(status_reason, Some(code), "{error:?} in the status");
        g.finish();
    }
}

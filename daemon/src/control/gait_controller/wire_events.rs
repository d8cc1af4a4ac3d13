//! The executor's events → wire events (SPEC §7.3): goal transitions with
//! the client's ids and the wire reason, gait events (place, lift, roll),
//! substitutions and rewinds recognised in the finished steps, faults
//! (with the finger that caused them, if one did), drifts and invariants
//! near their limit.

use super::GaitController;
use super::codes::{fault_code, goal_reason, goal_state, reason_finger};
use crate::control::controller::TickContext;
use gait::executor::{ExecutorEvent, FaultKind};
use gait::planner::StepKind;
use gait::planner::gaiting::FingerGait;
use shm_schema::EventKind;

impl GaitController {
    /// Moves every queued executor event to `ctx.events`; `remaining` is
    /// the angle still to turn, for goal transitions.
    pub(super) fn forward_events(&mut self, ctx: &mut TickContext<'_>, remaining: f64) {
        while let Some(e) = self.exec.pop_event() {
            match e {
                ExecutorEvent::Goal { id, state, reason } => {
                    // A new plan, or none: no rewind spans it (a gait step
                    // in flight still completes its substitution).
                    self.gaits.interrupt();
                    let (client, goal) = self.ids.wire(id);
                    let code = goal_reason(Some(state), reason);
                    if state.is_terminal() && self.tracing() == Some(id) {
                        self.trace_end = Some((goal_state(state), code));
                    }
                    ctx.events.goal_transition(
                        client,
                        goal,
                        goal_state(state),
                        code,
                        remaining,
                        reason_finger(reason),
                    );
                }
                ExecutorEvent::Step {
                    id, kind, finger, ..
                } => {
                    self.gaits.started(kind);
                    let (client, goal) = self.ids.wire(id);
                    match kind {
                        StepKind::Lift => ctx.events.gait(EventKind::Lift, finger, goal, client),
                        StepKind::Roll => ctx.events.gait(EventKind::Roll, finger, goal, client),
                        _ => {}
                    }
                }
                ExecutorEvent::StepDone {
                    id, kind, finger, ..
                } => {
                    let (client, goal) = self.ids.wire(id);
                    if kind == StepKind::Place {
                        ctx.events.gait(EventKind::Place, finger, goal, client);
                    }
                    let done = self.gaits.done(kind, finger);
                    if let Some(FingerGait::Substitution { left, by }) = done.substitution {
                        ctx.events.substitution(left, by, goal, client);
                    }
                    if let Some(FingerGait::Rewind { relocated, helper }) = done.rewind {
                        ctx.events.rewind(helper, relocated, goal, client);
                    }
                }
                ExecutorEvent::Fault { kind, finger } => {
                    self.gaits.reset();
                    let count = match kind {
                        FaultKind::PlantFault => u64::from(self.plant_fault.code()),
                        _ => 0,
                    };
                    ctx.events.fault(fault_code(kind), finger, count);
                }
                ExecutorEvent::FaultCleared => ctx
                    .events
                    .push(shm_schema::Event::new(EventKind::FaultCleared)),
                ExecutorEvent::Drift { id, finger, replan } => {
                    self.gaits.interrupt();
                    let (client, goal) = self.ids.wire(id);
                    ctx.events.drift(finger, replan, goal, client);
                }
                ExecutorEvent::NearLimit {
                    id,
                    kind,
                    finger,
                    replan,
                } => {
                    self.gaits.interrupt();
                    let (client, goal) = self.ids.wire(id);
                    ctx.events
                        .near_limit(fault_code(kind), finger, replan, goal, client);
                }
            }
        }
    }
}

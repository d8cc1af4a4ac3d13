//! The real controller: the planner, the executor and the embedded
//! kinematic hand behind the daemon's [`Controller`] seam (SPEC §6, §7.2).
//!
//! Per tick, on the loop thread: read the plant, drain the planner's
//! replies into the executor, tick the executor, write the setpoint to the
//! plant, turn the executor's events into wire events, and report. Plans
//! are made on the planner thread ([`GaitPlanner`]); the executor hands
//! back every plan it no longer needs and this controller retires it to the
//! planner thread, so nothing is allocated or freed here.

use crate::control::controller::{
    ControlCommand, ControlOutput, Controller, FingerReport, GoalReport, GoalTarget, TickContext,
};
use crate::control::planner::{Planner, PlannerLink};
use crate::io::tracer::{Sample, TraceRecorder};
use gait::executor::{self, Command, Event, Executor, FaultKind, PlanRequest, Reason, TickReport};
use gait::gaiting::{FingerGait, GaitTracker};
use gait::planner::{Plan, StepKind};
use gait::sim::{KinematicHand, Plant};
use gait::{FINGERS, FingerMode, HandConfig, HandState};
use nalgebra::Vector3;
use shm_schema::{
    EventKind, FaultCode, FingerPhase, GoalState, GraspState, Phase, ReasonCode, Verdict,
};

/// Plans on the planner thread (SPEC §4).
#[derive(Debug)]
pub struct GaitPlanner(pub gait::planner::Planner);

impl Planner for GaitPlanner {
    type Request = PlanRequest;
    type Plan = Plan;
    fn plan(&mut self, r: &PlanRequest) -> Result<Plan, ReasonCode> {
        r.target
            .plan(&self.0, &r.start)
            .map_err(|_| ReasonCode::NoPlan)
    }
}

/// Goals in flight whose ids the executor knows by a number of its own.
const GOAL_SLOTS: usize = 32;
/// Plan requests in flight (sequence number → executor goal).
const REQUEST_SLOTS: usize = 8;
/// Plans kept on the loop while the retire ring is full.
const RETIRE_SLOTS: usize = 4;

/// The daemon's controller (module docs).
pub struct GaitController {
    exec: Executor,
    plant: KinematicHand,
    link: PlannerLink<PlanRequest, Plan>,
    /// Executor goal id → (client id, goal id).
    goals: [(u64, u64, u64); GOAL_SLOTS],
    next_goal: u64,
    requests: [(u64, u64); REQUEST_SLOTS],
    /// Plans waiting for room in the retire ring.
    retiring: [Option<Box<Plan>>; RETIRE_SLOTS],
    /// Plans leaked because the retire ring and `retiring` were full.
    leaked_plans: u64,
    /// Recognises substitutions and rewinds in the finished steps.
    gaits: GaitTracker,
    safe_hold_requested: bool,
    /// The configured workspace margin \[rad\].
    workspace_margin: f64,
    /// Targets of the goals in `goals` (same slots), for trace headers.
    targets: [Option<executor::GoalTarget>; GOAL_SLOTS],
    /// Goal traces, when configured ([`GaitController::set_trace`]).
    trace: Option<TraceRecorder>,
    /// Terminal state of the goal being traced, seen in this tick's events.
    trace_end: Option<(GoalState, ReasonCode)>,
}

impl std::fmt::Debug for GaitController {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GaitController")
            .field("phase", &self.exec.phase())
            .finish()
    }
}

impl GaitController {
    /// The hand at the paper's start grasp, ticking every `dt`; plans go
    /// through `link`.
    pub fn new(
        config: &HandConfig,
        dt: f64,
        link: PlannerLink<PlanRequest, Plan>,
    ) -> Result<Self, gait::ConfigError> {
        let start = HandState::paper_start(config);
        Ok(Self {
            exec: Executor::new(config, dt, start)?,
            plant: KinematicHand::new(start, dt),
            link,
            goals: [(0, 0, 0); GOAL_SLOTS],
            next_goal: 1,
            requests: [(0, 0); REQUEST_SLOTS],
            retiring: [const { None }; RETIRE_SLOTS],
            leaked_plans: 0,
            gaits: GaitTracker::new(),
            safe_hold_requested: false,
            workspace_margin: config.model.workspace_margin_deg.to_radians(),
            targets: [None; GOAL_SLOTS],
            trace: None,
            trace_end: None,
        })
    }

    /// Records every goal's execution through `recorder` (SPEC §8; see
    /// [`crate::io::tracer`]).
    pub fn set_trace(&mut self, recorder: TraceRecorder) {
        self.trace = Some(recorder);
    }

    /// Feeds this tick to the trace recorder: a goal is recorded from the
    /// tick it is first reported `Executing` to the tick its terminal state
    /// is seen (that tick included). Copies one `Sample`; no allocation.
    fn record_trace(&mut self, r: &TickReport) {
        let Some(rec) = &mut self.trace else { return };
        let sample = Sample::from_report(r);
        let starting = match r.goal {
            Some((id, executor::GoalState::Executing, _)) if rec.recording() != Some(id) => {
                Some(id)
            }
            _ => None,
        };
        // This tick belongs to the goal being recorded unless another one
        // starts executing in it.
        if starting.is_none() {
            rec.record(&sample);
        }
        if let Some(end) = self.trace_end.take() {
            rec.end(Some(end));
        }
        if let Some(id) = starting {
            let slot = (id as usize) % GOAL_SLOTS;
            let (g, client, goal) = self.goals[slot];
            let (client, goal, target) = if g == id {
                (client, goal, self.targets[slot])
            } else {
                (0, id, None)
            };
            rec.begin(id, client, goal, target);
            rec.record(&sample);
        }
    }

    /// The executor's phase.
    pub fn phase(&self) -> executor::Phase {
        self.exec.phase()
    }

    /// The commanded hand state: where the next goal is planned from.
    pub fn state(&self) -> HandState {
        self.exec.setpoint().state
    }

    /// Plans leaked because they could not be handed back to the planner
    /// thread (expected 0: see `retire`).
    pub fn leaked_plans(&self) -> u64 {
        self.leaked_plans
    }

    /// The embedded plant (tests inject faults through it).
    pub fn plant_mut(&mut self) -> &mut KinematicHand {
        &mut self.plant
    }

    fn wire_goal(&self, id: u64) -> (u64, u64) {
        self.goals
            .iter()
            .find(|g| g.0 == id)
            .map_or((0, id), |g| (g.1, g.2))
    }

    fn retire(&mut self, plan: Option<Box<Plan>>) {
        let Some(plan) = plan else { return };
        if let Err(p) = self.link.retire(plan) {
            // Ring full: keep it for the next tick (never drop it here).
            match self.retiring.iter_mut().find(|slot| slot.is_none()) {
                Some(slot) => *slot = Some(p),
                None => {
                    // Cannot happen (the ring has room for every plan alive
                    // on this side, see `planner::spawn`); should it, a
                    // leaked plan is a bounded loss, a free here is not.
                    Box::leak(p);
                    self.leaked_plans += 1;
                }
            }
        }
    }

    fn pump_planner(&mut self) {
        for k in 0..RETIRE_SLOTS {
            let p = self.retiring[k].take();
            self.retire(p);
        }
        if let Some(req) = self.exec.take_plan_request() {
            match self.link.submit(req) {
                Ok(seq) => {
                    let slot = (seq as usize) % REQUEST_SLOTS;
                    self.requests[slot] = (seq, req.goal);
                }
                Err(_) => {
                    // The planner is swamped: the goal fails rather than waits.
                    let old = self
                        .exec
                        .deliver_plan(req.goal, Err(gait::planner::PlanError::SearchExhausted));
                    self.retire(old);
                }
            }
        }
        while let Some(reply) = self.link.poll() {
            let slot = (reply.seq as usize) % REQUEST_SLOTS;
            let (seq, goal) = self.requests[slot];
            if seq != reply.seq {
                if let Ok(p) = reply.result {
                    self.retire(Some(p));
                }
                continue;
            }
            let result = reply
                .result
                .map_err(|_| gait::planner::PlanError::SearchExhausted);
            let old = self.exec.deliver_plan(goal, result);
            self.retire(old);
        }
    }

    fn forward_events(&mut self, ctx: &mut TickContext<'_>, remaining: f64) {
        while let Some(e) = self.exec.pop_event() {
            match e {
                Event::Goal { id, state, reason } => {
                    // A new plan, or none: no rewind spans it (a gait step
                    // in flight still completes its substitution).
                    self.gaits.interrupt();
                    let (client, goal) = self.wire_goal(id);
                    let reason = match (state, reason) {
                        (executor::GoalState::Succeeded, _) => ReasonCode::Reached,
                        _ => reason_code(reason),
                    };
                    if state.is_terminal()
                        && self.trace.as_ref().and_then(TraceRecorder::recording) == Some(id)
                    {
                        self.trace_end = Some((goal_state(state), reason));
                    }
                    ctx.events
                        .goal_transition(client, goal, goal_state(state), reason, remaining);
                }
                Event::Step {
                    id, kind, finger, ..
                } => {
                    self.gaits.started(kind);
                    let (client, goal) = self.wire_goal(id);
                    match kind {
                        StepKind::Lift => ctx.events.gait(EventKind::Lift, finger, goal, client),
                        StepKind::Roll => ctx.events.gait(EventKind::Roll, finger, goal, client),
                        _ => {}
                    }
                }
                Event::StepDone {
                    id, kind, finger, ..
                } => {
                    let (client, goal) = self.wire_goal(id);
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
                Event::Fault { kind, .. } => {
                    self.gaits.reset();
                    ctx.events.fault(fault_code(kind));
                }
                Event::FaultCleared => ctx
                    .events
                    .push(shm_schema::Event::new(EventKind::FaultCleared)),
                Event::Drift { id, finger, replan } => {
                    self.gaits.interrupt();
                    let (client, goal) = self.wire_goal(id);
                    ctx.events.drift(finger, replan, goal, client);
                }
                Event::NearLimit {
                    id,
                    kind,
                    finger,
                    replan,
                } => {
                    self.gaits.interrupt();
                    let (client, goal) = self.wire_goal(id);
                    ctx.events
                        .near_limit(fault_code(kind), finger, replan, goal, client);
                }
            }
        }
    }

    fn output(&self, r: &TickReport, out: &mut ControlOutput) {
        let hand = r.setpoint.state;
        let active = self.exec.plan().and_then(|p| {
            matches!(r.phase, executor::Phase::Moving | executor::Phase::Stopping)
                .then(|| p.steps.get(self.exec.step_index()))
                .flatten()
        });
        let active_finger = active.and_then(|s| match s.motion {
            gait::planner::Motion::Free(m) => Some(m.finger),
            gait::planner::Motion::RollSegment { finger, .. } => Some(finger),
            gait::planner::Motion::Roll { rolls, .. } => rolls[0].map(|r| r.finger),
            gait::planner::Motion::Rotate { .. } => None,
        });
        out.hand = hand;
        out.object_omega = r.setpoint.object_rate;
        out.phase = match (r.phase, r.step_kind) {
            (executor::Phase::Moving, Some(StepKind::Roll)) => Phase::Roll,
            (executor::Phase::Moving, Some(StepKind::Rotate)) => Phase::Rotate,
            (executor::Phase::Moving, Some(StepKind::Place | StepKind::Transfer)) => Phase::Place,
            (executor::Phase::Moving, Some(StepKind::Lift)) => Phase::Lift,
            (executor::Phase::Stopping, _) => Phase::Stopping,
            (executor::Phase::SafeHold, _) => Phase::SafeHold,
            _ => Phase::Hold,
        };
        out.fault = r.fault.map_or(FaultCode::None, |(k, _)| fault_code(k));
        let (goal_id, state, reason) = r
            .goal
            .map_or((0, None, Reason::None), |(id, s, why)| (id, Some(s), why));
        let (client_id, wire_goal) = if goal_id == 0 {
            (0, 0)
        } else {
            self.wire_goal(goal_id)
        };
        out.goal = GoalReport {
            goal_id: wire_goal,
            client_id,
            state: state.map_or(GoalState::None, goal_state),
            reason: match state {
                Some(executor::GoalState::Succeeded) => ReasonCode::Reached,
                _ => reason_code(reason),
            },
            remaining_angle: r.remaining_angle,
            eta: matches!(r.phase, executor::Phase::Moving | executor::Phase::Stopping)
                .then_some(r.eta),
            gaits_done: r.gaits.0,
            gaits_planned: r.gaits.1,
            active_finger,
        };
        for k in 0..FINGERS {
            let f = &hand.fingers[k];
            let phase = match (f.mode, active.map(|s| s.kind), active_finger == Some(k)) {
                (FingerMode::Grasping, Some(StepKind::Roll), true) => FingerPhase::Rolling,
                (_, Some(StepKind::Lift), true) => FingerPhase::Lifting,
                (_, Some(StepKind::Place), true) => FingerPhase::Placing,
                (FingerMode::Grasping, _, _) => FingerPhase::Grasping,
                (FingerMode::Free, _, _) => FingerPhase::Free,
            };
            out.fingers[k] = FingerReport {
                phase,
                // The executor's invariant check measured it this tick
                // against β − margin; the status reports it against β.
                workspace_margin: r.workspace_slack[k] + self.workspace_margin,
                normal_force: r.grip[k],
            };
        }
        out.grasp = if r.force_closure.0 {
            GraspState::ForceClosure
        } else {
            GraspState::NotForceClosure
        };
        out.grasp_margin = r.force_closure.1;
    }
}

fn goal_state(s: executor::GoalState) -> GoalState {
    match s {
        executor::GoalState::Accepted => GoalState::Accepted,
        executor::GoalState::Planning => GoalState::Planning,
        executor::GoalState::Executing => GoalState::Executing,
        executor::GoalState::Succeeded => GoalState::Succeeded,
        executor::GoalState::Aborted => GoalState::Aborted,
        executor::GoalState::Canceled => GoalState::Canceled,
        executor::GoalState::Preempted => GoalState::Preempted,
        executor::GoalState::Rejected => GoalState::Rejected,
    }
}

fn reason_code(r: Reason) -> ReasonCode {
    match r {
        Reason::None => ReasonCode::None,
        Reason::InvalidTarget => ReasonCode::NonUnitQuaternion,
        Reason::FaultActive => ReasonCode::Faulted,
        Reason::NoPlan | Reason::InvalidStart | Reason::Stale => ReasonCode::NoPlan,
        Reason::Fault => ReasonCode::FaultDetected,
        Reason::CancelCommand => ReasonCode::CanceledByClient,
        Reason::HoldCommand => ReasonCode::HoldRequested,
        Reason::NewerGoal => ReasonCode::PreemptedByGoal,
        Reason::DuplicateId => ReasonCode::DuplicateGoalId,
    }
}

fn fault_code(k: FaultKind) -> FaultCode {
    match k {
        FaultKind::MissingMeasurement => FaultCode::MeasurementMissing,
        FaultKind::BadMeasurement => FaultCode::NonFiniteState,
        FaultKind::ObjectTracking | FaultKind::ContactDrift => FaultCode::Slip,
        FaultKind::FingerTracking => FaultCode::StuckFinger,
        FaultKind::Trajectory | FaultKind::Contact => FaultCode::NonFiniteState,
        FaultKind::ForceClosure => FaultCode::ForceClosureLost,
        FaultKind::Workspace => FaultCode::WorkspaceViolation,
        FaultKind::Fingertip => FaultCode::FingertipViolation,
        FaultKind::Collision => FaultCode::FingertipCollision,
    }
}

impl Controller for GaitController {
    fn command(&mut self, cmd: &ControlCommand, ctx: &mut TickContext<'_>) -> Verdict {
        if self.safe_hold_requested {
            return Verdict::Rejected(ReasonCode::ShuttingDown);
        }
        let answer = match *cmd {
            ControlCommand::Goal(g) => {
                let id = self.next_goal;
                self.next_goal += 1;
                self.goals[(id as usize) % GOAL_SLOTS] = (id, g.client_id, g.goal_id);
                let object = self.exec.setpoint().state.object;
                let target = match g.target {
                    GoalTarget::Absolute(q) => executor::GoalTarget::Orientation(q),
                    GoalTarget::Relative(q) => executor::GoalTarget::Orientation(q * object),
                    GoalTarget::Rotation { axis, angle } => {
                        executor::GoalTarget::Rotation { axis, angle }
                    }
                };
                self.targets[(id as usize) % GOAL_SLOTS] = Some(target);
                self.exec.command(Command::Goal {
                    id,
                    target,
                    limits: Some(g.limits),
                })
            }
            ControlCommand::Cancel { goal_id, .. } => {
                let active = self.exec.report().goal;
                let matches = goal_id == 0
                    || active.is_some_and(|(id, s, _)| {
                        !s.is_terminal() && self.wire_goal(id).1 == goal_id
                    });
                if !matches {
                    return Verdict::Rejected(ReasonCode::UnknownGoalId);
                }
                self.exec.command(Command::Cancel)
            }
            ControlCommand::Hold { client_id } => {
                let mut e = shm_schema::Event::new(EventKind::Hold);
                e.client_id = client_id;
                e.reason = ReasonCode::HoldRequested.code();
                ctx.events.push(e);
                self.exec.command(Command::Hold)
            }
            ControlCommand::Reset { .. } => {
                if self.exec.phase() != executor::Phase::SafeHold {
                    return Verdict::Rejected(ReasonCode::NotFaulted);
                }
                self.exec.command(Command::Reset)
            }
        };
        self.forward_events(ctx, self.exec.report().remaining_angle);
        match answer {
            executor::Answer::Accepted => Verdict::Accepted,
            executor::Answer::Rejected(Reason::None) => Verdict::Rejected(ReasonCode::NoActiveGoal),
            executor::Answer::Rejected(r) => Verdict::Rejected(reason_code(r)),
        }
    }

    fn tick(&mut self, ctx: &mut TickContext<'_>, out: &mut ControlOutput) {
        self.pump_planner();
        let m = self.plant.read();
        let r = *self.exec.tick(m.as_ref());
        self.plant.write(&r.setpoint);
        self.pump_planner();
        self.forward_events(ctx, r.remaining_angle);
        self.record_trace(&r);
        self.output(&r, out);
    }

    fn begin_safe_hold(&mut self, ctx: &mut TickContext<'_>) {
        self.safe_hold_requested = true;
        self.exec.command(Command::Hold);
        self.forward_events(ctx, self.exec.report().remaining_angle);
    }

    fn at_rest(&self) -> bool {
        let v = self.exec.setpoint();
        matches!(
            self.exec.phase(),
            executor::Phase::Holding | executor::Phase::Planning | executor::Phase::SafeHold
        ) && v.finger_velocity.iter().all(|x| *x == Vector3::zeros())
    }
}

//! The real controller: the planner, the executor and the plant behind
//! the daemon's [`Controller`] seam (SPEC §6, §7.2).
//!
//! Per tick, on the loop thread: read the plant, drain the planner's
//! replies into the executor, tick the executor, write the setpoint to the
//! plant, turn the executor's events into wire events, and report. Plans
//! are made on the planner thread ([`GaitPlanner`]); the executor hands
//! back every plan it no longer needs and [`plan_link`] retires it to the
//! planner thread, so nothing is allocated or freed here.
//!
//! - [`goal_ids`]: executor goal ids ↔ the clients' (client, goal) ids;
//! - [`plan_link`]: plan requests out, plans in, old plans back;
//! - `events`: executor events → wire events;
//! - `report`: the tick's report → the status's controller output;
//! - [`codes`]: executor enums → wire codes;
//! - `trace`: goal traces from the loop side.

pub mod codes;
mod control_output;
pub mod goal_ids;
pub mod hand_planner;
pub mod plan_link;
mod trace_recording;
mod wire_events;

use crate::control::controller::{
    ClientTarget, ControlCommand, ControlOutput, Controller, MeasuredReport, TickContext,
};
use crate::control::plan_thread::{BackgroundPlanner, PlannerLink, Wanted};
use crate::io::plan_paths::PathPublisher;
use crate::io::tracer::{PlanNote, PlanNotes, TraceRecorder};
use crate::plant::external::ExternalPlant;
use crate::plant::{Hand, PlantSample};
use crate::sys::clock::Nanos;
use codes::reason_code;
use gait::executor::TickReport;
use gait::executor::feedback::NOT_A_FINGER;
use gait::executor::{self, Executor, ExecutorCommand, FaultKind, PlanRequest, Reason};
use gait::planner::GoalPlanner;
use gait::planner::chains::ChainHand;
use gait::planner::gaiting::GaitTracker;
use gait::planner::{Budget, Halt, Plan, PlanError, Stop};
use gait::sim::{KinematicHand, Measurement, Plant};
use gait::{HandConfig, HandState};
use goal_ids::GoalIds;
use hand_planner::HandPlanner;
use nalgebra::Vector3;
use plan_link::PlanShuttle;
use shm_schema::{
    EventKind, FingerPhase, GoalState, PlantFault, PlantFingerMode, ReasonCode, Verdict,
    command_flags,
};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Plans on the planner thread (SPEC §4), timed with each goal's limits,
/// within the configured budget: `planner.max_expansions` always, and in
/// real time `planner.budget_ms` of wall clock too (a lockstep run plans
/// on expansions alone, so that it is reproducible bit for bit); a goal
/// canceled or preempted while planned stops its planning at once.
#[derive(Debug)]
pub struct GaitPlanner {
    planner: HandPlanner,
    budget: Option<Duration>,
    notes: Option<Arc<PlanNotes>>,
    /// Where each plan's path goes (the `plan` service), if anywhere.
    paths: Option<PathPublisher>,
    /// The state to prepare planning from, before the first request.
    prepare_from: Option<HandState>,
}

impl GaitPlanner {
    /// `planner`, with a wall-clock budget per request or none.
    pub fn new(planner: impl Into<HandPlanner>, budget: Option<Duration>) -> Self {
        Self {
            planner: planner.into(),
            budget,
            notes: None,
            paths: None,
            prepare_from: None,
        }
    }

    /// Before its first request, the planner thread does what planning
    /// from `start` begins with and the goal does not change
    /// ([`HandPlanner::prepare`]).
    pub fn prepare_from(&mut self, start: HandState) {
        self.prepare_from = Some(start);
    }

    /// From now on each plan's route, effort and planning time is noted
    /// in `notes` (for the goal's trace header).
    pub fn keep_notes(&mut self, notes: Arc<PlanNotes>) {
        self.notes = Some(notes);
    }

    /// From now on each plan's path is published with `paths`, for views.
    pub fn publish_paths(&mut self, paths: PathPublisher) {
        self.paths = Some(paths);
    }
}

/// A plan request as the planner thread gets it: the executor's, and the
/// client's (client id, goal id) of its goal, which the plan's published
/// path names.
#[derive(Debug, Clone, Copy)]
pub struct GoalPlanRequest {
    /// The executor's request.
    pub request: PlanRequest,
    /// The goal's client and the client's goal id (`(0, 0)`: none known).
    pub wire: (u64, u64),
}

/// The gait controller's link to its planner thread.
pub type GaitPlannerLink = PlannerLink<GoalPlanRequest, Plan, PlanError>;

/// The planner's stop: the request is no longer wanted, or its wall-clock
/// budget is spent.
struct Deadline<'a> {
    until: Option<Instant>,
    wanted: &'a Wanted,
}

impl Stop for Deadline<'_> {
    fn poll(&mut self) -> Option<Halt> {
        if !self.wanted.still() {
            return Some(Halt::Canceled);
        }
        match self.until {
            Some(t) if Instant::now() >= t => Some(Halt::OutOfBudget),
            _ => None,
        }
    }
}

impl BackgroundPlanner for GaitPlanner {
    type Request = GoalPlanRequest;
    type Plan = Plan;
    type Error = PlanError;
    fn idle(&mut self) {
        if let Some(paths) = &self.paths {
            paths.connect_late_joiners();
        }
    }

    fn prepare(&mut self) {
        if let Some(start) = self.prepare_from.take() {
            let t = Instant::now();
            self.planner.prepare(&start);
            tracing::info!(
                ms = t.elapsed().as_secs_f64() * 1e3,
                "planner prepared for the start state"
            );
        }
    }
    fn plan(&mut self, goal: &GoalPlanRequest, wanted: &Wanted) -> Result<Plan, PlanError> {
        let r = &goal.request;
        let mut stop = Deadline {
            until: self.budget.map(|b| Instant::now() + b),
            wanted,
        };
        let started = Instant::now();
        let mut budget = Budget::new(self.planner.config().planner.max_expansions, &mut stop);
        let plan = r.plan_within(&self.planner, &mut budget);
        if let (Some(notes), Ok(p)) = (&self.notes, &plan) {
            notes.add(PlanNote {
                goal: r.goal,
                route: p.route.to_string(),
                effort: p.summary.effort,
                planning_ms: started.elapsed().as_secs_f64() * 1e3,
            });
        }
        if let (Some(paths), Ok(p)) = (&mut self.paths, &plan) {
            paths.publish(p, r.dt, goal.wire);
        }
        plan
    }
}

/// The daemon's controller (module docs).
pub struct GaitController {
    exec: Executor,
    hand: Hand,
    /// This tick's reading of the external plant, taken in
    /// [`Controller::feed_plant`] (before the tick's commands, so that a
    /// goal arriving with the plant's first measurement finds the hand
    /// started).
    reading: Option<(Option<Measurement>, bool)>,
    /// The plant's own fault code of the last `PlantFault` (for the event).
    plant_fault: PlantFault,
    /// The setpoints describe where the external plant really is: its
    /// state was taken (first measurement, or a reset after it was lost),
    /// so commands may enable it. A plant that comes back after a loss may
    /// be anywhere: it is not enabled again before a reset.
    plant_enabled: bool,
    planning: PlanShuttle,
    ids: GoalIds,
    /// Recognises substitutions and rewinds in the finished steps.
    gaits: GaitTracker,
    safe_hold_requested: bool,
    /// The configured workspace margin \[rad\] (0 on a chain hand).
    workspace_margin: f64,
    /// Whether the hand is a chain hand.
    chains: bool,
    /// The last fresh measurement, the tick it was read at and the
    /// setpoint it answers.
    measured: Option<MeasuredReport>,
    /// The joints of this tick's reading (a joint-level plant's).
    measured_joints: Option<[Vector3<f64>; 3]>,
    /// The commanded hand state of the last [`executor::WRITTEN`] ticks,
    /// a ring (allocated once): a measurement answers the one written
    /// `age` ticks before the last.
    sent: Box<[HandState]>,
    /// Where the next tick's commanded state goes in `sent`.
    sent_next: usize,
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
    /// The embedded kinematic hand at the paper's start grasp, ticking
    /// every `dt`; plans go through `link`.
    pub fn new(
        config: &HandConfig,
        dt: f64,
        link: GaitPlannerLink,
    ) -> Result<Self, gait::ConfigError> {
        Self::embedded_hand(config, None, HandState::paper_start(config), dt, link)
    }

    /// The embedded kinematic hand at `start`: the free fingertips of
    /// `config`, or the chain hand `chains` (SPEC §14; `config` as its
    /// model sets it), every tick checked against its limits.
    pub fn embedded_hand(
        config: &HandConfig,
        chains: Option<ChainHand>,
        start: HandState,
        dt: f64,
        link: GaitPlannerLink,
    ) -> Result<Self, gait::ConfigError> {
        let hand = Hand::Embedded(KinematicHand::new(start, dt));
        Self::with_hand(config, chains, start, dt, (link, hand))
    }

    /// An external plant over `plant`'s link: nothing moves until its
    /// first valid measurement, which becomes the start state if it
    /// satisfies every invariant (SPEC §1.3; else the fault says which is
    /// broken). The hand: free fingertips, or the chain hand `chains`
    /// (`plant` then reads and commands its joints,
    /// [`ExternalPlant::with_joints`]), until then at `start`.
    pub fn new_external(
        config: &HandConfig,
        (chains, start): (Option<ChainHand>, HandState),
        dt: f64,
        link: GaitPlannerLink,
        plant: ExternalPlant,
    ) -> Result<Self, gait::ConfigError> {
        let lockstep = plant.lockstep();
        let mut c = Self::with_hand(config, chains, start, dt, (link, Hand::External(plant)))?;
        if lockstep {
            c.planning.deliver_deterministically();
        }
        c.exec.await_plant();
        // (The waiting fault is the status's, not an event.)
        while c.exec.pop_event().is_some() {}
        Ok(c)
    }

    fn with_hand(
        config: &HandConfig,
        chains: Option<ChainHand>,
        start: HandState,
        dt: f64,
        (link, hand): (GaitPlannerLink, Hand),
    ) -> Result<Self, gait::ConfigError> {
        Ok(Self {
            exec: Executor::for_hand(config, chains.clone(), dt, start)?,
            hand,
            reading: None,
            plant_fault: PlantFault::None,
            plant_enabled: false,
            planning: PlanShuttle::new(link),
            ids: GoalIds::new(),
            gaits: GaitTracker::new(),
            safe_hold_requested: false,
            // On chains the slack is already against the joint limits.
            workspace_margin: if chains.is_some() {
                0.0
            } else {
                config.model.workspace_margin_deg.to_radians()
            },
            chains: chains.is_some(),
            measured: None,
            measured_joints: None,
            sent: vec![start; executor::WRITTEN].into_boxed_slice(),
            sent_next: 0,
            trace: None,
            trace_end: None,
        })
    }

    /// The executor's phase.
    pub fn phase(&self) -> executor::Mode {
        self.exec.phase()
    }

    /// The commanded hand state: where the next goal is planned from.
    pub fn state(&self) -> HandState {
        self.exec.setpoint().state
    }

    /// Plans leaked because they could not be handed back to the planner
    /// thread (expected 0: see [`PlanShuttle::retire`]).
    pub fn leaked_plans(&self) -> u64 {
        self.planning.leaked()
    }

    /// The embedded hand, if that is the plant (tests inject faults
    /// through it).
    pub fn embedded_mut(&mut self) -> Option<&mut KinematicHand> {
        match &mut self.hand {
            Hand::Embedded(h) => Some(h),
            Hand::External(_) => None,
        }
    }

    /// The embedded hand, if that is the plant.
    pub fn embedded(&self) -> Option<&KinematicHand> {
        match &self.hand {
            Hand::Embedded(h) => Some(h),
            Hand::External(_) => None,
        }
    }

    /// Whether the controller waits for an external plant's first valid
    /// measurement.
    pub fn awaiting_plant(&self) -> bool {
        self.exec.awaiting_plant()
    }

    /// This tick's measurement: the embedded hand's, or the external
    /// plant's (fresh or held) with its faults handed to the executor and,
    /// while waiting for the plant, the start from its first valid state.
    /// Returns it and whether it is fresh (not held).
    fn read_plant(&mut self, sample: &PlantSample, now: Nanos) -> (Option<Measurement>, bool) {
        match &mut self.hand {
            Hand::Embedded(h) => (h.read(), true),
            Hand::External(x) => {
                let r = x.read(sample, now);
                self.measured_joints = r.joints;
                if let Some(f) = r.fault {
                    self.plant_fault = f.code;
                    self.exec
                        .plant_fault(f.kind, f.finger.unwrap_or(NOT_A_FINGER));
                    if f.kind == FaultKind::PlantLost {
                        self.plant_enabled = false;
                    }
                }
                if r.fresh
                    && let Some(m) = &r.measurement
                    && self.exec.start_from(m)
                {
                    self.plant_enabled = true;
                }
                let m = r
                    .measurement
                    .filter(|_| r.fresh || !self.exec.awaiting_plant());
                (m, r.fresh)
            }
        }
    }

    /// The commanded hand state written `age` ticks before the last one
    /// (0: the last; the oldest kept beyond the ring).
    fn sent_before(&self, age: u32) -> HandState {
        let n = self.sent.len();
        let age = (age as usize).min(n - 1);
        self.sent[(self.sent_next + 2 * n - 1 - age) % n]
    }

    /// Writes this tick's setpoint: the embedded hand applies it; an
    /// external plant gets a command (pose, velocities, mode and grip per
    /// finger, flags), handed to the loop in `out`.
    fn write_plant(&mut self, r: &TickReport, out: &mut ControlOutput) {
        match &mut self.hand {
            Hand::Embedded(h) => h.write(&r.setpoint),
            Hand::External(x) => {
                let modes = out.fingers.map(|f| match f.phase {
                    FingerPhase::Grasping | FingerPhase::Rolling => PlantFingerMode::Grasping,
                    FingerPhase::Lifting => PlantFingerMode::Lifting,
                    FingerPhase::Placing => PlantFingerMode::Placing,
                    FingerPhase::Free => PlantFingerMode::Free,
                });
                let mut flags = 0;
                if self.plant_enabled {
                    flags |= command_flags::ENABLE;
                }
                if self.exec.phase() == executor::Mode::SafeHold {
                    flags |= command_flags::HOLD;
                }
                if x.lockstep() {
                    flags |= command_flags::LOCKSTEP;
                }
                out.plant_command = Some(x.command(
                    &r.setpoint,
                    &modes,
                    (&r.grip, &r.grip_force),
                    &r.joints,
                    flags,
                ));
            }
        }
    }
}

impl Controller for GaitController {
    fn command(&mut self, cmd: &ControlCommand, ctx: &mut TickContext<'_>) -> Verdict {
        if self.safe_hold_requested {
            return Verdict::Rejected(ReasonCode::ShuttingDown);
        }
        let answer = match *cmd {
            ControlCommand::Goal(g) => {
                let object = self.exec.setpoint().state.object;
                let target = match g.target {
                    ClientTarget::Absolute(q) => executor::GoalTarget::Orientation(q),
                    ClientTarget::Relative(q) => executor::GoalTarget::Orientation(q * object),
                    ClientTarget::Rotation { axis, angle } => {
                        executor::GoalTarget::Rotation { axis, angle }
                    }
                };
                let id = self.ids.assign(g.client_id, g.goal_id, target);
                self.exec.command(ExecutorCommand::Goal {
                    id,
                    target,
                    limits: Some(g.limits),
                })
            }
            ControlCommand::Cancel { goal_id, .. } => {
                let active = self.exec.report().goal;
                let matches = goal_id == 0
                    || active.is_some_and(|(id, s, _)| {
                        !s.is_terminal() && self.ids.wire(id).1 == goal_id
                    });
                if !matches {
                    return Verdict::Rejected(ReasonCode::UnknownGoalId);
                }
                self.exec.command(ExecutorCommand::Cancel)
            }
            ControlCommand::Hold { client_id } => {
                let mut e = shm_schema::Event::new(EventKind::Hold);
                e.client_id = client_id;
                e.reason = ReasonCode::HoldRequested.code();
                ctx.events.push(e);
                self.exec.command(ExecutorCommand::Hold)
            }
            ControlCommand::Reset { .. } => {
                if self.exec.phase() != executor::Mode::SafeHold {
                    return Verdict::Rejected(ReasonCode::NotFaulted);
                }
                // An external plant: only on a measurement read in this
                // very tick (held or fresh), never on the last one from
                // before the plant was lost, nor between ticks.
                let measured_now = matches!(self.reading, Some((Some(_), _)));
                if matches!(self.hand, Hand::External(_)) && !measured_now {
                    return Verdict::Rejected(ReasonCode::NoFreshMeasurement);
                }
                let a = self.exec.command(ExecutorCommand::Reset);
                // The state is the measured one again: the plant may follow.
                if a == executor::ExecutorAnswer::Accepted {
                    self.plant_enabled = true;
                }
                a
            }
        };
        self.forward_events(ctx, self.exec.report().remaining_angle);
        match answer {
            executor::ExecutorAnswer::Accepted => Verdict::Accepted,
            executor::ExecutorAnswer::Rejected(Reason::None) => {
                Verdict::Rejected(ReasonCode::NoActiveGoal)
            }
            executor::ExecutorAnswer::Rejected(r) => Verdict::Rejected(reason_code(r)),
        }
    }

    fn awaits_plan(&self) -> bool {
        self.planning.awaits_reply()
    }

    fn tick(&mut self, ctx: &mut TickContext<'_>, out: &mut ControlOutput) {
        self.planning.pump(&mut self.exec, &self.ids, true);
        let (m, fresh) = match self.reading.take() {
            Some(r) => r,
            None => self.read_plant(&PlantSample::default(), ctx.now),
        };
        if let Some(m) = m
            && fresh
        {
            self.measured = Some(MeasuredReport {
                measurement: m,
                tick: ctx.tick,
                answers: self.sent_before(m.age),
                joints: self.measured_joints,
            });
        }
        let r = *self.exec.tick(m.as_ref());
        self.planning.pump(&mut self.exec, &self.ids, false);
        self.forward_events(ctx, r.remaining_angle);
        self.record_trace(&r);
        self.output(&r, out);
        self.write_plant(&r, out);
        self.sent[self.sent_next] = r.setpoint.state;
        self.sent_next = (self.sent_next + 1) % self.sent.len();
    }

    fn feed_plant(&mut self, sample: &PlantSample, now: Nanos) {
        self.reading = Some(self.read_plant(sample, now));
    }

    fn begin_safe_hold(&mut self, ctx: &mut TickContext<'_>) {
        self.safe_hold_requested = true;
        self.exec.command(ExecutorCommand::Hold);
        self.forward_events(ctx, self.exec.report().remaining_angle);
    }

    fn at_rest(&self) -> bool {
        let v = self.exec.setpoint();
        matches!(
            self.exec.phase(),
            executor::Mode::Holding | executor::Mode::Planning | executor::Mode::SafeHold
        ) && v.finger_velocity.iter().all(|x| *x == Vector3::zeros())
    }
}

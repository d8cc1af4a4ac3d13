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
mod events;
pub mod goal_ids;
pub mod plan_link;
mod report;
mod trace;

use crate::control::controller::{
    ControlCommand, ControlOutput, Controller, GoalTarget, TickContext,
};
use crate::control::planner::{Planner, PlannerLink};
use crate::io::tracer::TraceRecorder;
use codes::reason_code;
use gait::executor::{self, Command, Executor, PlanRequest, Reason};
use gait::gaiting::GaitTracker;
use gait::planner::{Plan, PlanError};
use gait::sim::{KinematicHand, Measurement, Plant};
use gait::{HandConfig, HandState};
use goal_ids::GoalIds;
use nalgebra::Vector3;
use plan_link::PlanShuttle;
use shm_schema::{EventKind, GoalState, ReasonCode, Verdict};

/// Plans on the planner thread (SPEC §4), timed with each goal's limits.
#[derive(Debug)]
pub struct GaitPlanner(pub gait::planner::Planner);

impl Planner for GaitPlanner {
    type Request = PlanRequest;
    type Plan = Plan;
    type Error = PlanError;
    fn plan(&mut self, r: &PlanRequest) -> Result<Plan, PlanError> {
        r.plan(&self.0)
    }
}

/// The daemon's controller (module docs).
pub struct GaitController {
    exec: Executor,
    plant: KinematicHand,
    planning: PlanShuttle,
    ids: GoalIds,
    /// Recognises substitutions and rewinds in the finished steps.
    gaits: GaitTracker,
    safe_hold_requested: bool,
    /// The configured workspace margin \[rad\].
    workspace_margin: f64,
    /// The last measurement and the tick it was read at.
    measured: Option<(Measurement, u64)>,
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
        link: PlannerLink<PlanRequest, Plan, PlanError>,
    ) -> Result<Self, gait::ConfigError> {
        let start = HandState::paper_start(config);
        Ok(Self {
            exec: Executor::new(config, dt, start)?,
            plant: KinematicHand::new(start, dt),
            planning: PlanShuttle::new(link),
            ids: GoalIds::new(),
            gaits: GaitTracker::new(),
            safe_hold_requested: false,
            workspace_margin: config.model.workspace_margin_deg.to_radians(),
            measured: None,
            trace: None,
            trace_end: None,
        })
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
    /// thread (expected 0: see [`PlanShuttle::retire`]).
    pub fn leaked_plans(&self) -> u64 {
        self.planning.leaked()
    }

    /// The embedded plant (tests inject faults through it).
    pub fn plant_mut(&mut self) -> &mut KinematicHand {
        &mut self.plant
    }

    /// The embedded plant.
    pub fn plant(&self) -> &KinematicHand {
        &self.plant
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
                    GoalTarget::Absolute(q) => executor::GoalTarget::Orientation(q),
                    GoalTarget::Relative(q) => executor::GoalTarget::Orientation(q * object),
                    GoalTarget::Rotation { axis, angle } => {
                        executor::GoalTarget::Rotation { axis, angle }
                    }
                };
                let id = self.ids.assign(g.client_id, g.goal_id, target);
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
                        !s.is_terminal() && self.ids.wire(id).1 == goal_id
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
        self.planning.pump(&mut self.exec);
        let m = self.plant.read();
        if let Some(m) = m {
            self.measured = Some((m, ctx.tick));
        }
        let r = *self.exec.tick(m.as_ref());
        self.plant.write(&r.setpoint);
        self.planning.pump(&mut self.exec);
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

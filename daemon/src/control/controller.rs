//! The seam between the daemon and the controller that moves the hand.
//!
//! The daemon owns time, IPC, statistics and shutdown; a [`Controller`]
//! owns the hand: it takes validated commands, advances one tick at a time
//! and reports what it did in a [`ControlOutput`]. The daemon runs the
//! [`GaitController`](crate::control::gait_controller::GaitController)
//! (planner + trajectory generator + plant); tests also use a still one.
//!
//! Contract (copper-rs `CuTask` phases): every method runs on the real-time
//! loop thread, so it must not allocate, free, block, sleep, log or do I/O
//! other than its plant; planning goes through a
//! [`PlannerLink`](crate::control::plan_thread::PlannerLink). Per tick the loop calls
//! [`Controller::command`] for each command that arrived (in order), then
//! [`Controller::tick`] exactly once.

use crate::control::tick_events::TickEvents;
use crate::sys::clock::Nanos;
use gait::HandState;
use gait::config::LimitsConfig;
use gait::sim::Measurement;
use nalgebra::{UnitQuaternion, Vector3};
use shm_schema::{
    FaultCode, FingerPhase, GoalState, GraspState, Phase, PlantCommand, ReasonCode, Verdict,
};

/// A goal's target as the client asked for it (decoded from the schema's
/// `GoalFrame`); the controller resolves it into the executor's
/// `gait::executor::GoalTarget` (a relative target against the object).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ClientTarget {
    /// The object orientation q_o to reach (object → hand frame).
    Absolute(UnitQuaternion<f64>),
    /// A rotation (hand frame) applied to the orientation at acceptance:
    /// q_goal = q_rel · q_o.
    Relative(UnitQuaternion<f64>),
    /// Turn by `angle` about the hand-frame `axis` (any angle: a full turn
    /// is a full turn) from the orientation when planning starts.
    Rotation {
        /// Unit axis.
        axis: Vector3<f64>,
        /// Angle \[rad\].
        angle: f64,
    },
}

/// A reorientation goal that passed every check the daemon can make.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Goal {
    /// Sending client.
    pub client_id: u64,
    /// Goal id, unique for this client.
    pub goal_id: u64,
    /// Target, renormalised.
    pub target: ClientTarget,
    /// Effective motion limits: the configured ones with the goal's
    /// overrides applied (each override ≤ the configured limit).
    pub limits: LimitsConfig,
}

/// A command for the controller (SPEC §6.4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlCommand {
    /// Reorient; preempts the active goal.
    Goal(Goal),
    /// Stop the active goal (`goal_id` 0 = whichever is active), then hold.
    Cancel {
        /// Sender.
        client_id: u64,
        /// Goal to cancel, 0 = active.
        goal_id: u64,
    },
    /// Stop any motion and hold.
    Hold {
        /// Sender.
        client_id: u64,
    },
    /// Clear a fault.
    Reset {
        /// Sender.
        client_id: u64,
    },
}

/// Per-tick context handed to the controller.
#[derive(Debug)]
pub struct TickContext<'a> {
    /// This tick's wake-up time.
    pub now: Nanos,
    /// Tick counter.
    pub tick: u64,
    /// Events to publish at the end of this tick.
    pub events: &'a mut TickEvents,
}

/// The current goal, for the status.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoalReport {
    /// Goal id, 0 = none yet.
    pub goal_id: u64,
    /// Its client.
    pub client_id: u64,
    /// Lifecycle state.
    pub state: GoalState,
    /// Reason (terminal states).
    pub reason: ReasonCode,
    /// Angle still to rotate \[rad\].
    pub remaining_angle: f64,
    /// Estimated time to completion \[s\], if known.
    pub eta: Option<f64>,
    /// Gaits completed.
    pub gaits_done: u32,
    /// Gaits planned.
    pub gaits_planned: u32,
    /// Finger moved by the current primitive.
    pub active_finger: Option<usize>,
}

impl Default for GoalReport {
    fn default() -> Self {
        Self {
            goal_id: 0,
            client_id: 0,
            state: GoalState::None,
            reason: ReasonCode::None,
            remaining_angle: 0.0,
            eta: None,
            gaits_done: 0,
            gaits_planned: 0,
            active_finger: None,
        }
    }
}

/// Per-finger data the hand state alone does not give.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FingerOutput {
    /// Finger state.
    pub phase: FingerPhase,
    /// Angle to the workspace cone boundary, > 0 inside \[rad\].
    pub workspace_margin: f64,
    /// Intended normal force \[N\] (0 when not in contact or unknown).
    pub normal_force: f64,
    /// A chain hand's commanded joints \[rad\] (`None`: free fingertips,
    /// or no branch reaches the tip).
    pub joints: Option<Vector3<f64>>,
    /// The commanded contact's margin on the fingertip \[rad\] (0 when
    /// not touching).
    pub tip_margin: f64,
    /// A chain hand's links off the object beyond the clearance \[m\].
    pub link_clearance: Option<f64>,
}

impl FingerOutput {
    /// A finger in `phase` with nothing else known.
    pub fn bare(phase: FingerPhase) -> Self {
        Self {
            phase,
            workspace_margin: 0.0,
            normal_force: 0.0,
            joints: None,
            tip_margin: 0.0,
            link_clearance: None,
        }
    }
}

/// A measurement as the status reports it, with the setpoint it answers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredReport {
    /// What the plant measured.
    pub measurement: Measurement,
    /// The tick it was read at.
    pub tick: u64,
    /// The commanded hand state of the setpoint it answers (written
    /// `measurement.age` setpoints before the last one before `tick`): the
    /// status's tracking errors compare with it, not with this tick's
    /// setpoint, which the plant has not received yet.
    pub answers: HandState,
    /// A chain hand's measured joints, where its plant measures them.
    pub joints: Option<[Vector3<f64>; 3]>,
}

/// What the controller reports after each tick (in maths types; the
/// daemon converts it to the wire format in one place, `convert`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlOutput {
    /// The commanded hand and object state (the setpoint just written).
    pub hand: HandState,
    /// Commanded object angular velocity, hand frame [rad/s].
    pub object_omega: Vector3<f64>,
    /// What the plant measured, the tick it was read at and the setpoint
    /// it answers (`None`: no measurement yet). Reported beside the
    /// command, never in its place.
    pub measured: Option<MeasuredReport>,
    /// Controller phase.
    pub phase: Phase,
    /// Current fault.
    pub fault: FaultCode,
    /// Current goal and progress.
    pub goal: GoalReport,
    /// Per-finger extras.
    pub fingers: [FingerOutput; gait::FINGERS],
    /// Whether the hand is a chain hand (its fingers have joints).
    pub chains: bool,
    /// Force closure of the grasping fingers.
    pub grasp: GraspState,
    /// Force-closure margin \[rad\] (0 when unknown).
    pub grasp_margin: f64,
    /// The largest normal force the grasp needs to hold the load (F*,
    /// SPEC §1.3 I1') \[N\]; +∞ when none does.
    pub load_grip: f64,
    /// `load.max_grip` − `load_grip` \[N\]: negative when the grasp cannot
    /// hold the load within the force limit.
    pub load_margin: f64,
    /// The command for an external plant (the loop hands it to the writer
    /// first; `None` with the embedded hand).
    pub plant_command: Option<PlantCommand>,
}

/// A controller the daemon's loop drives. See the module docs for the
/// real-time contract.
pub trait Controller {
    /// Handles one command that passed validation and the daemon's checks
    /// (duplicate ids, limits). Returns the immediate answer; state changes
    /// and goal transitions go into `ctx.events`.
    fn command(&mut self, cmd: &ControlCommand, ctx: &mut TickContext<'_>) -> Verdict;

    /// Advances one tick: read the plant, advance the motion, write
    /// setpoints, check invariants, fill `out`.
    fn tick(&mut self, ctx: &mut TickContext<'_>, out: &mut ControlOutput);

    /// Shutdown was requested: bring any motion smoothly to rest and hold
    /// the grasp (SPEC §7.1). The loop keeps calling [`Controller::tick`]
    /// until [`Controller::at_rest`] or its shutdown timeout.
    fn begin_safe_hold(&mut self, ctx: &mut TickContext<'_>);

    /// Whether the hand is still (no motion in progress).
    fn at_rest(&self) -> bool;

    /// What the loop received from an external plant for the coming tick,
    /// at `now`: called first in the tick, before its commands (the
    /// embedded hand needs none).
    fn feed_plant(&mut self, _sample: &crate::plant::PlantSample, _now: Nanos) {}

    /// Lockstep: whether the next tick must wait for a plan in flight, so
    /// that every plan arrives at the same tick in every run. The loop then
    /// holds the plant's measurement and waits between ticks (heartbeats
    /// and the watchdog go on), not inside one: a tick's compute time never
    /// includes planning.
    fn awaits_plan(&self) -> bool {
        false
    }
}

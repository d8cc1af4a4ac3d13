"""The payloads, codes and constants of the gaitd shared-memory schema v8, for ctypes.

Generated from the ``shm_schema`` crate (``shm_schema/src/layout/python.rs``) by
``cargo test -p shm_schema`` (set ``GAITD_BLESS=1`` to rewrite it); a test fails when this
file and the code disagree, so edit the Rust code, not this file. ``shm_schema/LAYOUT.md``
is generated from the same code; :mod:`gaitd.schema` adds the helpers and the check
against that document.
"""

from __future__ import annotations

import ctypes
import enum
from typing import ClassVar

#: Version of the payload layout (part of every type name).
SCHEMA_VERSION = 8
#: The iceoryx2 release the daemon is built with; resource names are
#: version-tagged, so the Python bindings must be exactly this version.
ICEORYX2_VERSION = "0.10.0"
#: Default service-name prefix.
DEFAULT_PREFIX = "gaitd"
#: Fingers of the hand (f1, f2, f3).
FINGERS = 3
#: Most joints a finger's plant command and measurement carry.
MAX_JOINTS = 4
#: ``active_finger`` / ``finger`` value meaning "no finger".
NO_FINGER = 0xFFFFFFFF
#: Attribute of the ``version`` service: the daemon's schema version (decimal).
VERSION_ATTRIBUTE_SCHEMA = "gaitd.schema"
#: Attribute of the ``version`` service: the daemon's build.
VERSION_ATTRIBUTE_BUILD = "gaitd.build"

u32 = ctypes.c_uint32
u64 = ctypes.c_uint64
f64 = ctypes.c_double

# --------------------------------------------------------------------------- payloads


class Payload(ctypes.Structure):
    """A payload of the schema: a ctypes structure with its iceoryx2 type name."""

    #: The iceoryx2 type name (must equal the Rust ``#[type_name]``).
    _type_name: ClassVar[str] = ""

    @classmethod
    def type_name(cls) -> str:
        """The iceoryx2 type name, which iceoryx2 compares with the daemon's."""
        return cls._type_name


class MotionLimits(Payload):
    """Velocity, acceleration and jerk limit overrides of one motion kind."""

    _type_name = "gaitd::MotionLimits.v8"
    _fields_ = [
        # unit/s: velocity limit, > 0 when set
        ("velocity", f64),
        # unit/s²: acceleration limit, > 0 when set
        ("acceleration", f64),
        # unit/s³: jerk limit, > 0 when set
        ("jerk", f64),
    ]


class Command(Payload):
    """client → daemon: a goal, cancel, hold or reset."""

    _type_name = "gaitd::Command.v8"
    _fields_ = [
        # CommandKind: what is asked
        ("kind", u32),
        # GoalFrame: goal target meaning (goals only, else 0)
        ("frame", u32),
        # sender's non-zero id
        ("client_id", u64),
        # any value, echoed in the answer
        ("request_id", u64),
        # goal id (Goal: non-zero; Cancel: 0 = active goal)
        ("goal_id", u64),
        # [w,x,y,z]: target unit quaternion (goals only)
        ("target", f64 * 4),
        # bits: set overrides: bit 3*kind+order
        ("limit_mask", u32),
        # padding, 0
        ("reserved", u32),
        # rad/s, rad/s², rad/s³: object rotation limit overrides (bits 0-2)
        ("object_limits", MotionLimits),
        # m/s, m/s², m/s³: fingertip translation limit overrides (bits 3-5)
        ("fingertip_limits", MotionLimits),
        # rad/s, rad/s², rad/s³: rolling-rate limit overrides (bits 6-8)
        ("rolling_limits", MotionLimits),
    ]


class Answer(Payload):
    """daemon → client: one per command, matched by client_id + request_id."""

    _type_name = "gaitd::Answer.v8"
    _fields_ = [
        # echo of the command's client_id
        ("client_id", u64),
        # echo of the command's request_id
        ("request_id", u64),
        # echo of the command's goal_id
        ("goal_id", u64),
        # CommandKind: echo of the command's kind (raw)
        ("command", u32),
        # AnswerCode: accepted or rejected
        ("code", u32),
        # ReasonCode: why rejected (0 when accepted)
        ("reason", u32),
        # padding, 0
        ("reserved", u32),
        # tick: daemon tick that handled the command
        ("tick", u64),
        # daemon instance id
        ("instance", u64),
    ]


class GoalStatus(Payload):
    """The current goal and its progress (part of :class:`Status`)."""

    _type_name = "gaitd::GoalStatus.v8"
    _fields_ = [
        # current or last goal, 0 = none
        ("goal_id", u64),
        # its client
        ("client_id", u64),
        # GoalState: goal state
        ("state", u32),
        # ReasonCode: reason (terminal states)
        ("reason", u32),
        # rad: rotation still to make: while the plan runs (also braking to a stop), the plan's remaining path length,
        # the sum of its rotation angles left (a full turn counts 2π; more than the angle to the goal when the plan
        # detours); before it runs: an AxisAngle goal's angle (absolute value), else the angle from the commanded
        # orientation to the target; 0 without an active goal
        ("remaining_angle", f64),
        # s: estimated time to completion, -1 = unknown
        ("eta", f64),
        # gaits completed
        ("gaits_done", u32),
        # gaits in the plan
        ("gaits_planned", u32),
        # index: finger of the current primitive, 0xFFFFFFFF = none
        ("active_finger", u32),
        # padding, 0
        ("reserved", u32),
    ]


class FingerStatus(Payload):
    """One finger in the status: commanded and measured."""

    _type_name = "gaitd::FingerStatus.v8"
    _fields_ = [
        # FingerPhase: finger state
        ("state", u32),
        # 0/1: measured contact, 1 = touching (mask bit CONTACTS)
        ("measured_contact", u32),
        # m: contact on the object surface, hand frame (0 if no contact)
        ("contact_hand", f64 * 3),
        # m: contact on the object surface, object frame (0 if no contact)
        ("contact_object", f64 * 3),
        # m: commanded fingertip centre p, hand frame
        ("commanded_tip_position", f64 * 3),
        # [w,x,y,z]: commanded fingertip orientation Q_f, fingertip → hand
        ("commanded_tip_orientation", f64 * 4),
        # unit vector: contact on the fingertip m, fingertip frame (0 if no contact)
        ("tip_contact", f64 * 3),
        # rad: commanded roll τ about the pole axis Q_f e_z (τ̇ = ω_f · Q_f e_z, 0 in the start grasp)
        ("roll", f64),
        # rad: angle to the workspace cone boundary, > 0 inside; on a chain hand the joints' margin inside their limits
        # (less the description's margin)
        ("workspace_margin", f64),
        # N: intended normal force (the plant command's `grip_force`): this finger's share of the current load (weight,
        # acceleration torque) plus the squeeze that holds every disturbance; 0 if it carries nothing
        ("commanded_normal_force", f64),
        # m: measured fingertip centre, hand frame (mask bit TIPS)
        ("measured_tip_position", f64 * 3),
        # [w,x,y,z]: measured fingertip orientation (mask bit TIPS)
        ("measured_tip_orientation", f64 * 4),
        # N: measured normal force (mask bit FORCES)
        ("measured_normal_force", f64),
        # m: distance measured → commanded fingertip centre, against the setpoint the measurement answers
        # (`Status.measured_age`) (mask bit TIPS)
        ("tip_error", f64),
        # rad: chain hand: the commanded joint positions, base to tip (0 on free fingertips)
        ("commanded_joints", f64 * 3),
        # rad: commanded contact on the fingertip to the edge of its tip patch (chains, less its margin) or hemisphere
        # (free fingertips), > 0 inside; 0 when not touching
        ("tip_margin", f64),
        # m: chain hand: the closest link's distance from the object beyond the configured clearance (0 on free
        # fingertips)
        ("link_clearance", f64),
        # rad: chain hand: the measured joint positions, base to tip (mask bit JOINTS)
        ("measured_joints", f64 * 3),
    ]


class Timing(Payload):
    """Loop timing statistics (part of :class:`Status`)."""

    _type_name = "gaitd::Timing.v8"
    _fields_ = [
        # ns: loop period
        ("period_ns", u64),
        # ns: compute time of the previous tick
        ("compute_last_ns", u64),
        # ns: compute time median since start
        ("compute_p50_ns", u64),
        # ns: compute time p99 since start
        ("compute_p99_ns", u64),
        # ns: compute time max since start
        ("compute_max_ns", u64),
        # ns: wake-up jitter of this tick
        ("jitter_last_ns", u64),
        # ns: wake-up jitter p99 since start
        ("jitter_p99_ns", u64),
        # ns: wake-up jitter max since start
        ("jitter_max_ns", u64),
        # periods: missed periods since start
        ("overruns", u64),
        # counts: bucket 0: < 1 µs; i: [2^(i-1), 2^i) µs; 15: ≥ 16.384 ms
        ("jitter_hist", u64 * 16),
        # ticks: external plant: commands that went out after their tick's deadline, since start
        ("plant_commands_late", u64),
        # steps: external plant: steps that applied the command of the step before although a newer one was sent
        ("plant_commands_repeated", u64),
        # ticks: external plant: ticks without a new measurement (the last one held)
        ("plant_measurements_late", u64),
        # external plant: measurements received again with a sequence number already taken
        ("plant_measurements_repeated", u64),
        # ticks: external plant: ticks in a row, up to this one, that missed the timing contract; faulted (PlantTiming)
        # at plant.max_misses_in_row
        ("plant_misses_in_row", u64),
        # ticks: external plant: the longest such run since start
        ("plant_misses_in_row_max", u64),
    ]


class Status(Payload):
    """daemon → clients, every tick (latest value)."""

    _type_name = "gaitd::Status.v8"
    _fields_ = [
        # tick: tick counter since start
        ("tick", u64),
        # ns: time of this tick: real time, its CLOCK_MONOTONIC wake-up; lockstep, the plant's `time_ns` of the
        # measurement it ran on (one clock per run; 0 before the plant's first measurement)
        ("time_ns", u64),
        # ns: CLOCK_MONOTONIC time just before publishing
        ("publish_time_ns", u64),
        # random id of this daemon run
        ("instance", u64),
        # DaemonState: running, or stopped (final status)
        ("daemon_state", u32),
        # Phase: controller phase
        ("phase", u32),
        # FaultCode: current fault, 0 = none
        ("fault", u32),
        # GraspState: force closure of the grasping fingers
        ("grasp", u32),
        # rad: force-closure margin, 0 when unknown
        ("grasp_margin", f64),
        # N: largest normal force a carrying finger needs, at the commanded squeeze, over every load scenario: weight,
        # acceleration torque and any disturbance of the configured size (F*, SPEC §1.3 I1'); no finger's
        # `commanded_normal_force` exceeds it; +inf when no grip holds the load
        ("load_grip", f64),
        # N: load.max_grip (a chain hand: the strongest normal push the grasping fingers' motors give, if lower) −
        # load_grip; negative when the grasp cannot hold the load
        ("load_margin", f64),
        # [w,x,y,z]: commanded object orientation q_o, object → hand (the setpoint)
        ("commanded_object_q", f64 * 4),
        # rad/s: commanded object angular velocity, hand frame
        ("commanded_object_omega", f64 * 3),
        # [w,x,y,z]: measured object orientation (mask bit OBJECT)
        ("measured_object_q", f64 * 4),
        # rad: angle from measured to commanded orientation, against the setpoint the measurement answers
        # (`measured_age`) (mask bit OBJECT)
        ("object_error", f64),
        # tick: tick the measurement was read at, 0 = none yet
        ("measured_tick", u64),
        # bits: valid measured fields: 1 OBJECT, 2 TIPS, 4 CONTACTS, 8 FORCES (a plant that reports normal forces), 16
        # JOINTS (a chain hand's plant that measures its joints); 0 before the first measurement; the embedded hand: 7
        ("measured_mask", u32),
        # commands: commands sent after the one the measurement answers: the errors compare with the setpoint of tick
        # measured_tick − 1 − measured_age
        ("measured_age", u32),
        # GoalStatus: current goal and progress
        ("goal", GoalStatus),
        # FingerStatus: fingers f1, f2, f3
        ("fingers", FingerStatus * 3),
        # Timing: loop timing
        ("timing", Timing),
        # commands received since start
        ("commands", u64),
        # commands rejected since start
        ("rejected", u64),
        # client nodes alive
        ("clients", u32),
        # 0/1: hand model: 0 free fingertips, 1 finger chains (fingers report their joints)
        ("hand", u32),
    ]


class Event(Payload):
    """daemon → clients, with history: goal transitions, gaits, faults."""

    _type_name = "gaitd::Event.v8"
    _fields_ = [
        # sequence number, from 1, no gaps
        ("seq", u64),
        # tick: tick at which it happened
        ("tick", u64),
        # ns: time of that tick (as Status.time_ns: the plant's in lockstep)
        ("time_ns", u64),
        # daemon instance id
        ("instance", u64),
        # EventKind: what happened
        ("kind", u32),
        # index: finger 0-2, 0xFFFFFFFF = none (EventKind says which kinds name one)
        ("finger", u32),
        # GoalState: new goal state (transitions)
        ("state", u32),
        # ReasonCode: reason
        ("reason", u32),
        # goal concerned, 0 = none
        ("goal_id", u64),
        # that goal's client
        ("client_id", u64),
        # FaultCode: Fault: the fault; NearLimit: the invariant
        ("fault", u32),
        # padding, 0
        ("reserved", u32),
        # Overrun: missed periods; ClientsCleaned: nodes; Drift, NearLimit: replans so far; Substitution: finger that
        # took over, as a bit; Rewind: relocated fingers as bits; Fault `PlantFault`: the plant's `PlantFault` code
        ("count", u64),
        # GoalTransition: `GoalStatus.remaining_angle` as last reported [rad] (0 for Rejected)
        ("value", f64),
    ]


class PathPoint(Payload):
    """The hand at one instant of a plan (part of :class:`PlanPath`)."""

    _type_name = "gaitd::PathPoint.v8"
    _fields_ = [
        # s: time since the plan's first tick
        ("t", f64),
        # [w,x,y,z]: object orientation (object → hand frame)
        ("object_q", f64 * 4),
        # m: fingertip sphere centres, hand frame, per finger
        ("tip_position", f64 * 3 * 3),
        # bits: bit k: finger k grasps
        ("touching", u32),
        # padding, 0
        ("reserved", u32),
    ]


class PlanPath(Payload):
    """daemon → clients: where each plan takes the hand (latest value)."""

    _type_name = "gaitd::PlanPath.v8"
    _fields_ = [
        # daemon instance id
        ("instance", u64),
        # the goal it was planned for
        ("goal_id", u64),
        # that goal's client
        ("client_id", u64),
        # plans of this instance, from 1 (a goal planned again gets a larger one)
        ("sequence", u64),
        # s: how long the plan runs (the last point's time)
        ("duration", f64),
        # points used, 1-256
        ("count", u32),
        # padding, 0
        ("reserved", u32),
        # PathPoint[256]: equal intervals from the plan's first tick to its end; past `count`: 0
        ("points", PathPoint * 256),
    ]


class PlantFingerCommand(Payload):
    """One fingertip's setpoint (part of :class:`PlantCommand`)."""

    _type_name = "gaitd::PlantFingerCommand.v8"
    _fields_ = [
        # PlantFingerMode: what the fingertip does
        ("mode", u32),
        # joints the joint fields hold, base to tip (0 on free fingertips, at most 4)
        ("joint_count", u32),
        # m: fingertip centre, hand frame (chains: relative to the object's centre O)
        ("position", f64 * 3),
        # [w,x,y,z]: fingertip orientation Q_f, fingertip → hand; pole axis Q_f e_z
        ("orientation", f64 * 4),
        # m/s: linear velocity, hand frame
        ("velocity", f64 * 3),
        # rad/s: angular velocity, hand frame
        ("angular_velocity", f64 * 3),
        # m/s²: linear acceleration feed-forward, hand frame
        ("acceleration", f64 * 3),
        # rad: commanded roll τ about the pole axis (τ̇ = ω_f · Q_f e_z, 0 in the start grasp)
        ("roll", f64),
        # N: intended normal force, 0 when not grasping
        ("grip_force", f64),
        # rad: joint position setpoints q*
        ("joint_position", f64 * 4),
        # rad/s: joint velocity setpoints q̇*
        ("joint_velocity", f64 * 4),
        # N·m: feed-forward torque τ_ff: the grip through the tip Jacobian, Jᵀf, plus the links' weight where
        # compensated
        ("joint_torque", f64 * 4),
        # N·m/rad: position gain: motor torque τ_ff + kp (q* − q) + kd (q̇* − q̇)
        ("kp", f64 * 4),
        # N·m·s/rad: velocity gain
        ("kd", f64 * 4),
    ]


class PlantCommand(Payload):
    """daemon → plant, every tick."""

    _type_name = "gaitd::PlantCommand.v8"
    _fields_ = [
        # daemon session id, random per start
        ("session", u64),
        # command sequence number, from 1, +1 each
        ("seq", u64),
        # seq of the measurement it answers, 0 = none
        ("answers", u64),
        # ns: plant time the setpoint holds at: answered time + period
        ("target_time_ns", u64),
        # ns: control period
        ("period_ns", u64),
        # bits: 1 ENABLE (without it: move nothing, still echo the command), 2 HOLD (safe hold: still, grasp kept), 4
        # LOCKSTEP, 8 JOINTS (a chain hand: follow the joint fields)
        ("flags", u32),
        # padding, 0
        ("reserved", u32),
        # [w,x,y,z]: object orientation setpoint, object → hand: what the controller wants, never to be copied into a
        # measurement
        ("object_q", f64 * 4),
        # rad/s: object angular velocity setpoint, hand frame
        ("object_omega", f64 * 3),
        # PlantFingerCommand: fingers f1, f2, f3
        ("fingers", PlantFingerCommand * 3),
    ]


class PlantFingerMeasurement(Payload):
    """One fingertip as measured (part of :class:`PlantMeasurement`)."""

    _type_name = "gaitd::PlantFingerMeasurement.v8"
    _fields_ = [
        # 0/1: 1 = touching the object
        ("contact", u32),
        # joints the joint fields hold, base to tip (chains: the hand's, 0 on free fingertips)
        ("joint_count", u32),
        # m: fingertip centre, hand frame (not read on chains: the joints give it)
        ("position", f64 * 3),
        # [w,x,y,z]: fingertip orientation, fingertip → hand
        ("orientation", f64 * 4),
        # m/s: linear velocity, hand frame
        ("velocity", f64 * 3),
        # rad/s: angular velocity, hand frame
        ("angular_velocity", f64 * 3),
        # rad: roll τ about the pole axis, as the command's
        ("roll", f64),
        # N: normal force at the contact
        ("normal_force", f64),
        # rad: joint positions
        ("joint_position", f64 * 4),
        # rad/s: joint velocities
        ("joint_velocity", f64 * 4),
        # N·m: joint torques applied, after the hand's own limits
        ("joint_torque", f64 * 4),
    ]


class PlantMeasurement(Payload):
    """plant → daemon, one per plant step."""

    _type_name = "gaitd::PlantMeasurement.v8"
    _fields_ = [
        # session of the last command applied, 0 = none yet
        ("session", u64),
        # measurement sequence number, from 1, +1 each (the daemon takes any increase)
        ("seq", u64),
        # seq of the last command applied, 0 = none
        ("applied", u64),
        # ns: sample time, plant clock: later than the last within a plant run
        ("time_ns", u64),
        # bits: valid fields: 1 object_q, 2 object_omega, 4 object_center, 8 tip pose, 16 tip velocity, 32 contact, 64
        # normal_force, 128 roll, 256 joint positions, 512 joint velocities, 1024 joint torques (required: 1, 8, 32,
        # 128; chains: 1, 32, 256)
        ("valid", u32),
        # bits: 1 SIMULATED, 2 PAUSED, 4 FAULT
        ("state", u32),
        # PlantFault: with FAULT: the plant's fault
        ("fault", u32),
        # µs: how long before time_ns the object's pose was sampled (a tracker's latency; 0: with the rest)
        ("object_age_us", u32),
        # [w,x,y,z]: object orientation, object → hand
        ("object_q", f64 * 4),
        # rad/s: object angular velocity, hand frame
        ("object_omega", f64 * 3),
        # m: object centre, hand frame
        ("object_center", f64 * 3),
        # PlantFingerMeasurement: fingers f1, f2, f3
        ("fingers", PlantFingerMeasurement * 3),
    ]


#: Every payload (the order of LAYOUT.md).
PAYLOADS: tuple[type[Payload], ...] = (
    Command,
    MotionLimits,
    Answer,
    Status,
    GoalStatus,
    FingerStatus,
    Timing,
    Event,
    PlanPath,
    PathPoint,
    PlantCommand,
    PlantFingerCommand,
    PlantMeasurement,
    PlantFingerMeasurement,
)

# --------------------------------------------------------------------------- codes


class CommandKind(enum.IntEnum):
    """What a :class:`Command` asks."""

    #: Reorient the object (SPEC §6.4); preempts the active goal.
    Goal = 1
    #: Stop the active goal smoothly, then hold.
    Cancel = 2
    #: Keep the grasp, no motion.
    Hold = 3
    #: Clear a fault and return to hold.
    Reset = 4


class GoalFrame(enum.IntEnum):
    """Meaning of a goal's target."""

    #: Target is the object orientation q_o to reach (object → hand frame).
    Absolute = 1
    #: Target is a rotation applied to the current orientation, hand frame: q_goal = q_rel · q_o.
    Relative = 2
    #: Target is `[angle, x, y, z]`: turn the object by `angle` \[rad\] about the hand-frame axis (x, y, z) from its
    #: orientation at acceptance; any angle (2π is a full turn, not a no-op).
    AxisAngle = 3


class AnswerCode(enum.IntEnum):
    """Accepted or rejected."""

    #: The command was accepted (for goals: it is now the active goal).
    Accepted = 1
    #: The command was refused; the reason code says why.
    Rejected = 2


class GoalState(enum.IntEnum):
    """Goal lifecycle (SPEC §6.4)."""

    #: No goal has been accepted yet.
    None_ = 0
    #: Accepted, waiting for the planner.
    Accepted = 1
    #: Being planned off the real-time thread.
    Planning = 2
    #: Plan is being executed.
    Executing = 3
    #: Reached the target (terminal).
    Succeeded = 4
    #: Stopped by a fault or a failed plan (terminal; reason says why).
    Aborted = 5
    #: Stopped by a cancel command (terminal).
    Canceled = 6
    #: Replaced by a newer goal (terminal).
    Preempted = 7
    #: Never started (terminal; reason says why).
    Rejected = 8

    @property
    def terminal(self) -> bool:
        """Whether the goal is over (no further transitions)."""
        return self in (
            GoalState.Succeeded,
            GoalState.Aborted,
            GoalState.Canceled,
            GoalState.Preempted,
            GoalState.Rejected,
        )


class ReasonCode(enum.IntEnum):
    """Why a command was rejected or a goal ended."""

    #: No reason (success, or nothing to report).
    None_ = 0
    #: `kind` is not a known [`CommandKind`].
    UnknownCommandKind = 1
    #: `frame` is not a known [`GoalFrame`].
    UnknownGoalFrame = 2
    #: A goal needs a non-zero `goal_id`.
    ZeroGoalId = 3
    #: `client_id` must be non-zero.
    ZeroClientId = 4
    #: The target quaternion has a NaN or infinite component.
    NonFiniteQuaternion = 5
    #: The target quaternion is (nearly) zero.
    ZeroQuaternion = 6
    #: The target quaternion's norm is not within tolerance of 1.
    NonUnitQuaternion = 7
    #: `limit_mask` has bits beyond the nine defined overrides.
    BadLimitMask = 8
    #: A limit override is NaN or infinite.
    NonFiniteLimit = 9
    #: A limit override is zero or negative.
    NonPositiveLimit = 10
    #: A field that must be zero is not (padding, unused field, unset limit).
    NonZeroReserved = 11
    #: The client already used this goal id.
    DuplicateGoalId = 12
    #: A limit override exceeds the configured limit.
    LimitAboveConfigured = 13
    #: The planner could not take the goal (its request queue was full): the accepted goal is Aborted with this reason.
    PlannerUnavailable = 14
    #: The controller is in a fault; send Reset first.
    Faulted = 15
    #: Cancel named a goal that is not the active one.
    UnknownGoalId = 16
    #: Nothing to cancel.
    NoActiveGoal = 17
    #: The daemon is shutting down.
    ShuttingDown = 18
    #: The planner's search ran out of nodes: no plan at its resolution (SPEC §4.1).
    NoPlan = 19
    #: Reset while there is no fault.
    NotFaulted = 20
    #: Replaced by a newer goal.
    PreemptedByGoal = 21
    #: Stopped by a cancel command.
    CanceledByClient = 22
    #: Stopped by a hold command.
    HoldRequested = 23
    #: Stopped because a fault was detected (see the fault code).
    FaultDetected = 24
    #: The target was reached within tolerance.
    Reached = 25
    #: An axis-angle target has a non-finite or zero axis, or a non-finite or huge (> 64π) angle.
    BadAxisAngle = 26
    #: A limit override is below the smallest allowed: 1 % of the configured limit (`MIN_LIMIT_OVERRIDE_FRACTION`).
    LimitBelowMinimum = 27
    #: No plan: the state to plan from has fewer than two grasping fingers, or they are not force-closure.
    StartNotForceClosure = 28
    #: No plan: the state to plan from holds a non-finite number.
    StartNotFinite = 29
    #: No plan: three fingers grasp, no pair is force-closure, and no roll reaches a force-closure pair.
    NoTwoFingerGrasp = 30
    #: No plan: a free finger cannot travel clear of the other fingertips (the event's `finger` names it).
    FingerBlocked = 31
    #: The goal's target is not a finite orientation or turn the planner can use.
    InvalidGoalTarget = 32
    #: Reset refused: the measured state breaks an invariant (SPEC §1.3); bring the hand back to a valid grasp first.
    MeasuredStateInvalid = 33
    #: No plan keeps the load feasible (SPEC §1.3 I1'): no sequence of grasps found holds the weight, the acceleration
    #: torque and the configured disturbance with every normal force within `load.max_grip` (also when the start grasp
    #: itself cannot).
    LoadInfeasible = 34
    #: Planning ran out of its budget (`[planner] budget_ms` of wall clock, or `max_expansions`) before it found a plan.
    PlanTimeout = 35
    #: Reset refused: no fresh valid measurement from the plant (it is lost, stalled or not started); start the plant,
    #: then reset.
    NoFreshMeasurement = 36
    #: Reset refused: the hand is still braking to rest after the fault; reset once it is still.
    NotAtRest = 37


class Phase(enum.IntEnum):
    """Controller phase."""

    #: Holding the grasp still.
    Hold = 1
    #: A fingertip rolls on the object (object still).
    Roll = 2
    #: The object rotates with the grasping fingertips.
    Rotate = 3
    #: A free finger moves through free space and makes contact.
    Place = 4
    #: A finger breaks contact and leaves to its free space.
    Lift = 5
    #: Motion being brought smoothly to rest (preemption, cancel, hold).
    Stopping = 6
    #: Safe hold after a fault.
    SafeHold = 7


class FingerPhase(enum.IntEnum):
    """A finger's state in the status."""

    #: In contact, part of the grasp.
    Grasping = 1
    #: In contact, rolling on the object.
    Rolling = 2
    #: Breaking contact, moving away along the normal.
    Lifting = 3
    #: In its free-space shell (parked or transferring).
    Free = 4
    #: Descending to make contact.
    Placing = 5


class GraspState(enum.IntEnum):
    """Force closure of the grasping fingers."""

    #: Not computed by this controller.
    Unknown = 0
    #: The grasping fingers are force-closure with margin.
    ForceClosure = 1
    #: The grasping fingers are not force-closure.
    NotForceClosure = 2


class FaultCode(enum.IntEnum):
    """The controller's fault."""

    #: No fault.
    None_ = 0
    #: Force closure lost (invariant I1).
    ForceClosureLost = 1
    #: A contact or free fingertip left its workspace (I2).
    WorkspaceViolation = 2
    #: A fingertip contact left its hemisphere or the roll limit (I3).
    FingertipViolation = 3
    #: Two fingertips too close (I4).
    FingertipCollision = 4
    #: A grasping contact slipped (I5).
    Slip = 5
    #: A plant measurement is missing.
    MeasurementMissing = 6
    #: A finger does not follow its setpoint.
    StuckFinger = 7
    #: A NaN or infinite value appeared in the state.
    NonFiniteState = 8
    #: No fresh measurement from the plant for more than `plant.max_missed` ticks (real time: or none that arrived
    #: within `plant.stale_after_ms`; lockstep: none within `plant.lockstep_timeout_ms`), or one that echoes a command
    #: more than `plant.max_missed` behind: it stopped, stalled or vanished.
    PlantLost = 9
    #: The plant sent an invalid measurement: a bad code, a missing required field, a non-finite number (in any field it
    #: flags valid, velocities included) or a non-unit quaternion.
    PlantInvalid = 10
    #: The plant's measurements went backwards (`seq` 0 or below the last, `time_ns` not after the last), echoed another
    #: daemon session, or echoed a command never sent.
    PlantSequence = 11
    #: The plant reports a fault of its own (the event's `count` holds its `PlantFault` code).
    PlantFault = 12
    #: A grasping contact is not touching: the measured contact flag or normal force says so.
    ContactLost = 13
    #: Waiting for the plant's first valid measurement: nothing moves until it arrives.
    PlantWaiting = 14
    #: The plant exchange missed its timing contract `plant.max_misses_in_row` ticks in a row: commands late or repeated
    #: by the plant, measurements late or repeated (PLANT-GUIDE.md; the status's `timing` counts each).
    PlantTiming = 15


class EventKind(enum.IntEnum):
    """What an :class:`Event` reports."""

    #: A goal changed state (`state`, `reason`, `goal_id`, `client_id`).
    GoalTransition = 1
    #: A finger made contact (`finger`).
    Place = 2
    #: A finger broke contact (`finger`).
    Lift = 3
    #: A finger started rolling (`finger`).
    Roll = 4
    #: A finger substitution gait completed (paper §2.1): a finger took over a grasping finger's place, then that one
    #: lifted (`finger` = the finger that left; `count` = the finger that took over as a bit, bit k for finger k).
    Substitution = 5
    #: A finger rewind gait completed (paper §2.1): one or both fingers of the grasping pair were moved back into their
    #: workspace with the third finger's help (`finger` = that helper, free again; `count` = the relocated fingers as
    #: bits, bit k for finger k). Its substitutions were reported before it.
    Rewind = 6
    #: A fault was detected (`fault`; `finger` = the finger whose state caused it, none when the cause is not one
    #: finger's: CLIENT-GUIDE.md lists which faults name one; with `PlantFault`, `count` = the plant's `PlantFault`
    #: code).
    Fault = 7
    #: The fault was cleared by a reset.
    FaultCleared = 8
    #: The loop missed periods (`count` = periods skipped).
    Overrun = 9
    #: Dead client nodes were cleaned up (`count` = how many).
    ClientsCleaned = 10
    #: The daemon started (first event of an instance).
    DaemonStarted = 11
    #: The daemon is shutting down (last event of an instance).
    DaemonStopping = 12
    #: The controller switched to hold on a command (`reason`).
    Hold = 13
    #: A contact drifted beyond tolerance (`finger`, `goal_id`, `client_id`; `count` = replans of the goal so far,
    #: drifts and near-limits together): the motion stops and the goal is replanned from the measured state.
    Drift = 14
    #: While moving, the measured state came near the limit of an invariant (SPEC §6.3; `fault` = the invariant as the
    #: fault it would become, `finger` = the finger concerned, or none (0xFFFFFFFF) for force closure, `goal_id`,
    #: `client_id`, `count` = replans of the goal so far, drifts and near-limits together): the motion stops and the
    #: goal is replanned from the measured state.
    NearLimit = 15


class DaemonState(enum.IntEnum):
    """Running, or the final status."""

    #: The control loop is running.
    Running = 1
    #: Final status: the daemon held the grasp and is exiting.
    Stopped = 2


class PlantFingerMode(enum.IntEnum):
    """What a fingertip is asked to do (:class:`PlantFingerCommand`)."""

    #: In contact, part of the grasp: follow the pose and press with the grip force.
    Grasping = 1
    #: Lifted, in its free space: follow the pose, touch nothing.
    Free = 2
    #: Descending to make contact: follow the pose; the grip force ramps in.
    Placing = 3
    #: Breaking contact and rising: the grip force ramps out, then follow the pose.
    Lifting = 4


class PlantFault(enum.IntEnum):
    """A plant's own fault (:class:`PlantMeasurement`)."""

    #: No fault.
    None_ = 0
    #: An emergency stop is pressed.
    EmergencyStop = 1
    #: An actuator or sensor failed.
    Hardware = 2
    #: A joint, torque or force limit was hit.
    Limit = 3
    #: The simulation diverged (non-finite or exploding state).
    Diverged = 4
    #: Another fault of the plant.
    Other = 5


#: Every code table, by its LAYOUT.md heading.
CODE_TABLES: tuple[type[enum.IntEnum], ...] = (
    CommandKind,
    GoalFrame,
    AnswerCode,
    GoalState,
    ReasonCode,
    Phase,
    FingerPhase,
    GraspState,
    FaultCode,
    EventKind,
    DaemonState,
    PlantFingerMode,
    PlantFault,
)

# --------------------------------------------------------------------------- bits


class LimitKind(enum.IntEnum):
    """Motion kind of a limit override; mask bits 3*kind + order."""

    Object = 0
    Fingertip = 1
    Rolling = 2


class LimitOrder(enum.IntEnum):
    """Derivative order of a limit override."""

    Velocity = 0
    Acceleration = 1
    Jerk = 2


#: Every defined bit of ``Command.limit_mask``.
LIMIT_MASK_ALL = 511


class Notify(enum.IntEnum):
    """Notification ids on ``<prefix>/notify``."""

    Status = 1
    Event = 2
    Answer = 3
    DaemonDead = 4


class MeasuredMask(enum.IntFlag):
    """Bits of ``Status.measured_mask``: which measured fields are valid."""

    OBJECT = 1
    TIPS = 2
    CONTACTS = 4
    FORCES = 8
    JOINTS = 16


#: Every bit of ``Status.measured_mask``.
MEASURED_MASK_ALL = 31


class CommandFlags(enum.IntFlag):
    """Bits of ``PlantCommand.flags``."""

    ENABLE = 1
    HOLD = 2
    LOCKSTEP = 4
    JOINTS = 8


#: Every bit of ``PlantCommand.flags``.
COMMAND_FLAGS_ALL = 15


class Valid(enum.IntFlag):
    """Bits of ``PlantMeasurement.valid``."""

    OBJECT_ORIENTATION = 1
    OBJECT_VELOCITY = 2
    OBJECT_CENTER = 4
    TIP_POSE = 8
    TIP_VELOCITY = 16
    CONTACT = 32
    FORCE = 64
    ROLL = 128
    JOINT_POSITION = 256
    JOINT_VELOCITY = 512
    JOINT_TORQUE = 1024


#: What the daemon needs to control a hand of free fingertips.
VALID_REQUIRED = 169
#: What the daemon needs to control a hand of finger chains.
VALID_REQUIRED_JOINTS = 289
#: Every bit of ``PlantMeasurement.valid``.
VALID_ALL = 2047


class PlantState(enum.IntFlag):
    """Bits of ``PlantMeasurement.state``."""

    SIMULATED = 1
    PAUSED = 2
    FAULT = 4


#: Every bit of ``PlantMeasurement.state``.
PLANT_STATE_ALL = 7

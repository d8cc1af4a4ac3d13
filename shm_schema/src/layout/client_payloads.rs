//! The layouts of the client's payloads (SPEC §7.3): commands, answers,
//! status, events.

use super::{TypeLayout, field, layout};
use crate::*;
use core::mem::offset_of;

/// The client's payload types, nested types after the types that use them.
pub(super) fn layouts() -> Vec<TypeLayout> {
    vec![
        layout::<Command>(
            "Command",
            vec![
                f!(Command, kind, "CommandKind", "what is asked"),
                f!(
                    Command,
                    frame,
                    "GoalFrame",
                    "goal target meaning (goals only, else 0)"
                ),
                f!(Command, client_id, "", "sender's non-zero id"),
                f!(Command, request_id, "", "any value, echoed in the answer"),
                f!(
                    Command,
                    goal_id,
                    "",
                    "goal id (Goal: non-zero; Cancel: 0 = active goal)"
                ),
                f!(
                    Command,
                    target,
                    "[w,x,y,z]",
                    "target unit quaternion (goals only)"
                ),
                f!(
                    Command,
                    limit_mask,
                    "bits",
                    "set overrides: bit 3*kind+order"
                ),
                f!(Command, reserved, "", "padding, 0"),
                f!(
                    Command,
                    object_limits,
                    "rad/s, rad/s², rad/s³",
                    "object rotation limit overrides (bits 0-2)"
                ),
                f!(
                    Command,
                    fingertip_limits,
                    "m/s, m/s², m/s³",
                    "fingertip translation limit overrides (bits 3-5)"
                ),
                f!(
                    Command,
                    rolling_limits,
                    "rad/s, rad/s², rad/s³",
                    "rolling-rate limit overrides (bits 6-8)"
                ),
            ],
        ),
        layout::<MotionLimits>(
            "MotionLimits",
            vec![
                f!(
                    MotionLimits,
                    velocity,
                    "unit/s",
                    "velocity limit, > 0 when set"
                ),
                f!(
                    MotionLimits,
                    acceleration,
                    "unit/s²",
                    "acceleration limit, > 0 when set"
                ),
                f!(MotionLimits, jerk, "unit/s³", "jerk limit, > 0 when set"),
            ],
        ),
        layout::<Answer>(
            "Answer",
            vec![
                f!(Answer, client_id, "", "echo of the command's client_id"),
                f!(Answer, request_id, "", "echo of the command's request_id"),
                f!(Answer, goal_id, "", "echo of the command's goal_id"),
                f!(
                    Answer,
                    command,
                    "CommandKind",
                    "echo of the command's kind (raw)"
                ),
                f!(Answer, code, "AnswerCode", "accepted or rejected"),
                f!(
                    Answer,
                    reason,
                    "ReasonCode",
                    "why rejected (0 when accepted)"
                ),
                f!(Answer, reserved, "", "padding, 0"),
                f!(Answer, tick, "tick", "daemon tick that handled the command"),
                f!(Answer, instance, "", "daemon instance id"),
            ],
        ),
        layout::<Status>(
            "Status",
            vec![
                f!(Status, tick, "tick", "tick counter since start"),
                f!(
                    Status,
                    time_ns,
                    "ns",
                    "time of this tick: real time, its CLOCK_MONOTONIC wake-up; lockstep, the plant's `time_ns` of the measurement it ran on (one clock per run; 0 before the plant's first measurement)"
                ),
                f!(
                    Status,
                    publish_time_ns,
                    "ns",
                    "CLOCK_MONOTONIC time just before publishing"
                ),
                f!(Status, instance, "", "random id of this daemon run"),
                f!(
                    Status,
                    daemon_state,
                    "DaemonState",
                    "running, or stopped (final status)"
                ),
                f!(Status, phase, "Phase", "controller phase"),
                f!(Status, fault, "FaultCode", "current fault, 0 = none"),
                f!(
                    Status,
                    grasp,
                    "GraspState",
                    "force closure of the grasping fingers"
                ),
                f!(
                    Status,
                    grasp_margin,
                    "rad",
                    "force-closure margin, 0 when unknown"
                ),
                f!(
                    Status,
                    load_grip,
                    "N",
                    "largest normal force a carrying finger needs, at the commanded squeeze, over every load scenario: weight, acceleration torque and any disturbance of the configured size (F*, SPEC §1.3 I1'); no finger's `commanded_normal_force` exceeds it; +inf when no grip holds the load"
                ),
                f!(
                    Status,
                    load_margin,
                    "N",
                    "load.max_grip (a chain hand: the strongest normal push the grasping fingers' motors give, if lower) − load_grip; negative when the grasp cannot hold the load"
                ),
                f!(
                    Status,
                    commanded_object_q,
                    "[w,x,y,z]",
                    "commanded object orientation q_o, object → hand (the setpoint)"
                ),
                f!(
                    Status,
                    commanded_object_omega,
                    "rad/s",
                    "commanded object angular velocity, hand frame"
                ),
                f!(
                    Status,
                    measured_object_q,
                    "[w,x,y,z]",
                    "measured object orientation (mask bit OBJECT)"
                ),
                f!(
                    Status,
                    object_error,
                    "rad",
                    "angle from measured to commanded orientation, against the setpoint the measurement answers (`measured_age`) (mask bit OBJECT)"
                ),
                f!(
                    Status,
                    measured_tick,
                    "tick",
                    "tick the measurement was read at, 0 = none yet"
                ),
                f!(
                    Status,
                    measured_mask,
                    "bits",
                    "valid measured fields: 1 OBJECT, 2 TIPS, 4 CONTACTS, 8 FORCES (a plant that reports normal forces), 16 JOINTS (a chain hand's plant that measures its joints); 0 before the first measurement; the embedded hand: 7"
                ),
                f!(
                    Status,
                    measured_age,
                    "commands",
                    "commands sent after the one the measurement answers: the errors compare with the setpoint of tick measured_tick − 1 − measured_age"
                ),
                f!(Status, goal, "GoalStatus", "current goal and progress"),
                f!(Status, fingers, "FingerStatus", "fingers f1, f2, f3"),
                f!(Status, timing, "Timing", "loop timing"),
                f!(Status, commands, "", "commands received since start"),
                f!(Status, rejected, "", "commands rejected since start"),
                f!(Status, clients, "", "client nodes alive"),
                f!(
                    Status,
                    hand,
                    "0/1",
                    "hand model: 0 free fingertips, 1 finger chains (fingers report their joints)"
                ),
            ],
        ),
        layout::<GoalStatus>(
            "GoalStatus",
            vec![
                f!(GoalStatus, goal_id, "", "current or last goal, 0 = none"),
                f!(GoalStatus, client_id, "", "its client"),
                f!(GoalStatus, state, "GoalState", "goal state"),
                f!(GoalStatus, reason, "ReasonCode", "reason (terminal states)"),
                f!(
                    GoalStatus,
                    remaining_angle,
                    "rad",
                    "rotation still to make: while the plan runs (also braking to a stop), the plan's remaining path length, the sum of its rotation angles left (a full turn counts 2π; more than the angle to the goal when the plan detours); before it runs: an AxisAngle goal's angle (absolute value), else the angle from the commanded orientation to the target; 0 without an active goal"
                ),
                f!(
                    GoalStatus,
                    eta,
                    "s",
                    "estimated time to completion, -1 = unknown"
                ),
                f!(GoalStatus, gaits_done, "", "gaits completed"),
                f!(GoalStatus, gaits_planned, "", "gaits in the plan"),
                f!(
                    GoalStatus,
                    active_finger,
                    "index",
                    "finger of the current primitive, 0xFFFFFFFF = none"
                ),
                f!(GoalStatus, reserved, "", "padding, 0"),
            ],
        ),
        layout::<FingerStatus>(
            "FingerStatus",
            vec![
                f!(FingerStatus, state, "FingerPhase", "finger state"),
                f!(
                    FingerStatus,
                    measured_contact,
                    "0/1",
                    "measured contact, 1 = touching (mask bit CONTACTS)"
                ),
                f!(
                    FingerStatus,
                    contact_hand,
                    "m",
                    "contact on the object surface, hand frame (0 if no contact)"
                ),
                f!(
                    FingerStatus,
                    contact_object,
                    "m",
                    "contact on the object surface, object frame (0 if no contact)"
                ),
                f!(
                    FingerStatus,
                    commanded_tip_position,
                    "m",
                    "commanded fingertip centre p, hand frame"
                ),
                f!(
                    FingerStatus,
                    commanded_tip_orientation,
                    "[w,x,y,z]",
                    "commanded fingertip orientation Q_f, fingertip → hand"
                ),
                f!(
                    FingerStatus,
                    tip_contact,
                    "unit vector",
                    "contact on the fingertip m, fingertip frame (0 if no contact)"
                ),
                f!(
                    FingerStatus,
                    roll,
                    "rad",
                    "commanded roll τ about the pole axis Q_f e_z (τ̇ = ω_f · Q_f e_z, 0 in the start grasp)"
                ),
                f!(
                    FingerStatus,
                    workspace_margin,
                    "rad",
                    "angle to the workspace cone boundary, > 0 inside; on a chain hand the joints' margin inside their limits (less the description's margin)"
                ),
                f!(
                    FingerStatus,
                    commanded_normal_force,
                    "N",
                    "intended normal force (the plant command's `grip_force`): this finger's share of the current load (weight, acceleration torque) plus the squeeze that holds every disturbance; 0 if it carries nothing"
                ),
                f!(
                    FingerStatus,
                    measured_tip_position,
                    "m",
                    "measured fingertip centre, hand frame (mask bit TIPS)"
                ),
                f!(
                    FingerStatus,
                    measured_tip_orientation,
                    "[w,x,y,z]",
                    "measured fingertip orientation (mask bit TIPS)"
                ),
                f!(
                    FingerStatus,
                    measured_normal_force,
                    "N",
                    "measured normal force (mask bit FORCES)"
                ),
                f!(
                    FingerStatus,
                    tip_error,
                    "m",
                    "distance measured → commanded fingertip centre, against the setpoint the measurement answers (`Status.measured_age`) (mask bit TIPS)"
                ),
                f!(
                    FingerStatus,
                    commanded_joints,
                    "rad",
                    "chain hand: the commanded joint positions, base to tip (0 on free fingertips)"
                ),
                f!(
                    FingerStatus,
                    tip_margin,
                    "rad",
                    "commanded contact on the fingertip to the edge of its tip patch (chains, less its margin) or hemisphere (free fingertips), > 0 inside; 0 when not touching"
                ),
                f!(
                    FingerStatus,
                    link_clearance,
                    "m",
                    "chain hand: the closest link's distance from the object beyond the configured clearance (0 on free fingertips)"
                ),
                f!(
                    FingerStatus,
                    measured_joints,
                    "rad",
                    "chain hand: the measured joint positions, base to tip (mask bit JOINTS)"
                ),
            ],
        ),
        layout::<Timing>(
            "Timing",
            vec![
                f!(Timing, period_ns, "ns", "loop period"),
                f!(
                    Timing,
                    compute_last_ns,
                    "ns",
                    "compute time of the previous tick"
                ),
                f!(
                    Timing,
                    compute_p50_ns,
                    "ns",
                    "compute time median since start"
                ),
                f!(Timing, compute_p99_ns, "ns", "compute time p99 since start"),
                f!(Timing, compute_max_ns, "ns", "compute time max since start"),
                f!(Timing, jitter_last_ns, "ns", "wake-up jitter of this tick"),
                f!(
                    Timing,
                    jitter_p99_ns,
                    "ns",
                    "wake-up jitter p99 since start"
                ),
                f!(
                    Timing,
                    jitter_max_ns,
                    "ns",
                    "wake-up jitter max since start"
                ),
                f!(Timing, overruns, "periods", "missed periods since start"),
                f!(
                    Timing,
                    jitter_hist,
                    "counts",
                    "bucket 0: < 1 µs; i: [2^(i-1), 2^i) µs; 15: ≥ 16.384 ms"
                ),
                f!(
                    Timing,
                    plant_commands_late,
                    "ticks",
                    "external plant: commands that went out after their tick's deadline, since start"
                ),
                f!(
                    Timing,
                    plant_commands_repeated,
                    "steps",
                    "external plant: steps that applied the command of the step before although a newer one was sent"
                ),
                f!(
                    Timing,
                    plant_measurements_late,
                    "ticks",
                    "external plant: ticks without a new measurement (the last one held)"
                ),
                f!(
                    Timing,
                    plant_measurements_repeated,
                    "",
                    "external plant: measurements received again with a sequence number already taken"
                ),
                f!(
                    Timing,
                    plant_misses_in_row,
                    "ticks",
                    "external plant: ticks in a row, up to this one, that missed the timing contract; faulted (PlantTiming) at plant.max_misses_in_row"
                ),
                f!(
                    Timing,
                    plant_misses_in_row_max,
                    "ticks",
                    "external plant: the longest such run since start"
                ),
            ],
        ),
        layout::<Event>(
            "Event",
            vec![
                f!(Event, seq, "", "sequence number, from 1, no gaps"),
                f!(Event, tick, "tick", "tick at which it happened"),
                f!(
                    Event,
                    time_ns,
                    "ns",
                    "time of that tick (as Status.time_ns: the plant's in lockstep)"
                ),
                f!(Event, instance, "", "daemon instance id"),
                f!(Event, kind, "EventKind", "what happened"),
                f!(
                    Event,
                    finger,
                    "index",
                    "finger 0-2, 0xFFFFFFFF = none (EventKind says which kinds name one)"
                ),
                f!(Event, state, "GoalState", "new goal state (transitions)"),
                f!(Event, reason, "ReasonCode", "reason"),
                f!(Event, goal_id, "", "goal concerned, 0 = none"),
                f!(Event, client_id, "", "that goal's client"),
                f!(
                    Event,
                    fault,
                    "FaultCode",
                    "Fault: the fault; NearLimit: the invariant"
                ),
                f!(Event, reserved, "", "padding, 0"),
                f!(
                    Event,
                    count,
                    "",
                    "Overrun: missed periods; ClientsCleaned: nodes; Drift, NearLimit: replans so far; \
                     Substitution: finger that took over, as a bit; Rewind: relocated fingers as bits; \
                     Fault `PlantFault`: the plant's `PlantFault` code"
                ),
                f!(
                    Event,
                    value,
                    "",
                    "GoalTransition: `GoalStatus.remaining_angle` as last reported [rad] (0 for Rejected)"
                ),
            ],
        ),
        layout::<PlanPath>(
            "PlanPath",
            vec![
                f!(PlanPath, instance, "", "daemon instance id"),
                f!(PlanPath, goal_id, "", "the goal it was planned for"),
                f!(PlanPath, client_id, "", "that goal's client"),
                f!(
                    PlanPath,
                    sequence,
                    "",
                    "plans of this instance, from 1 (a goal planned again gets a larger one)"
                ),
                f!(
                    PlanPath,
                    duration,
                    "s",
                    "how long the plan runs (the last point's time)"
                ),
                f!(PlanPath, count, "", "points used, 1-256"),
                f!(PlanPath, reserved, "", "padding, 0"),
                f!(
                    PlanPath,
                    points,
                    "PathPoint[256]",
                    "equal intervals from the plan's first tick to its end; past `count`: 0"
                ),
            ],
        ),
        layout::<PathPoint>(
            "PathPoint",
            vec![
                f!(PathPoint, t, "s", "time since the plan's first tick"),
                f!(
                    PathPoint,
                    object_q,
                    "[w,x,y,z]",
                    "object orientation (object → hand frame)"
                ),
                f!(
                    PathPoint,
                    tip_position,
                    "m",
                    "fingertip sphere centres, hand frame, per finger"
                ),
                f!(PathPoint, touching, "bits", "bit k: finger k grasps"),
                f!(PathPoint, reserved, "", "padding, 0"),
            ],
        ),
    ]
}

//! The documented byte layout of every payload, for C and Python mirrors.
//!
//! [`layouts`] lists every field with offset, size, type and unit, taken
//! from the compiler (`offset_of!`, `size_of`); a test checks that the
//! fields tile each struct exactly (no gap, no overlap, nothing missing) and
//! that `LAYOUT.md` equals [`layout_markdown`], so the document cannot drift.

use crate::codes::CodeInfo;
use crate::command::{LIMIT_OVERRIDES, QUATERNION_NORM_TOLERANCE};
use crate::*;
use core::mem::{align_of, offset_of, size_of};
use iceoryx2::prelude::ZeroCopySend;
use std::fmt::Write as _;

/// One field of a payload struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldInfo {
    /// Field name.
    pub name: &'static str,
    /// Byte offset from the start of the struct.
    pub offset: usize,
    /// Size in bytes.
    pub size: usize,
    /// Rust type (`u64`, `[f64; 4]`, `FingerStatus`).
    pub ty: String,
    /// Physical unit or code table ("" if none).
    pub unit: &'static str,
    /// Meaning, one line.
    pub doc: &'static str,
}

/// One payload struct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeLayout {
    /// Rust name.
    pub name: &'static str,
    /// iceoryx2 type name (compared when a service is opened).
    pub type_name: &'static str,
    /// `size_of`.
    pub size: usize,
    /// `align_of`.
    pub align: usize,
    /// Fields in offset order.
    pub fields: Vec<FieldInfo>,
}

fn short_type_name<F>() -> String {
    // "[shm_schema::status::FingerStatus; 3]" → "[FingerStatus; 3]"
    let full = core::any::type_name::<F>();
    let mut out = String::new();
    let mut word = String::new();
    for ch in full.chars() {
        if ch.is_alphanumeric() || ch == '_' || ch == ':' {
            word.push(ch);
        } else {
            out.push_str(word.rsplit("::").next().unwrap_or(""));
            word.clear();
            out.push(ch);
        }
    }
    out.push_str(word.rsplit("::").next().unwrap_or(""));
    out
}

fn field<T, F>(
    name: &'static str,
    offset: usize,
    _witness: fn(&T) -> &F,
    unit: &'static str,
    doc: &'static str,
) -> FieldInfo {
    FieldInfo {
        name,
        offset,
        size: size_of::<F>(),
        ty: short_type_name::<F>(),
        unit,
        doc,
    }
}

/// `f!(Type, field, unit, doc)`: a [`FieldInfo`] with offset, size and type
/// from the compiler.
macro_rules! f {
    ($t:ty, $field:ident, $unit:expr, $doc:expr) => {
        field(
            stringify!($field),
            offset_of!($t, $field),
            |s: &$t| &s.$field,
            $unit,
            $doc,
        )
    };
}

fn layout<T: ZeroCopySend>(name: &'static str, fields: Vec<FieldInfo>) -> TypeLayout {
    TypeLayout {
        name,
        // SAFETY: the type names are compile-time constants from the derive.
        type_name: unsafe { <T as ZeroCopySend>::type_name() },
        size: size_of::<T>(),
        align: align_of::<T>(),
        fields,
    }
}

/// Every payload type, nested types after the types that use them.
pub fn layouts() -> Vec<TypeLayout> {
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
                    "CLOCK_MONOTONIC wake-up time of this tick"
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
                    "largest normal force the grasp needs to hold the load (F*, SPEC §1.3 I1'); +inf when none does"
                ),
                f!(
                    Status,
                    load_margin,
                    "N",
                    "load.max_grip − load_grip; negative when the grasp cannot hold the load"
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
                    "angle from measured to commanded orientation (mask bit OBJECT)"
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
                    "valid measured fields: 1 OBJECT, 2 TIPS, 4 CONTACTS, 8 FORCES"
                ),
                f!(Status, reserved0, "", "padding, 0"),
                f!(Status, goal, "GoalStatus", "current goal and progress"),
                f!(Status, fingers, "FingerStatus", "fingers f1, f2, f3"),
                f!(Status, timing, "Timing", "loop timing"),
                f!(Status, commands, "", "commands received since start"),
                f!(Status, rejected, "", "commands rejected since start"),
                f!(Status, clients, "", "client nodes alive"),
                f!(Status, reserved, "", "padding, 0"),
            ],
        ),
        layout::<GoalStatus>(
            "GoalStatus",
            vec![
                f!(GoalStatus, goal_id, "", "current or last goal, 0 = none"),
                f!(GoalStatus, client_id, "", "its client"),
                f!(GoalStatus, state, "GoalState", "goal state"),
                f!(GoalStatus, reason, "ReasonCode", "reason (terminal states)"),
                f!(GoalStatus, remaining_angle, "rad", "angle still to rotate"),
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
                f!(FingerStatus, roll, "rad", "roll τ about the pole axis"),
                f!(
                    FingerStatus,
                    workspace_margin,
                    "rad",
                    "angle to the workspace cone boundary, > 0 inside"
                ),
                f!(
                    FingerStatus,
                    commanded_normal_force,
                    "N",
                    "intended normal force, 0 if none"
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
                    "distance measured → commanded fingertip centre (mask bit TIPS)"
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
            ],
        ),
        layout::<Event>(
            "Event",
            vec![
                f!(Event, seq, "", "sequence number, from 1, no gaps"),
                f!(Event, tick, "tick", "tick at which it happened"),
                f!(Event, time_ns, "ns", "CLOCK_MONOTONIC time of that tick"),
                f!(Event, instance, "", "daemon instance id"),
                f!(Event, kind, "EventKind", "what happened"),
                f!(Event, finger, "index", "finger 0-2, 0xFFFFFFFF = none"),
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
                     Substitution: finger that took over, as a bit; Rewind: relocated fingers as bits"
                ),
                f!(Event, value, "", "GoalTransition: remaining angle [rad]"),
            ],
        ),
        layout::<PlantCommand>(
            "PlantCommand",
            vec![
                f!(
                    PlantCommand,
                    session,
                    "",
                    "daemon session id, random per start"
                ),
                f!(
                    PlantCommand,
                    seq,
                    "",
                    "command sequence number, from 1, +1 each"
                ),
                f!(
                    PlantCommand,
                    answers,
                    "",
                    "seq of the measurement it answers, 0 = none"
                ),
                f!(
                    PlantCommand,
                    target_time_ns,
                    "ns",
                    "plant time the setpoint holds at: answered time + period"
                ),
                f!(PlantCommand, period_ns, "ns", "control period"),
                f!(
                    PlantCommand,
                    flags,
                    "bits",
                    "1 ENABLE, 2 HOLD (safe hold: still, grasp kept), 4 LOCKSTEP"
                ),
                f!(PlantCommand, reserved, "", "padding, 0"),
                f!(
                    PlantCommand,
                    object_q,
                    "[w,x,y,z]",
                    "object orientation setpoint, object → hand"
                ),
                f!(
                    PlantCommand,
                    object_omega,
                    "rad/s",
                    "object angular velocity setpoint, hand frame"
                ),
                f!(
                    PlantCommand,
                    fingers,
                    "PlantFingerCommand",
                    "fingers f1, f2, f3"
                ),
            ],
        ),
        layout::<PlantFingerCommand>(
            "PlantFingerCommand",
            vec![
                f!(
                    PlantFingerCommand,
                    mode,
                    "PlantFingerMode",
                    "what the fingertip does"
                ),
                f!(PlantFingerCommand, reserved, "", "padding, 0"),
                f!(
                    PlantFingerCommand,
                    position,
                    "m",
                    "fingertip centre, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    orientation,
                    "[w,x,y,z]",
                    "fingertip orientation, fingertip → hand"
                ),
                f!(
                    PlantFingerCommand,
                    velocity,
                    "m/s",
                    "linear velocity, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    angular_velocity,
                    "rad/s",
                    "angular velocity, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    acceleration,
                    "m/s²",
                    "linear acceleration feed-forward, hand frame"
                ),
                f!(
                    PlantFingerCommand,
                    roll,
                    "rad",
                    "commanded roll τ about the pole axis"
                ),
                f!(
                    PlantFingerCommand,
                    grip_force,
                    "N",
                    "intended normal force, 0 when not grasping"
                ),
            ],
        ),
        layout::<PlantMeasurement>(
            "PlantMeasurement",
            vec![
                f!(
                    PlantMeasurement,
                    session,
                    "",
                    "session of the last command applied, 0 = none yet"
                ),
                f!(
                    PlantMeasurement,
                    seq,
                    "",
                    "measurement sequence number, from 1, +1 each"
                ),
                f!(
                    PlantMeasurement,
                    applied,
                    "",
                    "seq of the last command applied, 0 = none"
                ),
                f!(PlantMeasurement, time_ns, "ns", "sample time, plant clock"),
                f!(
                    PlantMeasurement,
                    valid,
                    "bits",
                    "valid fields: 1 object_q, 2 object_omega, 4 object_center, 8 tip pose, \
                     16 tip velocity, 32 contact, 64 normal_force, 128 roll (required: 1, 8, 32, 128)"
                ),
                f!(
                    PlantMeasurement,
                    state,
                    "bits",
                    "1 SIMULATED, 2 PAUSED, 4 FAULT"
                ),
                f!(
                    PlantMeasurement,
                    fault,
                    "PlantFault",
                    "with FAULT: the plant's fault"
                ),
                f!(PlantMeasurement, reserved, "", "padding, 0"),
                f!(
                    PlantMeasurement,
                    object_q,
                    "[w,x,y,z]",
                    "object orientation, object → hand"
                ),
                f!(
                    PlantMeasurement,
                    object_omega,
                    "rad/s",
                    "object angular velocity, hand frame"
                ),
                f!(
                    PlantMeasurement,
                    object_center,
                    "m",
                    "object centre, hand frame"
                ),
                f!(
                    PlantMeasurement,
                    fingers,
                    "PlantFingerMeasurement",
                    "fingers f1, f2, f3"
                ),
            ],
        ),
        layout::<PlantFingerMeasurement>(
            "PlantFingerMeasurement",
            vec![
                f!(
                    PlantFingerMeasurement,
                    contact,
                    "0/1",
                    "1 = touching the object"
                ),
                f!(PlantFingerMeasurement, reserved, "", "padding, 0"),
                f!(
                    PlantFingerMeasurement,
                    position,
                    "m",
                    "fingertip centre, hand frame"
                ),
                f!(
                    PlantFingerMeasurement,
                    orientation,
                    "[w,x,y,z]",
                    "fingertip orientation, fingertip → hand"
                ),
                f!(
                    PlantFingerMeasurement,
                    velocity,
                    "m/s",
                    "linear velocity, hand frame"
                ),
                f!(
                    PlantFingerMeasurement,
                    angular_velocity,
                    "rad/s",
                    "angular velocity, hand frame"
                ),
                f!(
                    PlantFingerMeasurement,
                    roll,
                    "rad",
                    "roll τ about the pole axis"
                ),
                f!(
                    PlantFingerMeasurement,
                    normal_force,
                    "N",
                    "normal force at the contact"
                ),
            ],
        ),
    ]
}

/// Every code table: (enum name, rows).
pub fn code_tables() -> Vec<(&'static str, &'static [CodeInfo])> {
    vec![
        ("CommandKind", CommandKind::TABLE),
        ("GoalFrame", GoalFrame::TABLE),
        ("AnswerCode", AnswerCode::TABLE),
        ("GoalState", GoalState::TABLE),
        ("ReasonCode", ReasonCode::TABLE),
        ("Phase", Phase::TABLE),
        ("FingerPhase", FingerPhase::TABLE),
        ("GraspState", GraspState::TABLE),
        ("FaultCode", FaultCode::TABLE),
        ("EventKind", EventKind::TABLE),
        ("DaemonState", DaemonState::TABLE),
        ("PlantFingerMode", PlantFingerMode::TABLE),
        ("PlantFault", PlantFault::TABLE),
    ]
}

/// The layout document (`shm_schema/LAYOUT.md`).
pub fn layout_markdown() -> String {
    let mut s = String::new();
    let names = ServiceNames::new(DEFAULT_PREFIX);
    let _ = writeln!(
        s,
        "# gaitd shared-memory schema v{SCHEMA_VERSION}\n\n\
         Generated from `shm_schema` by `cargo test -p shm_schema` (set `GAITD_BLESS=1` to\n\
         rewrite it); a test fails when this file and the code disagree.\n\n\
         This file is the bytes. How to connect (iceoryx2 root path, file prefix, environment\n\
         variables), the service settings a client must match, when the daemon is ready, how\n\
         to choose ids and what the progress counters count, with a walk-through in Python:\n\
         [CLIENT-GUIDE.md](CLIENT-GUIDE.md).\n\n\
         All payloads are `#[repr(C)]`, little-endian as the host, with explicit padding\n\
         (fields named `reserved`, always 0). Enums travel as `u32` codes (tables below);\n\
         readers must refuse unknown codes. iceoryx2 {ICEORYX2_VERSION} compares the type name,\n\
         size and alignment when a service is opened: a C or Python mirror must use the\n\
         same type names. Quaternions are `[w, x, y, z]` Hamilton, unit norm.\n\n\
         ## Services (prefix `{DEFAULT_PREFIX}`, configurable)\n\n\
         | service | pattern | payload | notes |\n|---|---|---|---|\n\
         | `{}` | publish-subscribe | `Command` | client → daemon, one publisher per client |\n\
         | `{}` | publish-subscribe | `Answer` | one per command, match `client_id` + `request_id` |\n\
         | `{}` | publish-subscribe | `Status` | every tick, history 1, latest value |\n\
         | `{}` | publish-subscribe | `Event` | with history |\n\
         | `{}` | event | — | wake-ups, ids below |\n\
         | `{}` | publish-subscribe | `PlantCommand` | daemon → plant, every tick |\n\
         | `{}` | publish-subscribe | `PlantMeasurement` | plant → daemon |\n\
         | `{}` | event | — | daemon → plant: a command was published (id 1) |\n\
         | `{}` | event | — | plant → daemon: a measurement was published (id 1) |\n",
        names.commands,
        names.answers,
        names.status,
        names.events,
        names.notify,
        names.plant_command,
        names.plant_measurement,
        names.plant_commanded,
        names.plant_measured
    );
    let _ = writeln!(
        s,
        "Notification ids on `{}`: {} = status published, {} = event published, \
         {} = answer sent, {} = daemon node found dead.\n",
        names.notify, EVENT_ID_STATUS, EVENT_ID_EVENT, EVENT_ID_ANSWER, EVENT_ID_DAEMON_DEAD
    );
    s.push_str("## Payloads\n\n");
    for t in layouts() {
        let _ = writeln!(
            s,
            "### `{}` (`{}`, {} bytes, align {})\n\n\
             | offset | size | field | type | unit | meaning |\n|---:|---:|---|---|---|---|",
            t.name, t.type_name, t.size, t.align
        );
        for f in &t.fields {
            let _ = writeln!(
                s,
                "| {} | {} | `{}` | `{}` | {} | {} |",
                f.offset, f.size, f.name, f.ty, f.unit, f.doc
            );
        }
        s.push('\n');
    }
    let _ = writeln!(
        s,
        "## Command validation\n\n\
         What the daemon accepts in a `Command` (anything else is rejected with the\n\
         reason code in brackets):\n\n\
         - quaternion targets (`Absolute`, `Relative`): finite [`NonFiniteQuaternion`],\n\
         \x20 norm ≥ 1e-6 [`ZeroQuaternion`], |norm − 1| ≤ {QUATERNION_NORM_TOLERANCE:e}\n\
         \x20 [`NonUnitQuaternion`]; the daemon renormalises;\n\
         - axis-angle targets `[angle, x, y, z]`: finite, |angle| ≤ 64π = {MAX_AXIS_ANGLE} rad,\n\
         \x20 axis norm in [1e-6, 1e6] [`BadAxisAngle`];\n\
         - motion-limit overrides: only bits 0–{} of `limit_mask` [`BadLimitMask`]; a set\n\
         \x20 override finite [`NonFiniteLimit`] and > 0 [`NonPositiveLimit`], at most the\n\
         \x20 configured limit [`LimitAboveConfigured`] and at least {MIN_LIMIT_OVERRIDE_FRACTION} × the\n\
         \x20 configured limit [`LimitBelowMinimum`]; plans are timed with the limits in effect,\n\
         \x20 so ETA and plan cost hold under an override;\n\
         - every field a command kind does not use, and every unset override, is 0\n\
         \x20 [`NonZeroReserved`].\n",
        LIMIT_OVERRIDES - 1
    );
    s.push_str("## Codes\n\n");
    for (name, rows) in code_tables() {
        let _ = writeln!(
            s,
            "### `{name}`\n\n| code | name | meaning |\n|---:|---|---|"
        );
        for r in rows {
            let _ = writeln!(s, "| {} | `{}` | {} |", r.code, r.name, r.doc);
        }
        s.push('\n');
    }
    s.truncate(s.trim_end().len());
    s.push('\n');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_tile_every_struct_exactly() {
        for t in layouts() {
            let mut end = 0;
            for f in &t.fields {
                assert_eq!(
                    f.offset, end,
                    "{}.{}: gap or overlap before it",
                    t.name, f.name
                );
                assert_eq!(f.offset % t.align.min(f.size.max(1)).min(8), 0);
                end = f.offset + f.size;
            }
            assert_eq!(end, t.size, "{}: fields do not cover the struct", t.name);
            assert!(t.type_name.starts_with("gaitd::"), "{}", t.type_name);
            assert!(
                t.type_name.ends_with(&format!(".v{SCHEMA_VERSION}")),
                "{}",
                t.type_name
            );
        }
    }

    #[test]
    fn type_names_are_short() {
        assert_eq!(short_type_name::<[FingerStatus; 3]>(), "[FingerStatus; 3]");
        assert_eq!(short_type_name::<u64>(), "u64");
    }

    /// What an out-of-date LAYOUT.md leads to.
    #[derive(Debug, PartialEq)]
    enum Stale {
        /// `GAITD_BLESS` set outside CI: rewrite it.
        Rewrite,
        /// Fail with this message.
        Fail(&'static str),
    }

    /// `GAITD_BLESS` rewrites the document, except in CI (`CI` set, and not
    /// `false` or `0`): there a bless would turn any schema change into a
    /// pass, so it fails even when the document is current.
    fn on_stale(bless: bool, ci: Option<&str>, current: bool) -> Option<Stale> {
        let ci = ci.is_some_and(|v| !matches!(v, "" | "false" | "0"));
        match (bless, ci, current) {
            (true, true, _) => Some(Stale::Fail(
                "GAITD_BLESS is set in CI (CI=true): LAYOUT.md is never rewritten in CI; \
                 bless locally (`GAITD_BLESS=1 cargo test -p shm_schema`) and commit the result",
            )),
            (_, _, true) => None,
            (true, false, false) => Some(Stale::Rewrite),
            (false, _, false) => Some(Stale::Fail(
                "is out of date: run `GAITD_BLESS=1 cargo test -p shm_schema` \
                 and commit the result",
            )),
        }
    }

    #[test]
    fn ci_never_blesses() {
        assert_eq!(on_stale(true, None, false), Some(Stale::Rewrite));
        assert_eq!(on_stale(true, Some("false"), false), Some(Stale::Rewrite));
        assert_eq!(on_stale(false, None, true), None);
        assert!(matches!(on_stale(false, None, false), Some(Stale::Fail(_))));
        for current in [false, true] {
            let Some(Stale::Fail(why)) = on_stale(true, Some("true"), current) else {
                panic!("blessed in CI");
            };
            assert!(why.contains("CI"), "{why}");
        }
    }

    #[test]
    fn layout_document_is_current() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/LAYOUT.md");
        let want = layout_markdown();
        let have = std::fs::read_to_string(path).unwrap_or_default();
        let ci = std::env::var("CI").ok();
        let bless = std::env::var_os("GAITD_BLESS").is_some();
        match on_stale(bless, ci.as_deref(), have == want) {
            None => {}
            Some(Stale::Rewrite) => std::fs::write(path, &want).unwrap(),
            Some(Stale::Fail(why)) => panic!("{path}: {why}"),
        }
    }
}

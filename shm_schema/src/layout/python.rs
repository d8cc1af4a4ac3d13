//! The Python package's mirror of the schema, `client/python/gaitd/layout.py`,
//! generated from [`super::layouts`], [`super::code_tables`] and the
//! constants (a test checks the file equals it): ctypes structures with the
//! iceoryx2 type names, the code tables as `IntEnum`s, the bit constants.
//! `gaitd.schema` adds the helpers and the check against `LAYOUT.md`.

use super::{TypeLayout, code_tables, layouts};
use crate::command::LIMIT_OVERRIDES;
use crate::plant::{command_flags, measurement_valid, plant_state};
use crate::*;
use std::fmt::Write as _;

/// Longest generated line (the package's ruff line length).
const LINE: usize = 120;

/// One-line docstrings of the generated classes, by name: the payloads and
/// the code tables (a type or table without one fails the generator).
const SUMMARIES: &[(&str, &str)] = &[
    ("Command", "client → daemon: a goal, cancel, hold or reset."),
    (
        "MotionLimits",
        "Velocity, acceleration and jerk limit overrides of one motion kind.",
    ),
    (
        "Answer",
        "daemon → client: one per command, matched by client_id + request_id.",
    ),
    ("Status", "daemon → clients, every tick (latest value)."),
    (
        "GoalStatus",
        "The current goal and its progress (part of :class:`Status`).",
    ),
    (
        "FingerStatus",
        "One finger in the status: commanded and measured.",
    ),
    (
        "Timing",
        "Loop timing statistics (part of :class:`Status`).",
    ),
    (
        "Event",
        "daemon → clients, with history: goal transitions, gaits, faults.",
    ),
    (
        "PlanPath",
        "daemon → clients: where each plan takes the hand (latest value).",
    ),
    (
        "PathPoint",
        "The hand at one instant of a plan (part of :class:`PlanPath`).",
    ),
    ("PlantCommand", "daemon → plant, every tick."),
    (
        "PlantFingerCommand",
        "One fingertip's setpoint (part of :class:`PlantCommand`).",
    ),
    ("PlantMeasurement", "plant → daemon, one per plant step."),
    (
        "PlantFingerMeasurement",
        "One fingertip as measured (part of :class:`PlantMeasurement`).",
    ),
    ("CommandKind", "What a :class:`Command` asks."),
    ("GoalFrame", "Meaning of a goal's target."),
    ("AnswerCode", "Accepted or rejected."),
    ("GoalState", "Goal lifecycle (SPEC §6.4)."),
    ("ReasonCode", "Why a command was rejected or a goal ended."),
    ("Phase", "Controller phase."),
    ("FingerPhase", "A finger's state in the status."),
    ("GraspState", "Force closure of the grasping fingers."),
    ("FaultCode", "The controller's fault."),
    ("EventKind", "What an :class:`Event` reports."),
    ("DaemonState", "Running, or the final status."),
    (
        "PlantFingerMode",
        "What a fingertip is asked to do (:class:`PlantFingerCommand`).",
    ),
    (
        "PlantFault",
        "A plant's own fault (:class:`PlantMeasurement`).",
    ),
];

fn summary(name: &str) -> &'static str {
    SUMMARIES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
        .unwrap_or_else(|| panic!("layout/python.rs: no docstring for {name} in SUMMARIES"))
}

/// `text` as `#` comment lines indented by `indent`, wrapped at [`LINE`].
fn comment(s: &mut String, indent: &str, prefix: &str, text: &str) {
    let lead = format!("{indent}{prefix}");
    let mut line = lead.clone();
    for word in text.split_whitespace() {
        if line.len() > lead.len() && line.chars().count() + 1 + word.chars().count() > LINE {
            s.push_str(line.trim_end());
            s.push('\n');
            line = lead.clone();
        }
        if line.len() > lead.len() {
            line.push(' ');
        }
        line.push_str(word);
    }
    s.push_str(&line);
    s.push('\n');
}

/// The ctypes type of a Rust field type: `u32`, `[f64; 4]` → `f64 * 4`,
/// `[FingerStatus; 3]` → `FingerStatus * 3`, `[[f64; 3]; 3]` →
/// `f64 * 3 * 3` (ctypes reads it as `(f64 * 3) * 3`), `MotionLimits`.
fn ctype(ty: &str) -> String {
    match ty.strip_prefix('[').and_then(|t| t.strip_suffix(']')) {
        Some(array) => {
            // The outer length is after the last `; `.
            let (elem, n) = array
                .rsplit_once("; ")
                .unwrap_or_else(|| panic!("array type {ty}"));
            format!("{} * {n}", ctype(elem))
        }
        None => ty.to_string(),
    }
}

/// The payload a field's type names (`[FingerStatus; 3]` → `FingerStatus`), if any.
fn nested(ty: &str) -> Option<&str> {
    let base = ty
        .trim_start_matches('[')
        .split(';')
        .next()
        .unwrap_or(ty)
        .trim_end_matches(']');
    (!matches!(base, "u32" | "u64" | "f64")).then_some(base)
}

/// The payloads in an order Python can define them: each after the ones it contains.
fn definition_order(all: &[TypeLayout]) -> Vec<&TypeLayout> {
    fn visit<'a>(t: &'a TypeLayout, all: &'a [TypeLayout], out: &mut Vec<&'a TypeLayout>) {
        if out.iter().any(|d| d.name == t.name) {
            return;
        }
        for f in &t.fields {
            if let Some(inner) = nested(&f.ty) {
                let inner = all
                    .iter()
                    .find(|x| x.name == inner)
                    .unwrap_or_else(|| panic!("{}.{}: {inner} is no payload", t.name, f.name));
                visit(inner, all, out);
            }
        }
        out.push(t);
    }
    let mut out = Vec::new();
    for t in all {
        visit(t, all, &mut out);
    }
    out
}

/// A Python enum member's name (`None` is a keyword).
fn member(name: &str) -> &str {
    if name == "None" { "None_" } else { name }
}

fn bits(s: &mut String, class: &str, base: &str, doc: &str, values: &[(&str, u32)]) {
    let _ = writeln!(
        s,
        "\n\nclass {class}(enum.{base}):\n    \"\"\"{doc}\"\"\"\n"
    );
    for (name, v) in values {
        let _ = writeln!(s, "    {name} = {v}");
    }
}

fn every_limit_kind(k: LimitKind) -> (&'static str, LimitKind) {
    // Exhaustive: a new kind fails to compile here until it is listed below.
    match k {
        LimitKind::Object => ("Object", k),
        LimitKind::Fingertip => ("Fingertip", k),
        LimitKind::Rolling => ("Rolling", k),
    }
}

fn every_limit_order(o: LimitOrder) -> (&'static str, LimitOrder) {
    match o {
        LimitOrder::Velocity => ("Velocity", o),
        LimitOrder::Acceleration => ("Acceleration", o),
        LimitOrder::Jerk => ("Jerk", o),
    }
}

/// The generated module (`client/python/gaitd/layout.py`).
pub fn python_layout() -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "\"\"\"The payloads, codes and constants of the gaitd shared-memory schema v{SCHEMA_VERSION}, for ctypes.\n\
         \n\
         Generated from the ``shm_schema`` crate (``shm_schema/src/layout/python.rs``) by\n\
         ``cargo test -p shm_schema`` (set ``GAITD_BLESS=1`` to rewrite it); a test fails when this\n\
         file and the code disagree, so edit the Rust code, not this file. ``shm_schema/LAYOUT.md``\n\
         is generated from the same code; :mod:`gaitd.schema` adds the helpers and the check\n\
         against that document.\n\
         \"\"\"\n\
         \n\
         from __future__ import annotations\n\
         \n\
         import ctypes\n\
         import enum\n\
         from typing import ClassVar\n\
         \n\
         #: Version of the payload layout (part of every type name).\n\
         SCHEMA_VERSION = {SCHEMA_VERSION}\n\
         #: The iceoryx2 release the daemon is built with; resource names are\n\
         #: version-tagged, so the Python bindings must be exactly this version.\n\
         ICEORYX2_VERSION = \"{ICEORYX2_VERSION}\"\n\
         #: Default service-name prefix.\n\
         DEFAULT_PREFIX = \"{DEFAULT_PREFIX}\"\n\
         #: Fingers of the hand (f1, f2, f3).\n\
         FINGERS = {FINGERS}\n\
         #: Most joints a finger's plant command and measurement carry.\n\
         MAX_JOINTS = {MAX_JOINTS}\n\
         #: ``active_finger`` / ``finger`` value meaning \"no finger\".\n\
         NO_FINGER = 0x{NO_FINGER:X}\n\
         #: Attribute of the ``version`` service: the daemon's schema version (decimal).\n\
         VERSION_ATTRIBUTE_SCHEMA = \"{VERSION_ATTRIBUTE_SCHEMA}\"\n\
         #: Attribute of the ``version`` service: the daemon's build.\n\
         VERSION_ATTRIBUTE_BUILD = \"{VERSION_ATTRIBUTE_BUILD}\"\n\
         \n\
         u32 = ctypes.c_uint32\n\
         u64 = ctypes.c_uint64\n\
         f64 = ctypes.c_double\n\
         \n\
         # --------------------------------------------------------------------------- payloads\n\
         \n\
         \n\
         class Payload(ctypes.Structure):\n\
         \x20   \"\"\"A payload of the schema: a ctypes structure with its iceoryx2 type name.\"\"\"\n\
         \n\
         \x20   #: The iceoryx2 type name (must equal the Rust ``#[type_name]``).\n\
         \x20   _type_name: ClassVar[str] = \"\"\n\
         \n\
         \x20   @classmethod\n\
         \x20   def type_name(cls) -> str:\n\
         \x20       \"\"\"The iceoryx2 type name, which iceoryx2 compares with the daemon's.\"\"\"\n\
         \x20       return cls._type_name\n"
    );
    let all = layouts();
    for t in definition_order(&all) {
        let _ = write!(
            s,
            "\n\nclass {}(Payload):\n    \"\"\"{}\"\"\"\n\n    _type_name = \"{}\"\n    _fields_ = [\n",
            t.name,
            summary(t.name),
            t.type_name
        );
        for f in &t.fields {
            let unit = if f.unit.is_empty() {
                String::new()
            } else {
                format!("{}: ", f.unit)
            };
            comment(&mut s, "        ", "# ", &format!("{unit}{}", f.doc));
            let _ = writeln!(s, "        (\"{}\", {}),", f.name, ctype(&f.ty));
        }
        s.push_str("    ]\n");
    }
    s.push_str(
        "\n\n#: Every payload (the order of LAYOUT.md).\nPAYLOADS: tuple[type[Payload], ...] = (\n",
    );
    for t in &all {
        let _ = writeln!(s, "    {},", t.name);
    }
    s.push_str(")\n\n# --------------------------------------------------------------------------- codes\n");
    for (name, rows) in code_tables() {
        let _ = writeln!(
            s,
            "\n\nclass {name}(enum.IntEnum):\n    \"\"\"{}\"\"\"\n",
            summary(name)
        );
        for r in rows {
            comment(&mut s, "    ", "#: ", r.doc);
            let _ = writeln!(s, "    {} = {}", member(r.name), r.code);
        }
        if name == "GoalState" {
            let terminal: Vec<String> = GoalState::ALL
                .iter()
                .filter(|g| g.is_terminal())
                .map(|g| format!("            GoalState.{},\n", member(g.name())))
                .collect();
            let _ = write!(
                s,
                "\n    @property\n    def terminal(self) -> bool:\n        \
                 \"\"\"Whether the goal is over (no further transitions).\"\"\"\n        \
                 return self in (\n{}        )\n",
                terminal.concat()
            );
        }
    }
    s.push_str("\n\n#: Every code table, by its LAYOUT.md heading.\nCODE_TABLES: tuple[type[enum.IntEnum], ...] = (\n");
    for (name, _) in code_tables() {
        let _ = writeln!(s, "    {name},");
    }
    s.push_str(
        ")\n\n# --------------------------------------------------------------------------- bits\n",
    );
    let kinds = [LimitKind::Object, LimitKind::Fingertip, LimitKind::Rolling].map(every_limit_kind);
    let orders = [
        LimitOrder::Velocity,
        LimitOrder::Acceleration,
        LimitOrder::Jerk,
    ]
    .map(every_limit_order);
    bits(
        &mut s,
        "LimitKind",
        "IntEnum",
        "Motion kind of a limit override; mask bits 3*kind + order.",
        &kinds.map(|(n, k)| (n, k as u32)),
    );
    bits(
        &mut s,
        "LimitOrder",
        "IntEnum",
        "Derivative order of a limit override.",
        &orders.map(|(n, o)| (n, o as u32)),
    );
    for (n, k) in kinds {
        for (m, o) in orders {
            assert_eq!(limit_bit(k, o), 1 << (3 * k as u32 + o as u32), "{n} {m}");
        }
    }
    let _ = write!(
        s,
        "\n\n#: Every defined bit of ``Command.limit_mask``.\nLIMIT_MASK_ALL = {}\n",
        (1u32 << LIMIT_OVERRIDES) - 1
    );
    bits(
        &mut s,
        "Notify",
        "IntEnum",
        "Notification ids on ``<prefix>/notify``.",
        &[
            ("Status", EVENT_ID_STATUS as u32),
            ("Event", EVENT_ID_EVENT as u32),
            ("Answer", EVENT_ID_ANSWER as u32),
            ("DaemonDead", EVENT_ID_DAEMON_DEAD as u32),
        ],
    );
    bits(
        &mut s,
        "MeasuredMask",
        "IntFlag",
        "Bits of ``Status.measured_mask``: which measured fields are valid.",
        &[
            ("OBJECT", measured::OBJECT),
            ("TIPS", measured::TIPS),
            ("CONTACTS", measured::CONTACTS),
            ("FORCES", measured::FORCES),
            ("JOINTS", measured::JOINTS),
        ],
    );
    let _ = write!(
        s,
        "\n\n#: Every bit of ``Status.measured_mask``.\nMEASURED_MASK_ALL = {}\n",
        measured::ALL
    );
    bits(
        &mut s,
        "CommandFlags",
        "IntFlag",
        "Bits of ``PlantCommand.flags``.",
        &[
            ("ENABLE", command_flags::ENABLE),
            ("HOLD", command_flags::HOLD),
            ("LOCKSTEP", command_flags::LOCKSTEP),
            ("JOINTS", command_flags::JOINTS),
        ],
    );
    let _ = write!(
        s,
        "\n\n#: Every bit of ``PlantCommand.flags``.\nCOMMAND_FLAGS_ALL = {}\n",
        command_flags::ALL
    );
    bits(
        &mut s,
        "Valid",
        "IntFlag",
        "Bits of ``PlantMeasurement.valid``.",
        &[
            ("OBJECT_ORIENTATION", measurement_valid::OBJECT_ORIENTATION),
            ("OBJECT_VELOCITY", measurement_valid::OBJECT_VELOCITY),
            ("OBJECT_CENTER", measurement_valid::OBJECT_CENTER),
            ("TIP_POSE", measurement_valid::TIP_POSE),
            ("TIP_VELOCITY", measurement_valid::TIP_VELOCITY),
            ("CONTACT", measurement_valid::CONTACT),
            ("FORCE", measurement_valid::FORCE),
            ("ROLL", measurement_valid::ROLL),
            ("JOINT_POSITION", measurement_valid::JOINT_POSITION),
            ("JOINT_VELOCITY", measurement_valid::JOINT_VELOCITY),
            ("JOINT_TORQUE", measurement_valid::JOINT_TORQUE),
        ],
    );
    let _ = write!(
        s,
        "\n\n#: What the daemon needs to control a hand of free fingertips.\nVALID_REQUIRED = {}\n\
         #: What the daemon needs to control a hand of finger chains.\nVALID_REQUIRED_JOINTS = {}\n\
         #: Every bit of ``PlantMeasurement.valid``.\nVALID_ALL = {}\n",
        measurement_valid::REQUIRED,
        measurement_valid::REQUIRED_JOINTS,
        measurement_valid::ALL
    );
    bits(
        &mut s,
        "PlantState",
        "IntFlag",
        "Bits of ``PlantMeasurement.state``.",
        &[
            ("SIMULATED", plant_state::SIMULATED),
            ("PAUSED", plant_state::PAUSED),
            ("FAULT", plant_state::FAULT),
        ],
    );
    let _ = write!(
        s,
        "\n\n#: Every bit of ``PlantMeasurement.state``.\nPLANT_STATE_ALL = {}\n",
        plant_state::ALL
    );
    s
}

#[cfg(test)]
mod tests {
    use super::ctype;

    #[test]
    fn arrays_of_arrays_become_ctypes_arrays_of_arrays() {
        assert_eq!(ctype("u32"), "u32");
        assert_eq!(ctype("[f64; 4]"), "f64 * 4");
        assert_eq!(ctype("[FingerStatus; 3]"), "FingerStatus * 3");
        assert_eq!(ctype("[[f64; 3]; 3]"), "f64 * 3 * 3");
        assert_eq!(ctype("[[f64; 3]; 256]"), "f64 * 3 * 256");
    }
}

"""ctypes mirror of the gaitd shared-memory schema (``shm_schema/LAYOUT.md``).

Why a hand-written mirror: iceoryx2 opens a service only when the payload's
type name, size and alignment equal the Rust ones, and Python cannot read
the Rust types. So every payload is declared here field by field, with the
exact iceoryx2 type name (``type_name()``) and explicit padding, and
:func:`check_layout` compares the mirror against the generated document
(type names, sizes, alignments, every field's offset and size, every code
table, the bit constants, the service names). A mirror that drifts from the
daemon fails that check instead of misreading memory.

Enums travel as ``u32`` codes; the tables below are :class:`enum.IntEnum`
so that ``ReasonCode(19).name == "NoPlan"``. A reader never trusts another
process's bytes: decode codes with :func:`decode` (``None`` for an unknown
code) rather than indexing tables blindly.
"""

from __future__ import annotations

import ctypes
import enum
import re
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar, TypeVar
from collections.abc import Iterable

#: Version of the payload layout (part of every type name).
SCHEMA_VERSION = 4
#: The iceoryx2 release the daemon is built with; resource names are
#: version-tagged, so the Python bindings must be exactly this version.
ICEORYX2_VERSION = "0.10.0"
#: Default service-name prefix.
DEFAULT_PREFIX = "gaitd"
#: Fingers of the hand (f1, f2, f3).
FINGERS = 3
#: ``active_finger`` / ``finger`` value meaning "no finger".
NO_FINGER = 0xFFFF_FFFF

u32 = ctypes.c_uint32
u64 = ctypes.c_uint64
f64 = ctypes.c_double

_P = TypeVar("_P", bound=ctypes.Structure)


def _v(name: str) -> str:
    return f"gaitd::{name}.v{SCHEMA_VERSION}"


class Payload(ctypes.Structure):
    """A payload of the schema: a ctypes structure with its iceoryx2 type name."""

    #: The iceoryx2 type name (must equal the Rust ``#[type_name]``).
    _type_name: ClassVar[str] = ""

    @classmethod
    def type_name(cls) -> str:
        """The iceoryx2 type name, which iceoryx2 compares with the daemon's."""
        return cls._type_name


# --------------------------------------------------------------------------- payloads


class MotionLimits(Payload):
    """Velocity, acceleration and jerk limit overrides of one motion kind."""

    _type_name = _v("MotionLimits")

    _fields_ = [("velocity", f64), ("acceleration", f64), ("jerk", f64)]


class Command(Payload):
    """client → daemon: a goal, cancel, hold or reset."""

    _type_name = _v("Command")

    _fields_ = [
        ("kind", u32),
        ("frame", u32),
        ("client_id", u64),
        ("request_id", u64),
        ("goal_id", u64),
        ("target", f64 * 4),
        ("limit_mask", u32),
        ("reserved", u32),
        ("object_limits", MotionLimits),
        ("fingertip_limits", MotionLimits),
        ("rolling_limits", MotionLimits),
    ]


class Answer(Payload):
    """daemon → client: one per command, matched by client_id + request_id."""

    _type_name = _v("Answer")

    _fields_ = [
        ("client_id", u64),
        ("request_id", u64),
        ("goal_id", u64),
        ("command", u32),
        ("code", u32),
        ("reason", u32),
        ("reserved", u32),
        ("tick", u64),
        ("instance", u64),
    ]


class GoalStatus(Payload):
    """The current goal and its progress (part of :class:`Status`)."""

    _type_name = _v("GoalStatus")

    _fields_ = [
        ("goal_id", u64),
        ("client_id", u64),
        ("state", u32),
        ("reason", u32),
        ("remaining_angle", f64),
        ("eta", f64),
        ("gaits_done", u32),
        ("gaits_planned", u32),
        ("active_finger", u32),
        ("reserved", u32),
    ]


class FingerStatus(Payload):
    """One finger in the status: commanded and measured."""

    _type_name = _v("FingerStatus")

    _fields_ = [
        ("state", u32),
        ("measured_contact", u32),
        ("contact_hand", f64 * 3),
        ("contact_object", f64 * 3),
        ("commanded_tip_position", f64 * 3),
        ("commanded_tip_orientation", f64 * 4),
        ("tip_contact", f64 * 3),
        ("roll", f64),
        ("workspace_margin", f64),
        ("commanded_normal_force", f64),
        ("measured_tip_position", f64 * 3),
        ("measured_tip_orientation", f64 * 4),
        ("measured_normal_force", f64),
        ("tip_error", f64),
    ]


class Timing(Payload):
    """Loop timing statistics (part of :class:`Status`)."""

    _type_name = _v("Timing")

    _fields_ = [
        ("period_ns", u64),
        ("compute_last_ns", u64),
        ("compute_p50_ns", u64),
        ("compute_p99_ns", u64),
        ("compute_max_ns", u64),
        ("jitter_last_ns", u64),
        ("jitter_p99_ns", u64),
        ("jitter_max_ns", u64),
        ("overruns", u64),
        ("jitter_hist", u64 * 16),
        ("plant_commands_late", u64),
        ("plant_commands_repeated", u64),
        ("plant_measurements_late", u64),
        ("plant_measurements_repeated", u64),
        ("plant_misses_in_row", u64),
        ("plant_misses_in_row_max", u64),
    ]


class Status(Payload):
    """daemon → clients, every tick (latest value)."""

    _type_name = _v("Status")

    _fields_ = [
        ("tick", u64),
        ("time_ns", u64),
        ("publish_time_ns", u64),
        ("instance", u64),
        ("daemon_state", u32),
        ("phase", u32),
        ("fault", u32),
        ("grasp", u32),
        ("grasp_margin", f64),
        ("load_grip", f64),
        ("load_margin", f64),
        ("commanded_object_q", f64 * 4),
        ("commanded_object_omega", f64 * 3),
        ("measured_object_q", f64 * 4),
        ("object_error", f64),
        ("measured_tick", u64),
        ("measured_mask", u32),
        ("measured_age", u32),
        ("goal", GoalStatus),
        ("fingers", FingerStatus * FINGERS),
        ("timing", Timing),
        ("commands", u64),
        ("rejected", u64),
        ("clients", u32),
        ("reserved", u32),
    ]


class Event(Payload):
    """daemon → clients, with history: goal transitions, gaits, faults."""

    _type_name = _v("Event")

    _fields_ = [
        ("seq", u64),
        ("tick", u64),
        ("time_ns", u64),
        ("instance", u64),
        ("kind", u32),
        ("finger", u32),
        ("state", u32),
        ("reason", u32),
        ("goal_id", u64),
        ("client_id", u64),
        ("fault", u32),
        ("reserved", u32),
        ("count", u64),
        ("value", f64),
    ]


class PlantFingerCommand(Payload):
    """One fingertip's setpoint (part of :class:`PlantCommand`)."""

    _type_name = _v("PlantFingerCommand")

    _fields_ = [
        ("mode", u32),
        ("reserved", u32),
        ("position", f64 * 3),
        ("orientation", f64 * 4),
        ("velocity", f64 * 3),
        ("angular_velocity", f64 * 3),
        ("acceleration", f64 * 3),
        ("roll", f64),
        ("grip_force", f64),
    ]


class PlantCommand(Payload):
    """daemon → plant, every tick."""

    _type_name = _v("PlantCommand")

    _fields_ = [
        ("session", u64),
        ("seq", u64),
        ("answers", u64),
        ("target_time_ns", u64),
        ("period_ns", u64),
        ("flags", u32),
        ("reserved", u32),
        ("object_q", f64 * 4),
        ("object_omega", f64 * 3),
        ("fingers", PlantFingerCommand * FINGERS),
    ]


class PlantFingerMeasurement(Payload):
    """One fingertip as measured (part of :class:`PlantMeasurement`)."""

    _type_name = _v("PlantFingerMeasurement")

    _fields_ = [
        ("contact", u32),
        ("reserved", u32),
        ("position", f64 * 3),
        ("orientation", f64 * 4),
        ("velocity", f64 * 3),
        ("angular_velocity", f64 * 3),
        ("roll", f64),
        ("normal_force", f64),
    ]


class PlantMeasurement(Payload):
    """plant → daemon, one per plant step."""

    _type_name = _v("PlantMeasurement")

    _fields_ = [
        ("session", u64),
        ("seq", u64),
        ("applied", u64),
        ("time_ns", u64),
        ("valid", u32),
        ("state", u32),
        ("fault", u32),
        ("reserved", u32),
        ("object_q", f64 * 4),
        ("object_omega", f64 * 3),
        ("object_center", f64 * 3),
        ("fingers", PlantFingerMeasurement * FINGERS),
    ]


#: Every mirrored payload (the order of LAYOUT.md).
PAYLOADS: tuple[type[Payload], ...] = (
    Command,
    MotionLimits,
    Answer,
    Status,
    GoalStatus,
    FingerStatus,
    Timing,
    Event,
    PlantCommand,
    PlantFingerCommand,
    PlantMeasurement,
    PlantFingerMeasurement,
)

# --------------------------------------------------------------------------- codes


class CommandKind(enum.IntEnum):
    """What a :class:`Command` asks."""

    Goal = 1
    Cancel = 2
    Hold = 3
    Reset = 4


class GoalFrame(enum.IntEnum):
    """Meaning of a goal's target."""

    Absolute = 1
    Relative = 2
    AxisAngle = 3


class AnswerCode(enum.IntEnum):
    """Accepted or rejected."""

    Accepted = 1
    Rejected = 2


class GoalState(enum.IntEnum):
    """Goal lifecycle (SPEC §6.4)."""

    None_ = 0
    Accepted = 1
    Planning = 2
    Executing = 3
    Succeeded = 4
    Aborted = 5
    Canceled = 6
    Preempted = 7
    Rejected = 8

    @property
    def terminal(self) -> bool:
        """Whether the goal is over."""
        return self >= GoalState.Succeeded


class ReasonCode(enum.IntEnum):
    """Why a command was rejected or a goal ended."""

    None_ = 0
    UnknownCommandKind = 1
    UnknownGoalFrame = 2
    ZeroGoalId = 3
    ZeroClientId = 4
    NonFiniteQuaternion = 5
    ZeroQuaternion = 6
    NonUnitQuaternion = 7
    BadLimitMask = 8
    NonFiniteLimit = 9
    NonPositiveLimit = 10
    NonZeroReserved = 11
    DuplicateGoalId = 12
    LimitAboveConfigured = 13
    PlannerUnavailable = 14
    Faulted = 15
    UnknownGoalId = 16
    NoActiveGoal = 17
    ShuttingDown = 18
    NoPlan = 19
    NotFaulted = 20
    PreemptedByGoal = 21
    CanceledByClient = 22
    HoldRequested = 23
    FaultDetected = 24
    Reached = 25
    BadAxisAngle = 26
    LimitBelowMinimum = 27
    StartNotForceClosure = 28
    StartNotFinite = 29
    NoTwoFingerGrasp = 30
    FingerBlocked = 31
    InvalidGoalTarget = 32
    MeasuredStateInvalid = 33
    LoadInfeasible = 34
    PlanTimeout = 35
    NoFreshMeasurement = 36
    NotAtRest = 37


class Phase(enum.IntEnum):
    """Controller phase."""

    Hold = 1
    Roll = 2
    Rotate = 3
    Place = 4
    Lift = 5
    Stopping = 6
    SafeHold = 7


class FingerPhase(enum.IntEnum):
    """A finger's state in the status."""

    Grasping = 1
    Rolling = 2
    Lifting = 3
    Free = 4
    Placing = 5


class GraspState(enum.IntEnum):
    """Force closure of the grasping fingers."""

    Unknown = 0
    ForceClosure = 1
    NotForceClosure = 2


class FaultCode(enum.IntEnum):
    """The controller's fault."""

    None_ = 0
    ForceClosureLost = 1
    WorkspaceViolation = 2
    FingertipViolation = 3
    FingertipCollision = 4
    Slip = 5
    MeasurementMissing = 6
    StuckFinger = 7
    NonFiniteState = 8
    PlantLost = 9
    PlantInvalid = 10
    PlantSequence = 11
    PlantFault = 12
    ContactLost = 13
    PlantWaiting = 14
    PlantTiming = 15


class EventKind(enum.IntEnum):
    """What an :class:`Event` reports."""

    GoalTransition = 1
    Place = 2
    Lift = 3
    Roll = 4
    Substitution = 5
    Rewind = 6
    Fault = 7
    FaultCleared = 8
    Overrun = 9
    ClientsCleaned = 10
    DaemonStarted = 11
    DaemonStopping = 12
    Hold = 13
    Drift = 14
    NearLimit = 15


class DaemonState(enum.IntEnum):
    """Running, or the final status."""

    Running = 1
    Stopped = 2


class PlantFingerMode(enum.IntEnum):
    """What a fingertip is asked to do (:class:`PlantFingerCommand`)."""

    Grasping = 1
    Free = 2
    Placing = 3
    Lifting = 4


class PlantFault(enum.IntEnum):
    """A plant's own fault (:class:`PlantMeasurement`)."""

    None_ = 0
    EmergencyStop = 1
    Hardware = 2
    Limit = 3
    Diverged = 4
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


def code_name(member: enum.IntEnum) -> str:
    """The document's name of a code (``None_`` is spelled ``None`` there)."""
    return "None" if member.name == "None_" else member.name


def decode(table: type[enum.IntEnum], value: int) -> enum.IntEnum | None:
    """The code ``value`` of ``table``, or None when it is unknown (never trust the bytes)."""
    try:
        return table(value)
    except ValueError:
        return None


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


def limit_bit(kind: LimitKind, order: LimitOrder) -> int:
    """Bit of ``Command.limit_mask`` for one override."""
    return 1 << (3 * int(kind) + int(order))


#: Every defined bit of ``Command.limit_mask``.
LIMIT_MASK_ALL = (1 << 9) - 1


class Notify(enum.IntEnum):
    """Notification ids on ``<prefix>/notify``."""

    Status = 1
    Event = 2
    Answer = 3
    DaemonDead = 4


#: Notification id on ``plant/commanded`` and ``plant/measured``.
PLANT_EVENT_ID = 1


class MeasuredMask(enum.IntFlag):
    """Bits of ``Status.measured_mask``: which measured fields are valid."""

    OBJECT = 1
    TIPS = 2
    CONTACTS = 4
    FORCES = 8


class CommandFlags(enum.IntFlag):
    """Bits of ``PlantCommand.flags``."""

    ENABLE = 1
    HOLD = 2
    LOCKSTEP = 4


COMMAND_FLAGS_ALL = int(CommandFlags.ENABLE | CommandFlags.HOLD | CommandFlags.LOCKSTEP)


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


#: What the daemon needs to control the hand.
VALID_REQUIRED = int(Valid.OBJECT_ORIENTATION | Valid.TIP_POSE | Valid.CONTACT | Valid.ROLL)
VALID_ALL = 255


class PlantState(enum.IntFlag):
    """Bits of ``PlantMeasurement.state``."""

    SIMULATED = 1
    PAUSED = 2
    FAULT = 4


PLANT_STATE_ALL = 7

# (field, {bit value: name as the document's meaning column spells it})
_DOCUMENTED_BITS: tuple[tuple[str, str, dict[int, str]], ...] = (
    ("Status", "measured_mask", {1: "OBJECT", 2: "TIPS", 4: "CONTACTS", 8: "FORCES"}),
    ("PlantCommand", "flags", {1: "ENABLE", 2: "HOLD", 4: "LOCKSTEP"}),
    (
        "PlantMeasurement",
        "valid",
        {
            1: "object_q",
            2: "object_omega",
            4: "object_center",
            8: "tip pose",
            16: "tip velocity",
            32: "contact",
            64: "normal_force",
            128: "roll",
        },
    ),
    ("PlantMeasurement", "state", {1: "SIMULATED", 2: "PAUSED", 4: "FAULT"}),
)

# --------------------------------------------------------------------------- services


@dataclass(frozen=True)
class ServiceNames:
    """Every service name under one prefix."""

    prefix: str

    @property
    def commands(self) -> str:
        """client → daemon commands."""
        return f"{self.prefix}/commands"

    @property
    def answers(self) -> str:
        """daemon → client answers."""
        return f"{self.prefix}/answers"

    @property
    def status(self) -> str:
        """daemon → clients status (latest value)."""
        return f"{self.prefix}/status"

    @property
    def events(self) -> str:
        """daemon → clients events (with history)."""
        return f"{self.prefix}/events"

    @property
    def notify(self) -> str:
        """daemon → clients wake-ups."""
        return f"{self.prefix}/notify"

    @property
    def plant_command(self) -> str:
        """daemon → plant commands."""
        return f"{self.prefix}/plant/command"

    @property
    def plant_measurement(self) -> str:
        """plant → daemon measurements."""
        return f"{self.prefix}/plant/measurement"

    @property
    def plant_commanded(self) -> str:
        """daemon → plant wake-up."""
        return f"{self.prefix}/plant/commanded"

    @property
    def plant_measured(self) -> str:
        """plant → daemon wake-up."""
        return f"{self.prefix}/plant/measured"

    @property
    def version(self) -> str:
        """The daemon's schema version and build (event service attributes; any version opens it)."""
        return f"{self.prefix}/version"


# (service suffix, pattern, payload) as LAYOUT.md's service table lists them
_SERVICES: tuple[tuple[str, str, str | None], ...] = (
    ("commands", "publish-subscribe", "Command"),
    ("answers", "publish-subscribe", "Answer"),
    ("status", "publish-subscribe", "Status"),
    ("events", "publish-subscribe", "Event"),
    ("notify", "event", None),
    ("plant/command", "publish-subscribe", "PlantCommand"),
    ("plant/measurement", "publish-subscribe", "PlantMeasurement"),
    ("plant/commanded", "event", None),
    ("plant/measured", "event", None),
    ("version", "event", None),
)

#: Attributes of the ``version`` service: the daemon's schema version (decimal) and build.
VERSION_ATTRIBUTE_SCHEMA = "gaitd.schema"
VERSION_ATTRIBUTE_BUILD = "gaitd.build"

# --------------------------------------------------------------------------- helpers


def to_python(value: Any) -> Any:
    """A ctypes structure or array as plain dicts, lists and numbers (for JSON, printing)."""
    if isinstance(value, ctypes.Structure):
        return {f[0]: to_python(getattr(value, f[0])) for f in value._fields_}
    if isinstance(value, ctypes.Array):
        return [to_python(v) for v in value]
    return value


def copy_from(sample_payload: Any, cls: type[_P]) -> _P:
    """A private copy of a received payload (the sample's memory is lent, and may be reused)."""
    return cls.from_buffer_copy(sample_payload.contents)


# --------------------------------------------------------------------------- layout check


class LayoutMismatch(Exception):
    """The mirror and LAYOUT.md disagree; ``problems`` lists every difference."""

    def __init__(self, problems: list[str]):
        super().__init__("schema mirror differs from LAYOUT.md:\n  " + "\n  ".join(problems))
        self.problems = problems


@dataclass
class _DocType:
    type_name: str
    size: int
    align: int
    fields: list[tuple[str, int, int, str]]  # name, offset, size, meaning


@dataclass
class LayoutDocument:
    """What LAYOUT.md states: payload tables, code tables, services, notification ids."""

    version: int | None
    types: dict[str, _DocType]
    codes: dict[str, dict[str, int]]
    services: list[tuple[str, str, str | None]]
    notify_ids: dict[int, str]


_HEAD = re.compile(r"^### `(\w+)`(?: \(`([^`]+)`, (\d+) bytes, align (\d+)\))?\s*$")
_FIELD_ROW = re.compile(r"^\| (\d+) \| (\d+) \| `(\w+)` \|[^|]*\|[^|]*\| (.*) \|\s*$")
_CODE_ROW = re.compile(r"^\| (\d+) \| `(\w+)` \|")
_SERVICE_ROW = re.compile(r"^\| `([^`]+)` \| ([\w-]+) \| (`(\w+)`|—) \|")


def parse_layout(path: str | Path) -> LayoutDocument:
    """Reads the generated LAYOUT.md into a :class:`LayoutDocument`."""
    text = Path(path).read_text(encoding="utf-8")
    version = None
    if m := re.search(r"^# gaitd shared-memory schema v(\d+)", text, re.M):
        version = int(m.group(1))
    types: dict[str, _DocType] = {}
    codes: dict[str, dict[str, int]] = {}
    services: list[tuple[str, str, str | None]] = []
    current, kind = "", None
    for line in text.splitlines():
        if m := _HEAD.match(line):
            name, tname, size, align = m.groups()
            current = name
            if tname:
                kind = "type"
                types[name] = _DocType(tname, int(size), int(align), [])
            else:
                kind = "code"
                codes[name] = {}
            continue
        if line.startswith("## "):
            kind = "services" if line.startswith("## Services") else None
            continue
        if kind == "type" and (m := _FIELD_ROW.match(line)):
            off, size, field, meaning = m.groups()
            types[current].fields.append((field, int(off), int(size), meaning.strip()))
        elif kind == "code" and (m := _CODE_ROW.match(line)):
            value, cname = m.groups()
            codes[current][cname] = int(value)
        elif kind == "services" and (m := _SERVICE_ROW.match(line)):
            services.append((m.group(1), m.group(2), m.group(4)))
    notify_ids: dict[int, str] = {}
    if m := re.search(r"^Notification ids on `[^`]+/notify`: (.*)$", text, re.M):
        for value, what in re.findall(r"(\d+) = ([^,.]+)", m.group(1)):
            notify_ids[int(value)] = what.strip()
    return LayoutDocument(version, types, codes, services, notify_ids)


def _check_struct(cls: type[Payload], doc: _DocType | None, problems: list[str]) -> None:
    name = cls.__name__
    if doc is None:
        problems.append(f"{name}: not in the document")
        return
    if cls.type_name() != doc.type_name:
        problems.append(f"{name}: type name {cls.type_name()!r}, document {doc.type_name!r}")
    if ctypes.sizeof(cls) != doc.size:
        problems.append(f"{name}: size {ctypes.sizeof(cls)}, document {doc.size}")
    if ctypes.alignment(cls) != doc.align:
        problems.append(f"{name}: alignment {ctypes.alignment(cls)}, document {doc.align}")
    mine = [(n, getattr(cls, n).offset, getattr(cls, n).size) for n, *_ in cls._fields_]
    theirs = [(n, off, size) for n, off, size, _ in doc.fields]
    if mine != theirs:
        for i in range(max(len(mine), len(theirs))):
            a = mine[i] if i < len(mine) else None
            b = theirs[i] if i < len(theirs) else None
            if a != b:
                problems.append(f"{name} field #{i}: mirror {a} (name, offset, size), document {b}")
                break


def _check_codes(table: type[enum.IntEnum], doc: dict[str, int] | None, problems: list[str]) -> None:
    name = table.__name__
    if doc is None:
        problems.append(f"code table {name}: not in the document")
        return
    mine = {code_name(m): int(m) for m in table}
    if mine != doc:
        missing = sorted(set(doc.items()) - set(mine.items()))
        extra = sorted(set(mine.items()) - set(doc.items()))
        problems.append(
            f"code table {name}: document has {missing} not in the mirror, mirror has {extra} not in the document"
        )


def _check_bits(doc: LayoutDocument, problems: list[str]) -> None:
    for type_name, field, bits in _DOCUMENTED_BITS:
        t = doc.types.get(type_name)
        meaning = next((m for n, _, _, m in t.fields if n == field), None) if t else None
        if meaning is None:
            problems.append(f"{type_name}.{field}: not in the document")
            continue
        for value, label in bits.items():
            if not re.search(rf"(?<!\d){value} {re.escape(label)}\b", meaning):
                problems.append(f"{type_name}.{field}: bit {value} {label!r} not stated in {meaning!r}")
    mirror_flags = {
        "Status.measured_mask": {int(b): b.name for b in MeasuredMask},
        "PlantCommand.flags": {int(b): b.name for b in CommandFlags},
        "PlantMeasurement.state": {int(b): b.name for b in PlantState},
    }
    for type_name, field, bits in _DOCUMENTED_BITS:
        key = f"{type_name}.{field}"
        if key in mirror_flags and mirror_flags[key] != bits:
            problems.append(f"{key}: mirror bits {mirror_flags[key]} differ from the table {bits}")
    valid = {1 << i for i in range(8)}
    if {int(b) for b in Valid} != valid or VALID_ALL != sum(valid):
        problems.append("PlantMeasurement.valid: mirror bits are not 1..128")
    m = doc.types.get("PlantMeasurement")
    meaning = next((x for n, _, _, x in m.fields if n == "valid"), "") if m else ""
    if req := re.search(r"required: ([\d, ]+)", meaning):
        stated = sum(int(v) for v in req.group(1).split(","))
        if stated != VALID_REQUIRED:
            problems.append(f"PlantMeasurement.valid: required bits {stated}, mirror {VALID_REQUIRED}")
    else:
        problems.append("PlantMeasurement.valid: the document states no required bits")


def _check_services(doc: LayoutDocument, problems: list[str]) -> None:
    want = [(f"{DEFAULT_PREFIX}/{suffix}", pattern, payload) for suffix, pattern, payload in _SERVICES]
    if doc.services != want:
        problems.append(f"services: document {doc.services}, mirror {want}")
    names = ServiceNames(DEFAULT_PREFIX)
    for suffix, _, _ in _SERVICES:
        attr = suffix.replace("/", "_")
        if getattr(names, attr) != f"{DEFAULT_PREFIX}/{suffix}":
            problems.append(f"ServiceNames.{attr} is not {DEFAULT_PREFIX}/{suffix}")
    ids = {int(n): n.name for n in Notify}
    stated = {k: v.split()[0] for k, v in doc.notify_ids.items()}
    expect = {1: "status", 2: "event", 3: "answer", 4: "daemon"}
    if stated != expect or set(ids) != set(expect):
        problems.append(f"notification ids: document {doc.notify_ids}, mirror {ids}")


def layout_problems(
    path: str | Path,
    payloads: Iterable[type[Payload]] = PAYLOADS,
    code_tables: Iterable[type[enum.IntEnum]] = CODE_TABLES,
) -> list[str]:
    """Every difference between the mirror and the document (empty: they agree)."""
    doc = parse_layout(path)
    problems: list[str] = []
    if doc.version != SCHEMA_VERSION:
        problems.append(f"document is schema v{doc.version}, mirror v{SCHEMA_VERSION}")
    payloads = list(payloads)
    for cls in payloads:
        _check_struct(cls, doc.types.get(cls.__name__), problems)
    mirrored = {c.__name__ for c in payloads}
    for name in doc.types:
        if name not in mirrored:
            problems.append(f"{name}: in the document, not mirrored")
    tables = list(code_tables)
    for table in tables:
        _check_codes(table, doc.codes.get(table.__name__), problems)
    for name in sorted(set(doc.codes) - {t.__name__ for t in tables}):
        problems.append(f"code table {name}: in the document, not mirrored")
    _check_bits(doc, problems)
    _check_services(doc, problems)
    return problems


def check_layout(
    path: str | Path,
    payloads: Iterable[type[Payload]] = PAYLOADS,
    code_tables: Iterable[type[enum.IntEnum]] = CODE_TABLES,
) -> None:
    """Raises :class:`LayoutMismatch` unless every mirror matches LAYOUT.md exactly.

    Checked: each payload's type name, size, alignment and every field's
    name, offset and size (in order); each code table's names and values;
    the documented bit constants; the service table; the notification ids.
    """
    problems = layout_problems(path, payloads, code_tables)
    if problems:
        raise LayoutMismatch(problems)


def main(argv: list[str] | None = None) -> int:
    """``python -m gaitd.schema LAYOUT.md``: check the mirror, exit 1 on any difference."""
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m gaitd.schema path/to/LAYOUT.md", file=sys.stderr)
        return 2
    problems = layout_problems(args[0])
    for p in problems:
        print(f"MISMATCH {p}")
    if not problems:
        print(f"OK {len(PAYLOADS)} payloads, {len(CODE_TABLES)} code tables match {args[0]}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

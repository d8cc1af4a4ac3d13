"""The gaitd shared-memory schema for Python (``shm_schema/LAYOUT.md``): payloads, codes, helpers.

iceoryx2 opens a service only when the payload's type name, size and
alignment equal the Rust ones, and Python cannot read the Rust types. So
every payload is mirrored as a ctypes structure with the exact iceoryx2 type
name (``type_name()``) and explicit padding, in :mod:`gaitd.layout`, which
is generated from the Rust layout code (a cargo test fails when it is stale)
and re-exported here. This module adds the helpers and
:func:`check_layout`, which compares the mirror against the generated
document (type names, sizes, alignments, every field's offset and size,
every code table, the bit constants, the service names): a mirror that
drifts from the daemon fails that check instead of misreading memory.

Enums travel as ``u32`` codes; the tables are :class:`enum.IntEnum` so that
``ReasonCode(19).name == "NoPlan"``. A reader never trusts another
process's bytes: decode codes with :func:`decode` (``None`` for an unknown
code) rather than indexing tables blindly.
"""

from __future__ import annotations

import ctypes
import enum
import re
import sys
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, TypeVar

from .layout import (
    CODE_TABLES,
    COMMAND_FLAGS_ALL,
    DEFAULT_PREFIX,
    FINGERS,
    ICEORYX2_VERSION,
    LIMIT_MASK_ALL,
    MAX_JOINTS,
    MEASURED_MASK_ALL,
    NO_FINGER,
    PAYLOADS,
    PLANT_STATE_ALL,
    SCHEMA_VERSION,
    VALID_ALL,
    VALID_REQUIRED,
    VALID_REQUIRED_JOINTS,
    VERSION_ATTRIBUTE_BUILD,
    VERSION_ATTRIBUTE_SCHEMA,
    Answer,
    AnswerCode,
    Command,
    CommandFlags,
    CommandKind,
    DaemonState,
    Event,
    EventKind,
    FaultCode,
    FingerPhase,
    FingerStatus,
    GoalFrame,
    GoalState,
    GoalStatus,
    GraspState,
    LimitKind,
    LimitOrder,
    MeasuredMask,
    MotionLimits,
    Notify,
    PathPoint,
    Payload,
    Phase,
    PlanPath,
    PlantCommand,
    PlantFault,
    PlantFingerCommand,
    PlantFingerMeasurement,
    PlantFingerMode,
    PlantMeasurement,
    PlantState,
    ReasonCode,
    Status,
    Timing,
    Valid,
)

__all__ = [
    "CODE_TABLES",
    "COMMAND_FLAGS_ALL",
    "DEFAULT_PREFIX",
    "FINGERS",
    "ICEORYX2_VERSION",
    "LIMIT_MASK_ALL",
    "MAX_JOINTS",
    "MEASURED_MASK_ALL",
    "NO_FINGER",
    "PAYLOADS",
    "PLANT_EVENT_ID",
    "PLANT_STATE_ALL",
    "SCHEMA_VERSION",
    "VALID_ALL",
    "VALID_REQUIRED",
    "VALID_REQUIRED_JOINTS",
    "VERSION_ATTRIBUTE_BUILD",
    "VERSION_ATTRIBUTE_SCHEMA",
    "Answer",
    "AnswerCode",
    "Command",
    "CommandFlags",
    "CommandKind",
    "DaemonState",
    "Event",
    "EventKind",
    "FaultCode",
    "FingerPhase",
    "FingerStatus",
    "GoalFrame",
    "GoalState",
    "GoalStatus",
    "GraspState",
    "LayoutDocument",
    "LayoutMismatch",
    "LimitKind",
    "LimitOrder",
    "MeasuredMask",
    "MotionLimits",
    "Notify",
    "PathPoint",
    "Payload",
    "Phase",
    "PlanPath",
    "PlantCommand",
    "PlantFault",
    "PlantFingerCommand",
    "PlantFingerMeasurement",
    "PlantFingerMode",
    "PlantMeasurement",
    "PlantState",
    "ReasonCode",
    "ServiceNames",
    "Status",
    "Timing",
    "Valid",
    "check_layout",
    "code_name",
    "copy_from",
    "decode",
    "layout_problems",
    "limit_bit",
    "main",
    "parse_layout",
    "to_python",
]

_P = TypeVar("_P", bound=ctypes.Structure)

# --------------------------------------------------------------------------- codes and bits


def code_name(member: enum.IntEnum) -> str:
    """The document's name of a code (``None_`` is spelled ``None`` there)."""
    return "None" if member.name == "None_" else member.name


def decode(table: type[enum.IntEnum], value: int) -> enum.IntEnum | None:
    """The code ``value`` of ``table``, or None when it is unknown (never trust the bytes)."""
    try:
        return table(value)
    except ValueError:
        return None


def limit_bit(kind: LimitKind, order: LimitOrder) -> int:
    """Bit of ``Command.limit_mask`` for one override."""
    return 1 << (3 * int(kind) + int(order))


#: Notification id on ``plant/commanded`` and ``plant/measured``.
PLANT_EVENT_ID = 1

# (payload, field, {bit value: name as the document's meaning column spells it})
_DOCUMENTED_BITS: tuple[tuple[str, str, dict[int, str]], ...] = (
    ("Status", "measured_mask", {1: "OBJECT", 2: "TIPS", 4: "CONTACTS", 8: "FORCES", 16: "JOINTS"}),
    ("PlantCommand", "flags", {1: "ENABLE", 2: "HOLD", 4: "LOCKSTEP", 8: "JOINTS"}),
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
            256: "joint positions",
            512: "joint velocities",
            1024: "joint torques",
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
    def plan(self) -> str:
        """daemon → clients each plan's path (latest value)."""
        return f"{self.prefix}/plan"

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
    ("plan", "publish-subscribe", "PlanPath"),
    ("plant/command", "publish-subscribe", "PlantCommand"),
    ("plant/measurement", "publish-subscribe", "PlantMeasurement"),
    ("plant/commanded", "event", None),
    ("plant/measured", "event", None),
    ("version", "event", None),
)

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
    valid = {1 << i for i in range(11)}
    if {int(b) for b in Valid} != valid or VALID_ALL != sum(valid):
        problems.append("PlantMeasurement.valid: mirror bits are not 1..1024")
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

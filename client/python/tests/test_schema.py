"""The ctypes mirror of the schema (``gaitd.schema``): layouts without implicit padding, type names,
code tables read defensively, bit constants, and the LAYOUT.md reader and comparison.

That the mirror equals the generated LAYOUT.md is the cargo test ``python_schema``; these tests
check the mirror's own invariants and that the comparison finds what differs.
"""

from __future__ import annotations

import ctypes
import enum
from pathlib import Path

import pytest

from gaitd import schema
from gaitd.schema import (
    CODE_TABLES,
    COMMAND_FLAGS_ALL,
    LIMIT_MASK_ALL,
    PAYLOADS,
    PLANT_STATE_ALL,
    VALID_ALL,
    VALID_REQUIRED,
    Command,
    CommandFlags,
    GoalState,
    LimitKind,
    LimitOrder,
    MotionLimits,
    Payload,
    PlantFault,
    PlantState,
    ReasonCode,
    ServiceNames,
    Valid,
    code_name,
    decode,
    layout_problems,
    limit_bit,
    parse_layout,
    to_python,
)


@pytest.mark.parametrize("cls", PAYLOADS, ids=lambda c: c.__name__)
def test_payload_has_no_implicit_padding(cls: type[Payload]) -> None:
    """Every byte belongs to a field (padding is an explicit ``reserved`` field): offsets are
    contiguous and the size is their sum, a multiple of the 8-byte alignment."""
    end = 0
    for f in cls._fields_:
        field = getattr(cls, f[0])
        assert field.offset == end, f"{cls.__name__}.{f[0]} at {field.offset}, previous field ends at {end}"
        end += field.size
    assert ctypes.sizeof(cls) == end
    assert ctypes.alignment(cls) == 8
    assert end % 8 == 0


@pytest.mark.parametrize("cls", PAYLOADS, ids=lambda c: c.__name__)
def test_type_name_is_versioned(cls: type[Payload]) -> None:
    assert cls.type_name() == f"gaitd::{cls.__name__}.v{schema.SCHEMA_VERSION}"


def test_every_payload_is_listed_once() -> None:
    declared = {c for c in vars(schema).values() if isinstance(c, type) and issubclass(c, Payload) and c is not Payload}
    assert len(PAYLOADS) == len(set(PAYLOADS))
    assert set(PAYLOADS) == declared


def test_known_sizes() -> None:
    """A few sizes LAYOUT.md states, as a tripwire for an edited field list."""
    assert ctypes.sizeof(MotionLimits) == 24
    assert ctypes.sizeof(Command) == 144
    assert Command.target.offset == 32
    assert Command.object_limits.offset == 72


def test_decode_never_trusts_a_code() -> None:
    assert decode(ReasonCode, 19) is ReasonCode.NoPlan
    assert decode(ReasonCode, 0) is ReasonCode.None_
    assert decode(ReasonCode, max(ReasonCode) + 1) is None
    assert decode(GoalState, 0xFFFF_FFFF) is None
    for table in CODE_TABLES:
        for m in table:
            assert decode(table, int(m)) is m
        assert decode(table, max(table) + 1) is None


def test_code_name_spells_none_as_the_document_does() -> None:
    assert code_name(PlantFault.None_) == "None"
    assert code_name(PlantFault.Diverged) == "Diverged"


def test_terminal_goal_states() -> None:
    assert {s for s in GoalState if s.terminal} == {
        GoalState.Succeeded,
        GoalState.Aborted,
        GoalState.Canceled,
        GoalState.Preempted,
        GoalState.Rejected,
    }


def test_limit_bits() -> None:
    bits = [limit_bit(k, o) for k in LimitKind for o in LimitOrder]
    assert sorted(bits) == [1 << i for i in range(9)]
    assert limit_bit(LimitKind.Fingertip, LimitOrder.Acceleration) == 1 << 4
    assert sum(bits) == LIMIT_MASK_ALL


def test_bit_constants() -> None:
    assert sum(int(b) for b in CommandFlags) == COMMAND_FLAGS_ALL
    assert sum(int(b) for b in Valid) == VALID_ALL
    assert sum(int(b) for b in PlantState) == PLANT_STATE_ALL
    assert VALID_REQUIRED == int(Valid.OBJECT_ORIENTATION | Valid.TIP_POSE | Valid.CONTACT | Valid.ROLL)


def test_service_names() -> None:
    n = ServiceNames("lab/hand")
    assert (n.commands, n.answers, n.status, n.events, n.notify) == (
        "lab/hand/commands",
        "lab/hand/answers",
        "lab/hand/status",
        "lab/hand/events",
        "lab/hand/notify",
    )
    assert (n.plant_command, n.plant_measurement, n.plant_commanded, n.plant_measured, n.version) == (
        "lab/hand/plant/command",
        "lab/hand/plant/measurement",
        "lab/hand/plant/commanded",
        "lab/hand/plant/measured",
        "lab/hand/version",
    )


def test_to_python() -> None:
    c = Command(kind=1, goal_id=7)
    c.target[:] = (1.0, 0.0, 0.0, 0.0)
    c.rolling_limits.jerk = 3.5
    d = to_python(c)
    assert d["kind"] == 1 and d["goal_id"] == 7
    assert d["target"] == [1.0, 0.0, 0.0, 0.0]
    assert d["rolling_limits"] == {"velocity": 0.0, "acceleration": 0.0, "jerk": 3.5}


# --------------------------------------------------------------------------- reading LAYOUT.md

MINI_LAYOUT = f"""# gaitd shared-memory schema v{schema.SCHEMA_VERSION}

## Payloads

### `MotionLimits` (`gaitd::MotionLimits.v{schema.SCHEMA_VERSION}`, 24 bytes, align 8)

| offset | size | field | type | unit | meaning |
|---:|---:|---|---|---|---|
| 0 | 8 | `velocity` | `f64` | unit/s | velocity limit, > 0 when set |
| 8 | 8 | `acceleration` | `f64` | unit/s² | acceleration limit, > 0 when set |
| 16 | 8 | `jerk` | `f64` | unit/s³ | jerk limit, > 0 when set |

## Codes

### `PlantFault`

| code | name | meaning |
|---:|---|---|
| 0 | `None` | No fault. |
| 1 | `EmergencyStop` | An emergency stop is pressed. |
| 2 | `Hardware` | An actuator or sensor failed. |
| 3 | `Limit` | A joint, torque or force limit was hit. |
| 4 | `Diverged` | The simulation diverged. |
| 5 | `Other` | Another fault of the plant. |

## Services

| service | pattern | payload |
|---|---|---|
| `gaitd/commands` | publish-subscribe | `Command` |
| `gaitd/notify` | event | — |

Notification ids on `gaitd/notify`: 1 = status, 2 = event, 3 = answer, 4 = daemon dead.
"""


def mini(tmp_path: Path, text: str = MINI_LAYOUT) -> Path:
    p = tmp_path / "LAYOUT.md"
    p.write_text(text, encoding="utf-8")
    return p


def test_parse_layout(tmp_path: Path) -> None:
    doc = parse_layout(mini(tmp_path))
    assert doc.version == schema.SCHEMA_VERSION
    t = doc.types["MotionLimits"]
    assert (t.type_name, t.size, t.align) == (MotionLimits.type_name(), 24, 8)
    assert [(n, off, size) for n, off, size, _ in t.fields] == [
        ("velocity", 0, 8),
        ("acceleration", 8, 8),
        ("jerk", 16, 8),
    ]
    assert doc.codes == {
        "PlantFault": {"None": 0, "EmergencyStop": 1, "Hardware": 2, "Limit": 3, "Diverged": 4, "Other": 5}
    }
    assert doc.services == [("gaitd/commands", "publish-subscribe", "Command"), ("gaitd/notify", "event", None)]
    assert doc.notify_ids == {1: "status", 2: "event", 3: "answer", 4: "daemon dead"}


def problems_of(path: Path, prefix: str) -> list[str]:
    """What the comparison of the mirror's MotionLimits and PlantFault finds, about ``prefix``."""
    found = layout_problems(path, payloads=[MotionLimits], code_tables=[PlantFault])
    return [p for p in found if p.startswith(prefix)]


def test_the_comparison_finds_what_differs(tmp_path: Path) -> None:
    assert problems_of(mini(tmp_path), "MotionLimits") == []
    assert problems_of(mini(tmp_path), "code table PlantFault") == []

    moved = MINI_LAYOUT.replace("| 16 | 8 | `jerk`", "| 20 | 8 | `jerk`")
    assert problems_of(mini(tmp_path, moved), "MotionLimits field #2")

    renamed = MINI_LAYOUT.replace("`acceleration` | `f64`", "`accel` | `f64`")
    assert problems_of(mini(tmp_path, renamed), "MotionLimits field #1")

    bigger = MINI_LAYOUT.replace("24 bytes, align 8", "32 bytes, align 8")
    assert problems_of(mini(tmp_path, bigger), "MotionLimits: size 24, document 32")

    old = MINI_LAYOUT.replace(f"MotionLimits.v{schema.SCHEMA_VERSION}`", "MotionLimits.v1`")
    assert problems_of(mini(tmp_path, old), "MotionLimits: type name")

    renumbered = MINI_LAYOUT.replace("| 5 | `Other`", "| 6 | `Other`")
    assert problems_of(mini(tmp_path, renumbered), "code table PlantFault")

    newer = MINI_LAYOUT.replace(f"schema v{schema.SCHEMA_VERSION}", f"schema v{schema.SCHEMA_VERSION + 1}")
    assert problems_of(mini(tmp_path, newer), "document is schema")


def test_a_mirror_table_with_another_code_differs(tmp_path: Path) -> None:
    class PlantFault(enum.IntEnum):  # the mirror's table, with Other renumbered
        None_ = 0
        EmergencyStop = 1
        Hardware = 2
        Limit = 3
        Diverged = 4
        Other = 9

    found = layout_problems(mini(tmp_path), payloads=[MotionLimits], code_tables=[PlantFault])
    assert [p for p in found if p.startswith("code table PlantFault")]

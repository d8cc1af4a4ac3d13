"""Plant commands and measurements (``gaitd.setpoint``): every check refuses what it must, and the
conversions between ctypes payloads and Python values are exact."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import pytest

from gaitd import config, hand
from gaitd.quat import Vec
from gaitd.schema import CommandFlags, PlantCommand, PlantFault, PlantFingerMode, PlantState, Valid
from gaitd.setpoint import (
    BadCommand,
    FingerMeasured,
    JointSetpoint,
    JointsMeasured,
    Measured,
    Setpoint,
    check_header,
    check_setpoint,
    decode_command,
    encode_command,
    encode_measurement,
    measured_problem,
)

PERIOD_NS = 1_000_000


def start() -> Setpoint:
    """The paper's start grasp, numbered as a daemon's first lockstep command."""
    sp = hand.paper_start(config.Model(), grips=(2.0, 3.0, 4.0))
    return replace(
        sp,
        flags=int(CommandFlags.ENABLE | CommandFlags.LOCKSTEP),
        session=7,
        seq=1,
        answers=1,
        target_time_ns=2 * PERIOD_NS,
        period_ns=PERIOD_NS,
    )


def test_a_good_command_passes_and_round_trips() -> None:
    sp = start()
    c = encode_command(sp)
    check_header(c, PERIOD_NS, last_measurement=1, lockstep=True)
    check_setpoint(c)
    assert decode_command(c) == sp


def test_decode_renormalises_quaternions() -> None:
    c = encode_command(start())
    c.object_q[:] = (1.0 + 1e-7, 0.0, 0.0, 0.0)
    check_setpoint(c)  # within the unit tolerance
    assert decode_command(c).object_q == (1.0, 0.0, 0.0, 0.0)


@pytest.mark.parametrize(
    ("field", "value", "why"),
    [
        ("flags", 16 | int(CommandFlags.ENABLE), "unknown bits"),
        ("reserved", 1, "reserved padding"),
        ("session", 0, "session id 0"),
        ("seq", 0, "seq 0"),
        ("answers", 2, "the newest sent is 1"),
        ("period_ns", PERIOD_NS + 1, "period"),
        ("flags", int(CommandFlags.ENABLE), "the daemon runs realtime, this plant lockstep"),
    ],
)
def test_check_header_refuses(field: str, value: int, why: str) -> None:
    c = encode_command(start())
    setattr(c, field, value)
    with pytest.raises(BadCommand, match=why):
        check_header(c, PERIOD_NS, last_measurement=1, lockstep=True)


def test_check_header_refuses_lockstep_to_a_realtime_plant() -> None:
    with pytest.raises(BadCommand, match="the daemon runs lockstep, this plant realtime"):
        check_header(encode_command(start()), PERIOD_NS, last_measurement=1, lockstep=False)


@pytest.mark.parametrize(
    ("breaks", "why"),
    [
        (lambda c: c.object_q.__setitem__(0, 0.9), "object_q"),
        (lambda c: c.object_q.__setitem__(1, math.nan), "object_q"),
        (lambda c: c.object_q.__setitem__(slice(0, 4), (3.0, 0.0, 0.0, 0.0)), "object_q"),
        (lambda c: c.object_omega.__setitem__(2, math.inf), "object_omega"),
        (lambda c: setattr(c.fingers[1], "mode", 9), "finger 1: mode 9"),
        (lambda c: setattr(c.fingers[2], "joint_count", 5), "finger 2: joint_count 5"),
        (lambda c: c.fingers[0].orientation.__setitem__(0, 0.5), "finger 0: orientation"),
        (lambda c: c.fingers[0].velocity.__setitem__(1, math.nan), "finger 0: a non-finite number"),
        (lambda c: setattr(c.fingers[2], "roll", math.inf), "finger 2: a non-finite number"),
        (lambda c: setattr(c.fingers[1], "grip_force", -0.5), "finger 1: negative grip force"),
    ],
)
def test_check_setpoint_refuses(breaks: Callable[[PlantCommand], object], why: str) -> None:
    c = encode_command(start())
    breaks(c)
    with pytest.raises(BadCommand, match=why):
        check_setpoint(c)


def test_still_zeroes_every_velocity_and_keeps_the_pose() -> None:
    sp = start()
    moving = replace(
        sp,
        object_omega=(0.1, 0.2, 0.3),
        fingers=tuple(replace(f, velocity=(1.0, 0.0, 0.0), acceleration=(0.0, 2.0, 0.0)) for f in sp.fingers),
    )
    held = moving.still()
    assert held.object_omega == (0.0, 0.0, 0.0)
    assert all(f.velocity == f.angular_velocity == f.acceleration == (0.0, 0.0, 0.0) for f in held.fingers)
    assert [f.position for f in held.fingers] == [f.position for f in sp.fingers]
    assert [f.grip_force for f in held.fingers] == [2.0, 3.0, 4.0]


def test_flags_read_as_enabled_and_hold() -> None:
    assert start().enabled and not start().hold
    assert replace(start(), flags=int(CommandFlags.HOLD)).hold
    assert not replace(start(), flags=int(CommandFlags.HOLD)).enabled


def measured(
    velocity: Vec | None = None, angular_velocity: Vec | None = None, normal_force: float | None = None
) -> Measured:
    """Every fingertip where the start grasp has it, touching, with the optional values given."""
    tips = tuple(
        FingerMeasured(f.position, f.orientation, True, 0.25, velocity, angular_velocity, normal_force)
        for f in start().fingers
    )
    return Measured(object_q=(1.0, 0.0, 0.0, 0.0), fingers=tips)


def test_encode_measurement_carries_the_object_age_in_microseconds() -> None:
    m = measured()
    assert encode_measurement(m, seq=1, time_ns=1, session=1, applied=0, simulated=True).object_age_us == 0
    m = replace(m, object_age=0.0234567)
    assert encode_measurement(m, seq=1, time_ns=1, session=1, applied=0, simulated=True).object_age_us == 23457
    assert measured_problem(replace(m, object_age=-1e-3)) is not None
    assert measured_problem(replace(m, object_age=math.nan)) is not None


def test_encode_measurement_sets_only_the_valid_bits_of_what_is_present() -> None:
    required = Valid.OBJECT_ORIENTATION | Valid.TIP_POSE | Valid.CONTACT | Valid.ROLL
    out = encode_measurement(measured(), seq=3, time_ns=5, session=7, applied=2, simulated=False)
    assert out.valid == int(required)
    assert out.state == 0
    assert (out.seq, out.time_ns, out.session, out.applied) == (3, 5, 7, 2)
    assert [f.contact for f in out.fingers] == [1, 1, 1]
    assert out.fingers[2].roll == 0.25

    m = measured(velocity=(1.0, 2.0, 3.0), angular_velocity=(0.0, 0.0, 1.0), normal_force=4.0)
    m = replace(m, object_omega=(0.0, 0.0, 0.5), object_center=(0.01, 0.0, 0.0), fault=PlantFault.Limit)
    out = encode_measurement(m, seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert out.valid == int(required | Valid.OBJECT_VELOCITY | Valid.OBJECT_CENTER | Valid.TIP_VELOCITY | Valid.FORCE)
    assert out.state == int(PlantState.SIMULATED | PlantState.FAULT)
    assert out.fault == int(PlantFault.Limit)
    assert list(out.fingers[1].velocity) == [1.0, 2.0, 3.0]
    assert out.fingers[0].normal_force == 4.0
    assert list(out.object_center) == [0.01, 0.0, 0.0]


def test_tip_velocity_and_force_are_all_fingers_or_none() -> None:
    m = measured(velocity=(1.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), normal_force=1.0)
    one_missing = replace(m, fingers=(*m.fingers[:2], replace(m.fingers[2], velocity=None, normal_force=None)))
    out = encode_measurement(one_missing, seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert not out.valid & Valid.TIP_VELOCITY
    assert not out.valid & Valid.FORCE
    assert list(out.fingers[0].velocity) == [0.0, 0.0, 0.0]
    # Each optional group on its own: forces without velocities, and velocities without forces.
    out = encode_measurement(measured(normal_force=1.0), seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert out.valid & Valid.FORCE and not out.valid & Valid.TIP_VELOCITY
    m = measured(velocity=(1.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0))
    out = encode_measurement(m, seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert out.valid & Valid.TIP_VELOCITY and not out.valid & Valid.FORCE


def test_measured_problem() -> None:
    assert measured_problem(measured()) is None
    m = measured()
    assert "2 fingers" in str(measured_problem(replace(m, fingers=m.fingers[:2])))
    assert "object_q" in str(measured_problem(replace(m, object_q=(0.5, 0.0, 0.0, 0.0))))
    assert "not finite" in str(measured_problem(replace(m, object_center=(math.nan, 0.0, 0.0))))
    bad_tip = replace(m.fingers[1], normal_force=math.inf)
    assert "finger 1" in str(measured_problem(replace(m, fingers=(m.fingers[0], bad_tip, m.fingers[2]))))
    bad_q = replace(m.fingers[2], orientation=(0.0, 0.0, 0.0, 0.0))
    assert "finger 2: orientation" in str(measured_problem(replace(m, fingers=(*m.fingers[:2], bad_q))))


def test_mode_codes_survive_the_round_trip() -> None:
    sp = start()
    modes = (PlantFingerMode.Free, PlantFingerMode.Placing, PlantFingerMode.Lifting)
    sp = replace(sp, fingers=tuple(replace(f, mode=m) for f, m in zip(sp.fingers, modes)))
    assert tuple(f.mode for f in decode_command(encode_command(sp)).fingers) == modes


def chain_start() -> Setpoint:
    """:func:`start` as a chain hand's command: three joints per finger (TriFinger's gains)."""
    sp = start()
    joints = JointSetpoint(
        position=(0.3, 0.9, -1.8), velocity=(0.1, -0.2, 0.0), torque=(0.05, -0.1, 0.02), kp=(9.0,) * 3, kd=(0.01,) * 3
    )
    return replace(
        sp, flags=sp.flags | int(CommandFlags.JOINTS), fingers=tuple(replace(f, joints=joints) for f in sp.fingers)
    )


def test_a_chain_hands_joints_round_trip_and_are_checked() -> None:
    sp = chain_start()
    c = encode_command(sp)
    assert [f.joint_count for f in c.fingers] == [3, 3, 3]
    assert list(c.fingers[1].kp) == [9.0, 9.0, 9.0, 0.0]
    check_setpoint(c)
    back = decode_command(c)
    assert back == sp and back.joints
    held = back.still()
    assert all(f.joints is not None and f.joints.velocity == (0.0, 0.0, 0.0) for f in held.fingers)
    assert all(f.joints is not None and f.joints.position == (0.3, 0.9, -1.8) for f in held.fingers)
    # A fingertip command carries no joints.
    assert all(f.joints is None for f in decode_command(encode_command(start())).fingers)
    cases: list[tuple[Callable[[PlantCommand], object], str]] = [
        (lambda c: setattr(c.fingers[0], "joint_count", 0), "finger 0: no joints"),
        (lambda c: c.fingers[1].joint_torque.__setitem__(2, math.nan), "finger 1: a non-finite joint"),
        (lambda c: c.fingers[2].kd.__setitem__(0, -1.0), "finger 2: a negative gain"),
    ]
    for breaks, why in cases:
        c = encode_command(sp)
        breaks(c)
        with pytest.raises(BadCommand, match=why):
            check_setpoint(c)


def test_measured_joints_set_their_valid_bits_for_all_fingers_or_none() -> None:
    m = measured()
    j = JointsMeasured(position=(0.3, 0.9, -1.8), velocity=(0.0, 0.1, 0.0), torque=(0.1, 0.2, 0.3))
    with_joints = replace(m, fingers=tuple(replace(f, joints=j) for f in m.fingers))
    out = encode_measurement(with_joints, seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert out.valid & Valid.JOINT_POSITION and out.valid & Valid.JOINT_VELOCITY and out.valid & Valid.JOINT_TORQUE
    assert [f.joint_count for f in out.fingers] == [3, 3, 3]
    assert list(out.fingers[2].joint_torque) == [0.1, 0.2, 0.3, 0.0]
    positions_only = replace(with_joints.fingers[0], joints=JointsMeasured(position=(0.3, 0.9, -1.8)))
    out = encode_measurement(
        replace(with_joints, fingers=(positions_only, *with_joints.fingers[1:])),
        seq=1,
        time_ns=1,
        session=1,
        applied=0,
        simulated=True,
    )
    assert out.valid & Valid.JOINT_POSITION and not out.valid & (Valid.JOINT_VELOCITY | Valid.JOINT_TORQUE)
    one_missing = replace(with_joints, fingers=(*with_joints.fingers[:2], m.fingers[2]))
    out = encode_measurement(one_missing, seq=1, time_ns=1, session=1, applied=0, simulated=True)
    assert not out.valid & Valid.JOINT_POSITION
    bad = replace(with_joints.fingers[1], joints=JointsMeasured(position=(0.1, math.nan, 0.0)))
    fingers = (with_joints.fingers[0], bad, m.fingers[2])
    assert "finger 1" in str(measured_problem(replace(with_joints, fingers=fingers)))
    five = replace(with_joints.fingers[0], joints=JointsMeasured(position=(0.0,) * 5))
    assert "5 joints" in str(measured_problem(replace(with_joints, fingers=(five, *with_joints.fingers[1:]))))

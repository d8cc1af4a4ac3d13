"""What travels between the daemon and a plant, as checked Python values.

A plant never works on the raw ``PlantCommand`` bytes: :func:`check_command`
checks every field it will use (codes, bit fields, padding, finiteness,
unit quaternions, the period, the echo numbers) and :func:`decode_command`
turns a checked command into an immutable :class:`Setpoint`. In the other
direction a plant returns a :class:`Measured` and :func:`encode_measurement`
fills the ``PlantMeasurement`` with its ``valid`` bits set from which
optional fields are present.

A chain hand's command also carries each finger's joints
(``CommandFlags.JOINTS``: :class:`JointSetpoint`, the shape of a TriFinger
action), and its plant measures them (:class:`JointsMeasured`): the daemon
makes the tips from the measured joints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from collections.abc import Iterable, Sequence
from typing import Any

from . import quat
from .schema import (
    COMMAND_FLAGS_ALL,
    FINGERS,
    MAX_JOINTS,
    CommandFlags,
    PlantCommand,
    PlantFault,
    PlantFingerMode,
    PlantMeasurement,
    PlantState,
    Valid,
)

Vec = tuple[float, float, float]
Quat = tuple[float, float, float, float]
ZERO: Vec = (0.0, 0.0, 0.0)

#: A quaternion is unit when | |q| − 1 | ≤ this (the daemon renormalises; garbage is far off).
UNIT_TOLERANCE = 1e-6


@dataclass(frozen=True)
class JointSetpoint:
    """A chain finger's joints, base to tip: the motor torque is
    ``torque + kp·(position − q) + kd·(velocity − q̇)`` (rad, rad/s, N·m, N·m/rad, N·m·s/rad)."""

    position: tuple[float, ...]
    velocity: tuple[float, ...]
    torque: tuple[float, ...]
    kp: tuple[float, ...]
    kd: tuple[float, ...]


@dataclass(frozen=True)
class FingerSetpoint:
    """One finger's setpoint (hand frame, object centre at the origin); a chain hand's ``joints`` too."""

    mode: PlantFingerMode
    position: Vec
    orientation: Quat
    velocity: Vec = ZERO
    angular_velocity: Vec = ZERO
    acceleration: Vec = ZERO
    roll: float = 0.0
    grip_force: float = 0.0
    joints: JointSetpoint | None = None


@dataclass(frozen=True)
class Setpoint:
    """A checked command: what the hand is to do at ``target_time_ns``."""

    fingers: tuple[FingerSetpoint, ...]
    object_q: Quat = quat.IDENTITY
    object_omega: Vec = ZERO
    flags: int = int(CommandFlags.ENABLE)
    session: int = 0
    seq: int = 0
    answers: int = 0
    target_time_ns: int = 0
    period_ns: int = 0

    @property
    def enabled(self) -> bool:
        """The daemon controls the hand (ENABLE)."""
        return bool(self.flags & CommandFlags.ENABLE)

    @property
    def hold(self) -> bool:
        """Safe hold: stay still, keep the grasp (HOLD)."""
        return bool(self.flags & CommandFlags.HOLD)

    @property
    def joints(self) -> bool:
        """A chain hand's command: each finger's ``joints`` hold its setpoint (JOINTS)."""
        return bool(self.flags & CommandFlags.JOINTS)

    def still(self) -> Setpoint:
        """The same poses and grips with every velocity and acceleration zero (a held setpoint)."""

        def still_joints(j: JointSetpoint | None) -> JointSetpoint | None:
            return None if j is None else replace(j, velocity=tuple(0.0 for _ in j.velocity))

        fingers = tuple(
            replace(f, velocity=ZERO, angular_velocity=ZERO, acceleration=ZERO, joints=still_joints(f.joints))
            for f in self.fingers
        )
        return replace(self, fingers=fingers, object_omega=ZERO)


@dataclass(frozen=True)
class JointsMeasured:
    """A chain finger's joints as measured, base to tip; ``None`` = not measured."""

    position: tuple[float, ...]
    velocity: tuple[float, ...] | None = None
    torque: tuple[float, ...] | None = None


@dataclass(frozen=True)
class FingerMeasured:
    """One finger as measured; ``None`` = not measured by this plant. On a chain hand the daemon
    reads ``joints`` and makes the tip from them (``position`` and ``orientation`` are not read)."""

    position: Vec
    orientation: Quat
    contact: bool
    roll: float
    velocity: Vec | None = None
    angular_velocity: Vec | None = None
    normal_force: float | None = None
    joints: JointsMeasured | None = None


@dataclass(frozen=True)
class Measured:
    """What a plant measured at one instant; ``None`` = not measured."""

    object_q: Quat
    fingers: tuple[FingerMeasured, ...]
    object_omega: Vec | None = None
    object_center: Vec | None = None
    fault: PlantFault = PlantFault.None_
    #: How long before the measurement's time the object's pose was sampled [s] (a tracker's latency).
    object_age: float = 0.0


class BadCommand(ValueError):
    """A command that must not be applied; the message says which field and why."""


def _finite(values: Iterable[float]) -> bool:
    return all(map(math.isfinite, values))


def _unit(q: Sequence[float]) -> bool:
    if not _finite(q) or max(map(abs, q)) > 2.0:
        return False
    return abs(math.hypot(*q) - 1.0) <= UNIT_TOLERANCE


def check_header(c: PlantCommand, period_ns: int, last_measurement: int, lockstep: bool) -> None:
    """Raises :class:`BadCommand` unless the numbers every command must carry are sane."""
    if c.flags & ~COMMAND_FLAGS_ALL:
        raise BadCommand(f"flags {c.flags:#x}: unknown bits")
    if c.reserved != 0:
        raise BadCommand("reserved padding is not 0")
    if c.session == 0:
        raise BadCommand("session id 0 (a daemon numbers its sessions from 1)")
    if c.seq == 0:
        raise BadCommand("seq 0")
    if c.answers > last_measurement:
        raise BadCommand(f"answers measurement {c.answers}, the newest sent is {last_measurement}")
    if c.period_ns != period_ns:
        raise BadCommand(f"period {c.period_ns} ns, this plant runs {period_ns} ns (same [control] tick_hz?)")
    if bool(c.flags & CommandFlags.LOCKSTEP) != lockstep:
        mine = "lockstep" if lockstep else "realtime"
        theirs = "lockstep" if c.flags & CommandFlags.LOCKSTEP else "realtime"
        raise BadCommand(f"the daemon runs {theirs}, this plant {mine} (same [plant] timing?)")


def check_setpoint(c: PlantCommand) -> None:
    """Raises :class:`BadCommand` unless every setpoint field is a usable number or code."""
    if not _unit(c.object_q):
        raise BadCommand(f"object_q {list(c.object_q)} is not a finite unit quaternion")
    if not _finite(c.object_omega):
        raise BadCommand("object_omega is not finite")
    for i, f in enumerate(c.fingers):
        try:
            PlantFingerMode(f.mode)
        except ValueError:
            raise BadCommand(f"finger {i}: mode {f.mode} is no PlantFingerMode") from None
        if f.joint_count > MAX_JOINTS:
            raise BadCommand(f"finger {i}: joint_count {f.joint_count} > {MAX_JOINTS}")
        if c.flags & CommandFlags.JOINTS:
            n = f.joint_count
            if n == 0:
                raise BadCommand(f"finger {i}: no joints in a JOINTS command")
            joint_numbers = [*f.joint_position[:n], *f.joint_velocity[:n], *f.joint_torque[:n], *f.kp[:n], *f.kd[:n]]
            if not _finite(joint_numbers):
                raise BadCommand(f"finger {i}: a non-finite joint number")
            if any(g < 0.0 for g in [*f.kp[:n], *f.kd[:n]]):
                raise BadCommand(f"finger {i}: a negative gain")
        if not _unit(f.orientation):
            raise BadCommand(f"finger {i}: orientation {list(f.orientation)} is not a finite unit quaternion")
        numbers = [*f.position, *f.velocity, *f.angular_velocity, *f.acceleration, f.roll, f.grip_force]
        if not _finite(numbers):
            raise BadCommand(f"finger {i}: a non-finite number")
        if f.grip_force < 0.0:
            raise BadCommand(f"finger {i}: negative grip force {f.grip_force}")


def _joint_setpoint(f: Any) -> JointSetpoint:
    n = f.joint_count
    return JointSetpoint(
        position=tuple(f.joint_position[:n]),
        velocity=tuple(f.joint_velocity[:n]),
        torque=tuple(f.joint_torque[:n]),
        kp=tuple(f.kp[:n]),
        kd=tuple(f.kd[:n]),
    )


def decode_command(c: PlantCommand) -> Setpoint:
    """The :class:`Setpoint` of a command that passed :func:`check_setpoint` (quaternions renormalised)."""
    joints = bool(c.flags & CommandFlags.JOINTS)
    fingers = tuple(
        FingerSetpoint(
            mode=PlantFingerMode(f.mode),
            position=tuple(f.position),
            orientation=quat.normalize(f.orientation),
            velocity=tuple(f.velocity),
            angular_velocity=tuple(f.angular_velocity),
            acceleration=tuple(f.acceleration),
            roll=f.roll,
            grip_force=f.grip_force,
            joints=_joint_setpoint(f) if joints else None,
        )
        for f in c.fingers
    )
    return Setpoint(
        fingers=fingers,
        object_q=quat.normalize(c.object_q),
        object_omega=tuple(c.object_omega),
        flags=c.flags,
        session=c.session,
        seq=c.seq,
        answers=c.answers,
        target_time_ns=c.target_time_ns,
        period_ns=c.period_ns,
    )


def encode_command(sp: Setpoint) -> PlantCommand:
    """The ``PlantCommand`` of a setpoint (for test fixtures and open-loop drivers)."""
    c = PlantCommand(
        session=sp.session,
        seq=sp.seq,
        answers=sp.answers,
        target_time_ns=sp.target_time_ns,
        period_ns=sp.period_ns,
        flags=sp.flags,
    )
    c.object_q[:] = sp.object_q
    c.object_omega[:] = sp.object_omega
    for dst, f in zip(c.fingers, sp.fingers):
        dst.mode = int(f.mode)
        dst.position[:] = f.position
        dst.orientation[:] = f.orientation
        dst.velocity[:] = f.velocity
        dst.angular_velocity[:] = f.angular_velocity
        dst.acceleration[:] = f.acceleration
        dst.roll = f.roll
        dst.grip_force = f.grip_force
        if f.joints is not None:
            j = f.joints
            dst.joint_count = len(j.position)
            for name, values in (
                ("joint_position", j.position),
                ("joint_velocity", j.velocity),
                ("joint_torque", j.torque),
                ("kp", j.kp),
                ("kd", j.kd),
            ):
                getattr(dst, name)[: len(values)] = values
    return c


def measured_problem(m: Measured) -> str | None:
    """Why a plant's own measurement must not be sent as it is (None: it is fine)."""
    if len(m.fingers) != FINGERS:
        return f"{len(m.fingers)} fingers measured, the schema has {FINGERS}"
    if not _unit(m.object_q):
        return "object_q is not a finite unit quaternion"
    for v in (m.object_omega, m.object_center):
        if v is not None and not _finite(v):
            return "object velocity or centre is not finite"
    if not (math.isfinite(m.object_age) and m.object_age >= 0.0):
        return "object_age is not a finite age >= 0"
    for i, f in enumerate(m.fingers):
        if not _unit(f.orientation):
            return f"finger {i}: orientation is not a finite unit quaternion"
        numbers = [*f.position, f.roll]
        for v in (f.velocity, f.angular_velocity):
            numbers += list(v) if v is not None else []
        if f.normal_force is not None:
            numbers.append(f.normal_force)
        if f.joints is not None:
            j = f.joints
            if not 0 < len(j.position) <= MAX_JOINTS:
                return f"finger {i}: {len(j.position)} joints (1 to {MAX_JOINTS})"
            for jv in (j.velocity, j.torque):
                if jv is not None and len(jv) != len(j.position):
                    return f"finger {i}: joint velocities or torques for another number of joints"
                numbers += list(jv) if jv is not None else []
            numbers += list(j.position)
        if not _finite(numbers):
            return f"finger {i}: a non-finite number"
    return None


_VALID = {v.name: int(v) for v in Valid if v.name is not None}
_BASE_VALID = int(Valid.OBJECT_ORIENTATION | Valid.TIP_POSE | Valid.CONTACT | Valid.ROLL)
_SIMULATED, _FAULT = int(PlantState.SIMULATED), int(PlantState.FAULT)


def encode_measurement(
    m: Measured, seq: int, time_ns: int, session: int, applied: int, simulated: bool
) -> PlantMeasurement:
    """The ``PlantMeasurement`` of ``m``; ``valid`` says which optional fields are present."""
    # Plain ints: flag-enum arithmetic costs microseconds a measurement, every period.
    valid = _BASE_VALID
    state = _SIMULATED if simulated else 0
    out = PlantMeasurement(seq=seq, time_ns=time_ns, session=session, applied=applied)
    out.object_q[:] = quat.normalize(m.object_q)
    out.object_age_us = min(round(m.object_age * 1e6), 0xFFFF_FFFF)
    if m.object_omega is not None:
        valid |= _VALID["OBJECT_VELOCITY"]
        out.object_omega[:] = m.object_omega
    if m.object_center is not None:
        valid |= _VALID["OBJECT_CENTER"]
        out.object_center[:] = m.object_center
    tip_velocity = all(f.velocity is not None and f.angular_velocity is not None for f in m.fingers)
    force = all(f.normal_force is not None for f in m.fingers)
    joints = [f.joints for f in m.fingers]
    joint_position = all(j is not None for j in joints)
    joint_velocity = joint_position and all(j is not None and j.velocity is not None for j in joints)
    joint_torque = joint_position and all(j is not None and j.torque is not None for j in joints)
    for dst, f in zip(out.fingers, m.fingers):
        dst.contact = 1 if f.contact else 0
        dst.position[:] = f.position
        dst.orientation[:] = quat.normalize(f.orientation)
        dst.roll = f.roll
        if tip_velocity:
            dst.velocity[:] = f.velocity
            dst.angular_velocity[:] = f.angular_velocity
        if force:
            dst.normal_force = f.normal_force
        if joint_position and f.joints is not None:
            j = f.joints
            dst.joint_count = len(j.position)
            dst.joint_position[: len(j.position)] = j.position
            if joint_velocity and j.velocity is not None:
                dst.joint_velocity[: len(j.velocity)] = j.velocity
            if joint_torque and j.torque is not None:
                dst.joint_torque[: len(j.torque)] = j.torque
    if tip_velocity:
        valid |= _VALID["TIP_VELOCITY"]
    if force:
        valid |= _VALID["FORCE"]
    if joint_position:
        valid |= _VALID["JOINT_POSITION"]
    if joint_velocity:
        valid |= _VALID["JOINT_VELOCITY"]
    if joint_torque:
        valid |= _VALID["JOINT_TORQUE"]
    if m.fault != PlantFault.None_:
        state |= _FAULT
        out.fault = int(m.fault)
    out.valid = int(valid)
    out.state = int(state)
    return out

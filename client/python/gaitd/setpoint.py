"""What travels between the daemon and a plant, as checked Python values.

A plant never works on the raw ``PlantCommand`` bytes: :func:`check_command`
checks every field it will use (codes, bit fields, padding, finiteness,
unit quaternions, the period, the echo numbers) and :func:`decode_command`
turns a checked command into an immutable :class:`Setpoint`. In the other
direction a plant returns a :class:`Measured` and :func:`encode_measurement`
fills the ``PlantMeasurement`` with its ``valid`` bits set from which
optional fields are present.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from collections.abc import Iterable, Sequence

from . import quat
from .schema import (
    COMMAND_FLAGS_ALL,
    FINGERS,
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
class FingerSetpoint:
    """One fingertip's setpoint (hand frame, object centre at the origin)."""

    mode: PlantFingerMode
    position: Vec
    orientation: Quat
    velocity: Vec = ZERO
    angular_velocity: Vec = ZERO
    acceleration: Vec = ZERO
    roll: float = 0.0
    grip_force: float = 0.0


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

    def still(self) -> Setpoint:
        """The same poses and grips with every velocity and acceleration zero (a held setpoint)."""
        fingers = tuple(replace(f, velocity=ZERO, angular_velocity=ZERO, acceleration=ZERO) for f in self.fingers)
        return replace(self, fingers=fingers, object_omega=ZERO)


@dataclass(frozen=True)
class FingerMeasured:
    """One fingertip as measured; ``None`` = not measured by this plant."""

    position: Vec
    orientation: Quat
    contact: bool
    roll: float
    velocity: Vec | None = None
    angular_velocity: Vec | None = None
    normal_force: float | None = None


@dataclass(frozen=True)
class Measured:
    """What a plant measured at one instant; ``None`` = not measured."""

    object_q: Quat
    fingers: tuple[FingerMeasured, ...]
    object_omega: Vec | None = None
    object_center: Vec | None = None
    fault: PlantFault = PlantFault.None_


class BadCommand(ValueError):
    """A command that must not be applied; the message says which field and why."""


def _finite(values: Iterable[float]) -> bool:
    return all(math.isfinite(v) for v in values)


def _unit(q: Sequence[float]) -> bool:
    if not _finite(q) or any(abs(c) > 2.0 for c in q):
        return False
    return abs(math.sqrt(sum(c * c for c in q)) - 1.0) <= UNIT_TOLERANCE


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
        if f.reserved != 0:
            raise BadCommand(f"finger {i}: reserved padding is not 0")
        if not _unit(f.orientation):
            raise BadCommand(f"finger {i}: orientation {list(f.orientation)} is not a finite unit quaternion")
        numbers = [*f.position, *f.velocity, *f.angular_velocity, *f.acceleration, f.roll, f.grip_force]
        if not _finite(numbers):
            raise BadCommand(f"finger {i}: a non-finite number")
        if f.grip_force < 0.0:
            raise BadCommand(f"finger {i}: negative grip force {f.grip_force}")


def decode_command(c: PlantCommand) -> Setpoint:
    """The :class:`Setpoint` of a command that passed :func:`check_setpoint` (quaternions renormalised)."""
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
    for i, f in enumerate(m.fingers):
        if not _unit(f.orientation):
            return f"finger {i}: orientation is not a finite unit quaternion"
        numbers = [*f.position, f.roll]
        for v in (f.velocity, f.angular_velocity):
            numbers += list(v) if v is not None else []
        if f.normal_force is not None:
            numbers.append(f.normal_force)
        if not _finite(numbers):
            return f"finger {i}: a non-finite number"
    return None


def encode_measurement(
    m: Measured, seq: int, time_ns: int, session: int, applied: int, simulated: bool
) -> PlantMeasurement:
    """The ``PlantMeasurement`` of ``m``; ``valid`` says which optional fields are present."""
    valid = Valid.OBJECT_ORIENTATION | Valid.TIP_POSE | Valid.CONTACT | Valid.ROLL
    state = PlantState.SIMULATED if simulated else PlantState(0)
    out = PlantMeasurement(seq=seq, time_ns=time_ns, session=session, applied=applied)
    out.object_q[:] = quat.normalize(m.object_q)
    if m.object_omega is not None:
        valid |= Valid.OBJECT_VELOCITY
        out.object_omega[:] = m.object_omega
    if m.object_center is not None:
        valid |= Valid.OBJECT_CENTER
        out.object_center[:] = m.object_center
    tip_velocity = all(f.velocity is not None and f.angular_velocity is not None for f in m.fingers)
    force = all(f.normal_force is not None for f in m.fingers)
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
    if tip_velocity:
        valid |= Valid.TIP_VELOCITY
    if force:
        valid |= Valid.FORCE
    if m.fault != PlantFault.None_:
        state |= PlantState.FAULT
        out.fault = int(m.fault)
    out.valid = int(valid)
    out.state = int(state)
    return out

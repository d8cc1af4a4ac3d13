"""``gait-trajectory/1`` traces (SPEC §10) as plant setpoints, for open-loop drives.

A trace written by ``gaitctl plan`` or the daemon is the sequence of
setpoints the controller commanded, one per tick. Replaying it open loop
into a plant (no daemon) checks the plant against the plan: a good plant
makes the object follow ``object_q``. The finger modes are not in the
trace; they are derived as the daemon means them: ``contact`` true →
Grasping; a free finger during a ``place`` phase that ends in contact →
Placing; a finger that just broke contact, during the ``lift`` phase →
Lifting; otherwise Free. Velocities are backward differences.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import quat
from .schema import CommandFlags, PlantFingerMode
from .setpoint import FingerSetpoint, Setpoint


@dataclass(frozen=True)
class Trace:
    """A parsed trace: its header and its samples (dicts as in the file)."""

    header: dict[str, Any]
    samples: list[dict[str, Any]]

    @property
    def dt(self) -> float:
        """Sample spacing [s]."""
        return float(self.header["dt"])


def read(path: str | Path) -> Trace:
    """Reads a trace; raises ValueError for another format."""
    lines = [json.loads(line) for line in Path(path).read_text(encoding="utf-8").splitlines() if line.strip()]
    if not lines or lines[0].get("format") != "gait-trajectory/1":
        raise ValueError(f"{path}: not a gait-trajectory/1 trace")
    return Trace(lines[0], lines[1:])


def _vec(x: Sequence[float]) -> quat.Vec:
    return (float(x[0]), float(x[1]), float(x[2]))


def _per_second(v: Sequence[float], dt: float) -> quat.Vec:
    """A change over one sample as a rate: ``v / dt``."""
    return (v[0] / dt, v[1] / dt, v[2] / dt)


def _rate(a: Sequence[float], b: Sequence[float], dt: float) -> quat.Vec:
    """The backward difference ``(a - b) / dt``."""
    return ((a[0] - b[0]) / dt, (a[1] - b[1]) / dt, (a[2] - b[2]) / dt)


def finger_modes(trace: Trace) -> list[list[PlantFingerMode]]:
    """The PlantFingerMode of every finger at every sample (see the module docs)."""
    s = trace.samples
    n, nf = len(s), len(s[0]["fingers"])
    modes = [[PlantFingerMode.Free] * nf for _ in range(n)]
    for i in range(nf):
        contact = [x["fingers"][i]["contact"] for x in s]
        for k in range(n):
            if contact[k]:
                modes[k][i] = PlantFingerMode.Grasping
        # Lifting: from the break of contact while the lift phase lasts.
        for k in range(1, n):
            if contact[k - 1] and not contact[k]:
                j = k
                while j < n and not contact[j] and s[j]["phase"] == "lift":
                    modes[j][i] = PlantFingerMode.Lifting
                    j += 1
        # Placing: the place phase that ends in this finger's contact.
        for k in range(1, n):
            if not contact[k - 1] and contact[k]:
                j = k - 1
                while j >= 0 and not contact[j] and s[j]["phase"] == "place":
                    modes[j][i] = PlantFingerMode.Placing
                    j -= 1
    return modes


def setpoints(trace: Trace, lockstep: bool = True) -> list[Setpoint]:
    """One setpoint per sample (ENABLE, and LOCKSTEP if asked); numbers left for the driver to fill."""
    s, dt = trace.samples, trace.dt
    modes = finger_modes(trace)
    flags = int(CommandFlags.ENABLE | (CommandFlags.LOCKSTEP if lockstep else 0))
    out: list[Setpoint] = []
    for k, x in enumerate(s):
        prev = s[k - 1] if k else x
        prev2 = s[k - 2] if k > 1 else prev
        fingers = []
        for i, f in enumerate(x["fingers"]):
            fp, fpp = prev["fingers"][i], prev2["fingers"][i]
            p, p0, p00 = _vec(f["p"]), _vec(fp["p"]), _vec(fpp["p"])
            v = _rate(p, p0, dt)
            v0 = _rate(p0, p00, dt)
            w = quat.to_rotvec(quat.mul(quat.normalize(f["q"]), quat.conj(quat.normalize(fp["q"]))))
            fingers.append(
                FingerSetpoint(
                    mode=modes[k][i],
                    position=p,
                    orientation=quat.normalize(f["q"]),
                    velocity=v,
                    angular_velocity=_per_second(w, dt),
                    acceleration=_rate(v, v0, dt),
                    roll=float(f.get("roll", 0.0)),
                    grip_force=float(f["grip_force"]) if f["contact"] else 0.0,
                )
            )
        wo = quat.to_rotvec(quat.mul(quat.normalize(x["object_q"]), quat.conj(quat.normalize(prev["object_q"]))))
        out.append(
            Setpoint(
                fingers=tuple(fingers),
                object_q=quat.normalize(x["object_q"]),
                object_omega=_per_second(wo, dt),
                flags=flags,
            )
        )
    return out

"""The daemon's hand model where a plant needs it: the paper's start grasp.

``paper_start`` mirrors ``HandState::paper_start`` (gait/src/state.rs): the
object at identity, each fingertip on the equator at its finger azimuth φ_k,
touching with its pole: centre (R + r) d_k, pole axis Q_f e_z = −d_k,
fingertip x axis = hand z, roll 0. A plant that starts elsewhere would be
refused by the daemon's start-state checks, so every simulator starts here
unless told otherwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from . import quat
from .config import Model
from .schema import CommandFlags, PlantFingerMode
from .setpoint import FingerSetpoint, Setpoint


def base_direction(azimuth_deg: float) -> tuple[float, float, float]:
    """d_k = (cos φ, sin φ, 0)."""
    phi = math.radians(azimuth_deg)
    return (math.cos(phi), math.sin(phi), 0.0)


def paper_start(model: Model, grips: Sequence[float] = (0.0, 0.0, 0.0)) -> Setpoint:
    """The start grasp as a (still) setpoint, every finger Grasping with ``grips`` [N]."""
    reach = model.object_radius + model.fingertip_radius
    fingers = []
    for azimuth, grip in zip(model.finger_azimuth_deg, grips):
        d = base_direction(azimuth)
        z = (-d[0], -d[1], -d[2])
        x = (0.0, 0.0, 1.0)
        y = (z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0])
        fingers.append(
            FingerSetpoint(
                mode=PlantFingerMode.Grasping,
                position=(reach * d[0], reach * d[1], reach * d[2]),
                orientation=quat.from_matrix_columns(x, y, z),
                grip_force=float(grip),
            )
        )
    return Setpoint(fingers=tuple(fingers), flags=int(CommandFlags.ENABLE))


def holding_grip(model: Model, mass: float, gravity: Sequence[float], min_grip: float, max_grip: float) -> float:
    """A grip [N] per finger that holds the start grasp until the daemon commands its own.

    Three equatorial fingers carry the weight m|g| by friction alone, so each
    needs m|g| / (3 μ); twice that, at least ``min_grip``, at most ``max_grip``.
    """
    weight = mass * math.sqrt(sum(g * g for g in gravity))
    return min(max_grip, max(min_grip, 2.0 * weight / (3.0 * model.mu)))

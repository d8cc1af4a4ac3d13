"""The daemon's hand model where a plant needs it: the paper's start grasp,
and how grasping fingertips turn the object.

``paper_start`` mirrors ``HandState::paper_start`` (gait/src/hand_state.rs): the
object at identity, each fingertip on the equator at its finger azimuth φ_k,
touching with its pole: centre (R + r) d_k, pole axis Q_f e_z = −d_k,
fingertip x axis = hand z, roll 0. The daemon takes any start that passes
its invariant checks (SPEC §1.3), but a simulator starts here unless told
otherwise.

``object_rate`` is the object's angular velocity that the grasping
fingertips' motion gives it when every grasping contact rolls without
slipping (PLANT-GUIDE.md, "How the object moves"): what a kinematic
simulator integrates instead of copying the commanded orientation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from . import quat
from .config import Model
from .schema import CommandFlags, PlantFingerMode
from .setpoint import FingerSetpoint, Setpoint, Vec


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


def _cross(a: Sequence[float], b: Sequence[float]) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _det(m: Sequence[Sequence[float]]) -> float:
    c = _cross(m[0], m[1])
    return c[0] * m[2][0] + c[1] * m[2][1] + c[2] * m[2][2]


def object_rate(model: Model, setpoint: Setpoint) -> Vec:
    """The object's angular velocity [rad/s, hand frame] the grasping fingertips give it.

    Object centre at the origin; fingertip k (mode Grasping) at p_k with
    velocity v_k and angular velocity ω_k; n_k = p_k / |p_k|. Rolling without
    slipping moves the object's and the fingertip's material points at the
    contact alike: R (ω × n_k) = v_k − r (ω_k × n_k). ω is the least-squares
    solution over the grasping contacts. With two grasping fingers (soft
    contacts, no spin) also ω · n_k = ω_k · n_k, which fixes the turn about
    the chord through both contacts; three fingers may spin on the object,
    so only rolling counts then. With fewer than two the object stays still.
    """
    grasping = [f for f in setpoint.fingers if f.mode == PlantFingerMode.Grasping]
    if len(grasping) < 2:
        return (0.0, 0.0, 0.0)
    spin_free = len(grasping) == 2
    # Normal equations A ω = b: Σ (I − n nᵀ) ω = Σ n × t (rolling), + n nᵀ ω = (ω_k · n) n (no spin).
    a = [[0.0] * 3 for _ in range(3)]
    b = [0.0] * 3
    for f in grasping:
        n = quat.normalize((0.0, *f.position))[1:]
        w_n = _cross(f.angular_velocity, n)
        t = [(v - model.fingertip_radius * c) / model.object_radius for v, c in zip(f.velocity, w_n)]
        along = sum(w * c for w, c in zip(f.angular_velocity, n))
        for i in range(3):
            b[i] += _cross(n, t)[i] + (along * n[i] if spin_free else 0.0)
            for j in range(3):
                a[i][j] += float(i == j) - (0.0 if spin_free else n[i] * n[j])
    det = _det(a)
    if abs(det) < 1e-12:
        return (0.0, 0.0, 0.0)
    # Cramer's rule: column k of A replaced by b.
    x = [_det([[b[i] if j == k else a[i][j] for j in range(3)] for i in range(3)]) / det for k in range(3)]
    return (x[0], x[1], x[2])

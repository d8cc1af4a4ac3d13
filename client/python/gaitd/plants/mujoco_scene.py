"""The MuJoCo scene of the physics hand: a free sphere and three compliant fingertips.

Design (``tests/oracles/mujoco/NOTES.md`` explains what works for fingertips on a
sphere in MuJoCo, and why):

* Each finger is a heavy *mount* (10⁴ kg, free joint) whose position,
  orientation and velocities the plant overwrites every step with the
  commanded pose and the velocity that reaches the next one. MuJoCo gives
  mocap bodies zero velocity in the contact solver, so friction would fight
  the fingertip's own motion; an overwritten free body carries its true
  velocity, and its mass makes the solver treat it as kinematic.
* The fingertip hangs from the mount by a **slide joint along the inward
  contact normal** (the press axis: spring 5 kN/m, critical damping, ±3 mm
  travel, 0.1 kg) and a **ball joint** that is also overwritten (the
  commanded fingertip orientation: rolling needs it). Only the press axis
  is dynamic, so the delivered normal force is the commanded grip (a
  preload), not µm-level penetration.
* The fingertip's rotational inertia is mount-sized: a light fingertip on
  an overwritten joint lets the solver satisfy friction by spinning the tip
  instead of moving the object.
* Contacts are explicit pairs (object–fingertip only; fingertips never
  collide with each other): condim 4 (normal, two tangential, torsion — the
  soft finger), elliptic cones, impratio 10, noslip iterations, solref time
  constant 2 × timestep (MuJoCo's soft friction is a velocity servo: the
  stiffer, the less creep), a flat solimp so the contact is a linear spring.
* ``margin = 0, gap = contact tolerance``: MuJoCo (4.0, measured) lists
  contacts up to margin + gap apart but makes constraints only within
  margin, so a fingertip within the tolerance reads as touching while only
  penetration produces force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ..config import DaemonConfig


@dataclass(frozen=True)
class SceneParams:
    """Every number of the scene (SI units)."""

    object_radius: float = 0.5
    fingertip_radius: float = 0.1
    mu: float = math.tan(math.radians(20.0))
    torsion: float = 0.1 * 0.1 * math.tan(math.radians(20.0))  # m: spin torque ≤ torsion · f_n
    object_mass: float = 0.1
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    timestep: float = 0.001
    mount_mass: float = 1.0e4
    tip_mass: float = 0.1
    grip_stiffness: float = 5000.0
    grip_damping_ratio: float = 1.0
    grip_travel: float = 0.003
    contact_imp: float = 0.95
    impratio: float = 10.0
    noslip_iterations: int = 20
    touch_distance: float = 1e-4
    finger_positions: tuple[tuple[float, float, float], ...] = field(default_factory=tuple)

    @property
    def contact_timeconst(self) -> float:
        """solref time constant: 2 × timestep, the stiffest MuJoCo integrates stably."""
        return 2.0 * self.timestep

    @staticmethod
    def from_config(cfg: DaemonConfig, **overrides: Any) -> SceneParams:
        """The scene of the hand a daemon with ``cfg`` controls.

        The timestep divides the control period and is at most 1 ms (the
        accuracy NOTES.md measured), so each period is a whole number of steps.
        """
        substeps = max(1, math.ceil(cfg.period / 0.001 - 1e-9))
        m = cfg.model
        kw: dict[str, Any] = {
            "object_radius": m.object_radius,
            "fingertip_radius": m.fingertip_radius,
            "mu": m.mu,
            "torsion": m.torsion,
            "object_mass": cfg.load.object_mass,
            "gravity": tuple(cfg.load.gravity),
            "timestep": cfg.period / substeps,
            "touch_distance": m.contact_tolerance,
        }
        kw.update(overrides)
        return SceneParams(**kw)


def _inertial(mass: float, rot_inertia: float) -> str:
    i = f"{rot_inertia:.12g}"
    return f'<inertial pos="0 0 0" mass="{mass:.12g}" diaginertia="{i} {i} {i}"/>'


def build_xml(p: SceneParams) -> str:
    """The MJCF text of the scene."""
    R, r = p.object_radius, p.fingertip_radius
    damping = 2.0 * p.grip_damping_ratio * math.sqrt(p.grip_stiffness * p.tip_mass)
    tip_rot = 0.4 * p.mount_mass * r * r
    bodies, pairs = [], []
    for i, pos in enumerate(p.finger_positions):
        x, y, z = pos
        bodies.append(
            f'    <body name="mount{i}" pos="{x:.12g} {y:.12g} {z:.12g}" gravcomp="1">\n'
            f'      <freejoint name="mount{i}"/>\n'
            f"      {_inertial(p.mount_mass, tip_rot)}\n"
            f'      <body name="tip{i}" gravcomp="1">\n'
            f'        <joint name="press{i}" type="slide" axis="1 0 0" stiffness="{p.grip_stiffness:.12g}" '
            f'damping="{damping:.12g}" range="{-p.grip_travel:.12g} {p.grip_travel:.12g}"/>\n'
            f'        <joint name="ball{i}" type="ball"/>\n'
            f"        {_inertial(p.tip_mass, tip_rot)}\n"
            f'        <geom name="tip{i}" type="sphere" size="{r:.12g}" contype="0" conaffinity="0"/>\n'
            f"      </body>\n"
            f"    </body>"
        )
        pairs.append(
            f'    <pair name="contact{i}" geom1="object" geom2="tip{i}" condim="4" '
            f'friction="{p.mu:.12g} {p.mu:.12g} {p.torsion:.12g} 0 0" '
            f'solref="{p.contact_timeconst:.12g} 1" '
            f'solimp="{p.contact_imp:.12g} {p.contact_imp:.12g} 0.001 0.5 2" '
            f'margin="0" gap="{p.touch_distance:.12g}"/>'
        )
    g = " ".join(f"{v:.12g}" for v in p.gravity)
    inertia = 0.4 * p.object_mass * R * R  # solid sphere
    nl = "\n"
    return f"""<mujoco model="gaitd_mujoco_plant">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{p.timestep:.12g}" gravity="{g}" cone="elliptic" impratio="{p.impratio:.12g}"
          solver="Newton" iterations="200" tolerance="1e-10" ls_iterations="50"
          noslip_iterations="{p.noslip_iterations}" integrator="Euler"/>
  <worldbody>
    <body name="object">
      <freejoint name="object"/>
      {_inertial(p.object_mass, inertia)}
      <geom name="object" type="sphere" size="{R:.12g}" contype="0" conaffinity="0"/>
    </body>
{nl.join(bodies)}
  </worldbody>
  <contact>
{nl.join(pairs)}
  </contact>
</mujoco>
"""


def contact_stiffness(p: SceneParams, invweight_object: float, invweight_tip: float) -> float:
    """Static normal force per metre of penetration [N/m] of a fingertip contact.

    MuJoCo's soft constraint at rest with a flat impedance d: the reference
    stiffness is k = 1 / (d² tc² ζ²) (ζ = 1) and the regulariser
    R = (1 − d)/d · A_ii, with A_ii ≈ the bodies' inverse weights; the
    force per penetration is then k · d / R. The preload uses it so that
    the contact, not the press spring, carries the grip.
    """
    d = p.contact_imp
    k = 1.0 / (d * d * p.contact_timeconst**2)
    diag = invweight_object + invweight_tip
    return k * d / ((1.0 - d) / d * diag)

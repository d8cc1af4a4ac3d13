"""The MuJoCo physics hand: a :class:`~gaitd.plant.Plant` that simulates the grasp.

The scene (``mujoco_scene``) is built from the daemon's configuration:
radii, friction angle → μ, torsion, finger azimuths, the object's mass and
gravity (on or off as ``[load] gravity`` says; inertia of a solid sphere),
the control period. It starts in the daemon's paper start grasp.

How a setpoint drives the fingertips (`tests/oracles/mujoco/NOTES.md`):

* each step the mount's qpos is overwritten with the pose reached at the
  start of the step and its qvel with the *step velocity* that lands it on
  the next commanded pose ((p₁ − p₀)/h and the rotation increment; MuJoCo's
  semi-implicit Euler integrates with the new velocity, so a central
  difference would be wrong); the mount frame's x axis follows the inward
  contact normal −p/|p| by parallel transport;
* the ball joint is overwritten with the commanded fingertip orientation
  relative to the mount (rolling needs the true fingertip rotation);
* the press axis carries the grip: a force e · F · (1 + k_s / K) along the
  inward normal (k_s the press spring, K the contact stiffness), so that at
  rest the contact — not the spring — carries exactly F; e ramps in (10 ms)
  when a finger grasps, or when a placing finger touches, and out (5 ms)
  when it lifts or is free: no press force unless grasping. The ramp out
  is short because a pressed fingertip stays on the surface while its
  mount rises: for longer than a few ticks it would not follow its
  setpoint (the daemon's stall check, ``[feedback] stall_ratio``); the
  daemon unloads a finger before it lifts, so little force is left then.

Everything reported is read from the simulated state: object orientation,
angular velocity and centre from its free joint; fingertip poses and
velocities from the mount, press and ball joints; contact flags from
MuJoCo's contact list (within the contact tolerance) and normal forces
from the contact solver (``mj_contactForce``); the roll integrated as
τ̇ = ω_f · (Q_f e_z) from the simulated fingertip rotation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from .. import quat
from ..quat import Quat, Vec
from ..config import DaemonConfig
from ..hand import holding_grip, paper_start
from ..plant import Plant
from ..schema import PlantFault, PlantFingerMode
from ..setpoint import FingerMeasured, Measured, Setpoint
from .mujoco_scene import SceneParams, build_xml, contact_stiffness

E_X: Vec = (1.0, 0.0, 0.0)
E_Z: Vec = (0.0, 0.0, 1.0)


def _cross(a: Sequence[float], b: Sequence[float]) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Sequence[float], b: Sequence[float]) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _inward(p: Sequence[float]) -> Vec:
    n = math.sqrt(_dot(p, p))
    return (-p[0] / n, -p[1] / n, -p[2] / n)


@dataclass
class _Finger:
    """One finger's drive state (plain floats: a few per step, numpy would cost more)."""

    qpos_mount: int
    qvel_mount: int
    qpos_press: int
    qvel_press: int
    qpos_ball: int
    qvel_ball: int
    geom: int
    position: Vec  # commanded pose reached at the start of the next step
    orientation: Quat
    frame: Quat  # mount frame (x = inward normal)
    target_position: Vec
    target_orientation: Quat
    mode: PlantFingerMode
    grip: float  # F: the force the press axis delivers when engaged
    engaged: float  # e in [0, 1]
    roll: float
    measured_orientation: Quat
    touching: bool = False
    normal_force: float = 0.0


class MujocoPlant(Plant):
    """The reference physics hand (see the module docs)."""

    simulated = True

    def __init__(
        self,
        config: DaemonConfig,
        initial: Setpoint | None = None,
        initial_grip: float | None = None,
        press_ramp_in: float = 0.01,
        press_ramp_out: float = 0.005,
        scene: dict[str, Any] | None = None,
        **plant_args: Any,
    ):
        super().__init__(config, **plant_args)
        model = config.model
        if initial is None:
            grip = initial_grip
            if grip is None:
                grip = holding_grip(
                    model, config.load.object_mass, config.load.gravity, config.load.min_grip, config.load.max_grip
                )
            initial = paper_start(model, (grip,) * 3)
        self._initial = initial.still()
        self.params = SceneParams.from_config(
            config, finger_positions=tuple(f.position for f in initial.fingers), **(scene or {})
        )
        self.substeps = max(1, round(self.period / self.params.timestep))
        self.press_ramp_in, self.press_ramp_out = press_ramp_in, press_ramp_out
        self.xml = build_xml(self.params)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self.diverged: str | None = None
        self._max_reach = 2.0 * (model.object_radius + model.fingertip_radius)
        self._max_grip = config.load.max_grip
        self._force = np.zeros(6)
        self._reset()

    # ------------------------------------------------------------------ set-up

    def _reset(self) -> None:
        m, d = self.model, self.data

        def jq(name: str) -> int:
            return int(m.jnt_qposadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)])

        def jv(name: str) -> int:
            return int(m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)])

        def body(name: str) -> int:
            return int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name))

        def geom(name: str) -> int:
            return int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name))

        self._obj_q, self._obj_v = jq("object"), jv("object")
        self._obj_geom = geom("object")
        stiffness = contact_stiffness(
            self.params, m.body_invweight0[body("object"), 0], m.body_invweight0[body("tip0"), 0]
        )
        self.contact_stiffness = stiffness
        self._preload = 1.0 + self.params.grip_stiffness / stiffness
        self.fingers: list[_Finger] = []
        d.qpos[self._obj_q : self._obj_q + 7] = (0, 0, 0, *quat.IDENTITY)
        d.qvel[:] = 0.0
        for i, f in enumerate(self._initial.fingers):
            frame = quat.arc(E_X, _inward(f.position))
            engaged = 1.0 if f.mode == PlantFingerMode.Grasping else 0.0
            fs = _Finger(
                jq(f"mount{i}"),
                jv(f"mount{i}"),
                jq(f"press{i}"),
                jv(f"press{i}"),
                jq(f"ball{i}"),
                jv(f"ball{i}"),
                geom(f"tip{i}"),
                f.position,
                f.orientation,
                frame,
                f.position,
                f.orientation,
                f.mode,
                f.grip_force,
                engaged,
                f.roll,
                f.orientation,
            )
            d.qpos[fs.qpos_mount : fs.qpos_mount + 7] = (*f.position, *frame)
            d.qpos[fs.qpos_ball : fs.qpos_ball + 4] = quat.mul(quat.conj(frame), f.orientation)
            # Start at the static penetration, preloaded: the contact carries the grip at t = 0
            # (NOTES.md: apply the preload before the first mj_forward).
            d.qpos[fs.qpos_press] = engaged * f.grip_force / stiffness
            d.qfrc_applied[fs.qvel_press] = engaged * f.grip_force * self._preload
            self.fingers.append(fs)
        mujoco.mj_forward(m, d)
        self._contacts()

    # ------------------------------------------------------------------ Plant

    def initial_setpoint(self) -> Setpoint:
        """The start grasp the scene was built in."""
        return self._initial

    def check(self, setpoint: Setpoint) -> str | None:
        """Refuses fingertips out of reach of the scene and grips above ``[load] max_grip``."""
        for i, f in enumerate(setpoint.fingers):
            if math.sqrt(_dot(f.position, f.position)) > self._max_reach:
                return f"finger {i}: fingertip {f.position} beyond the hand's reach ({self._max_reach:g} m)"
            if math.sqrt(_dot(f.position, f.position)) < 1e-6:
                return f"finger {i}: fingertip at the object centre"
            if f.grip_force > self._max_grip:
                return f"finger {i}: grip {f.grip_force:g} N above max_grip {self._max_grip:g} N"
        return None

    def apply(self, setpoint: Setpoint) -> None:
        """Takes the new fingertip targets; :meth:`step` moves there."""
        for fs, f in zip(self.fingers, setpoint.fingers):
            fs.target_position = f.position
            fs.target_orientation = f.orientation
            fs.mode = f.mode
            # A grasping or placing finger presses with what is commanded now; a lifting or free
            # one keeps its last grip for the ramp out.
            if f.mode in (PlantFingerMode.Grasping, PlantFingerMode.Placing):
                fs.grip = f.grip_force

    def step(self, dt: float) -> None:
        """Advances ``dt`` (whole timesteps), moving each mount onto its target at the end."""
        n = max(1, round(dt / self.params.timestep))
        h = self.params.timestep
        m, d = self.model, self.data
        rate = (
            h / self.press_ramp_in if self.press_ramp_in > 0 else 1.0,
            h / self.press_ramp_out if self.press_ramp_out > 0 else 1.0,
        )
        starts = [(fs.position, fs.orientation) for fs in self.fingers]
        for j in range(1, n + 1):
            s = j / n
            for fs, (p0, q0) in zip(self.fingers, starts):
                if n == 1:
                    p1, q1 = fs.target_position, fs.target_orientation
                else:
                    tp = fs.target_position
                    p1 = (p0[0] + (tp[0] - p0[0]) * s, p0[1] + (tp[1] - p0[1]) * s, p0[2] + (tp[2] - p0[2]) * s)
                    q1 = quat.slerp(q0, fs.target_orientation, s)
                self._drive(fs, p1, q1, h, rate)
            mujoco.mj_step(m, d)
            self._after_step()
            if self.diverged:
                return

    def _drive(self, fs: _Finger, p1: Vec, q1: Quat, h: float, rate: tuple[float, float]) -> None:
        """Overwrites one finger's mount and ball for the step that ends at pose (p1, q1)."""
        d = self.data
        p0, q0, c0 = fs.position, fs.orientation, fs.frame
        c1 = quat.normalize(quat.mul(quat.arc(_inward(p0), _inward(p1)), c0))
        b0 = quat.mul(quat.conj(c0), q0)
        b1 = quat.mul(quat.conj(c1), q1)
        wm = quat.to_rotvec(quat.mul(quat.conj(c0), c1))
        wb = quat.to_rotvec(quat.mul(quat.conj(b0), b1))
        a, v = fs.qpos_mount, fs.qvel_mount
        d.qpos[a : a + 7] = (*p0, *c0)
        d.qvel[v : v + 6] = (
            (p1[0] - p0[0]) / h,
            (p1[1] - p0[1]) / h,
            (p1[2] - p0[2]) / h,
            wm[0] / h,
            wm[1] / h,
            wm[2] / h,
        )
        d.qpos[fs.qpos_ball : fs.qpos_ball + 4] = b0
        d.qvel[fs.qvel_ball : fs.qvel_ball + 3] = (wb[0] / h, wb[1] / h, wb[2] / h)
        want = fs.mode == PlantFingerMode.Grasping or (fs.mode == PlantFingerMode.Placing and fs.touching)
        fs.engaged = min(1.0, fs.engaged + rate[0]) if want else max(0.0, fs.engaged - rate[1])
        d.qfrc_applied[fs.qvel_press] = fs.engaged * fs.grip * self._preload
        fs.position, fs.orientation, fs.frame = p1, q1, c1

    def _after_step(self) -> None:
        d = self.data
        o = self._obj_q
        centre = (d.qpos[o], d.qpos[o + 1], d.qpos[o + 2])
        if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
            self.diverged = "MuJoCo reported bad accelerations (the simulation reset itself)"
        elif not all(math.isfinite(c) for c in centre) or _dot(centre, centre) > self.params.object_radius**2:
            self.diverged = f"object centre {centre} left the hand"
        for fs in self.fingers:
            q = self._tip_orientation(fs)
            # τ̇ = ω_f · a_f over the step: the rotation increment about the mean pole axis.
            axis = quat.rotate(q, E_Z)
            axis0 = quat.rotate(fs.measured_orientation, E_Z)
            mid = (axis[0] + axis0[0], axis[1] + axis0[1], axis[2] + axis0[2])
            n = math.sqrt(_dot(mid, mid))
            if n > 1e-12:
                fs.roll += _dot(quat.to_rotvec(quat.mul(q, quat.conj(fs.measured_orientation))), mid) / n
            fs.measured_orientation = q
        self._contacts()

    def _contacts(self) -> None:
        """Contact flags and normal forces per finger from MuJoCo's contact list and solver."""
        m, d = self.model, self.data
        for fs in self.fingers:
            fs.touching, fs.normal_force = False, 0.0
        if d.ncon == 0:
            return
        geoms = d.contact.geom
        for c in range(d.ncon):
            g1, g2 = int(geoms[c][0]), int(geoms[c][1])
            other = g2 if g1 == self._obj_geom else g1
            for fs in self.fingers:
                if fs.geom == other:
                    fs.touching = True
                    mujoco.mj_contactForce(m, d, c, self._force)
                    fs.normal_force += float(self._force[0])

    def _tip_orientation(self, fs: _Finger) -> Quat:
        q = self.data.qpos
        a, b = fs.qpos_mount, fs.qpos_ball
        return quat.normalize(quat.mul((q[a + 3], q[a + 4], q[a + 5], q[a + 6]), (q[b], q[b + 1], q[b + 2], q[b + 3])))

    def measure(self) -> Measured:
        """The simulated state (see the module docs)."""
        qp, qv = self.data.qpos, self.data.qvel
        o, ov = self._obj_q, self._obj_v
        oq = (qp[o + 3], qp[o + 4], qp[o + 5], qp[o + 6])
        fingers = []
        for fs in self.fingers:
            a, va = fs.qpos_mount, fs.qvel_mount
            qm = (qp[a + 3], qp[a + 4], qp[a + 5], qp[a + 6])
            axis = quat.rotate(qm, E_X)
            s, sd = qp[fs.qpos_press], qv[fs.qvel_press]
            offset = (s * axis[0], s * axis[1], s * axis[2])
            p = (qp[a] + offset[0], qp[a + 1] + offset[1], qp[a + 2] + offset[2])
            wm = quat.rotate(qm, (qv[va + 3], qv[va + 4], qv[va + 5]))
            q = self._tip_orientation(fs)
            wb = quat.rotate(q, (qv[fs.qvel_ball], qv[fs.qvel_ball + 1], qv[fs.qvel_ball + 2]))
            rot = _cross(wm, offset)
            vel = (
                qv[va] + rot[0] + sd * axis[0],
                qv[va + 1] + rot[1] + sd * axis[1],
                qv[va + 2] + rot[2] + sd * axis[2],
            )
            fingers.append(
                FingerMeasured(
                    position=p,
                    orientation=q,
                    contact=fs.touching,
                    roll=fs.roll,
                    velocity=vel,
                    angular_velocity=(wm[0] + wb[0], wm[1] + wb[1], wm[2] + wb[2]),
                    normal_force=fs.normal_force,
                )
            )
        return Measured(
            object_q=oq,
            fingers=tuple(fingers),
            object_omega=quat.rotate(oq, (qv[ov + 3], qv[ov + 4], qv[ov + 5])),
            object_center=(qp[o], qp[o + 1], qp[o + 2]),
            fault=PlantFault.Diverged if self.diverged else PlantFault.None_,
        )

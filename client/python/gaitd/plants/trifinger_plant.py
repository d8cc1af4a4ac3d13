"""TriFingerPro in MuJoCo as gaitd's joint-level plant: the daemon commands its joints, it measures them.

The hand is the chain hand of the daemon's ``[hand]`` (``kind = "chains"``):
the scene is ``trifinger_scene``'s, built from the description the
configuration names (URDF and hand section: links, masses, the 10 mm tips,
the ball, friction, gravity on as the hand section says), and it is stepped
by ``trifinger_hand`` — robot_fingers' action law every physics step.

* **Start**: the configured start grasp (``[hand] start_normals``): each
  finger's joints by inverse kinematics onto the ball, on the branch the
  daemon picks (``trifinger_grasp.start_joints``), the ball at the
  described centre; the hand holds it with balanced contact forces
  (``trifinger_grasp.holding_torques``, links' weight included) and a PD to
  those joints with the configured gains, and settles for ``settle``
  seconds under gravity before its first measurement, so the daemon's first
  state is a resting grasp. Until the daemon commands (and whenever it
  holds) that hold, or the last command, is applied.
* **Each command**: per finger a :class:`~gaitd.setpoint.JointSetpoint`,
  whose motor torque is ``torque + kp·(position − q) + kd·(velocity − q̇)``:
  the action law gets the torque ``torque + kd·velocity`` and the PD
  ``kp·(position − q) − kd·q̇`` — then its soft-limit push-back, clip,
  safety damping and clip. The physics steps ``substeps`` times per
  control period (default 1: the robot's own 1 kHz, one action per step).
* **Measured**: joint positions, velocities and the torque the motors
  really applied; per finger whether its tip touches the ball and the
  normal force there (MuJoCo's contact solver); the tip pose by MuJoCo's
  forward kinematics (relative to the described centre O, as the daemon
  reads tips); the object's orientation and centre (hand frame) as a
  tracking system gives them (``tracker``: rate, latency, noise), never the
  simulator's truth directly.
* **Truth kept for reports** (:class:`Truth`): the ball's true pose and its
  largest displacement from O, how often the action law's clip and soft
  limits acted per joint, the largest applied torque, how often the
  daemon's feed-forward torque was already at a motor's limit, the largest
  normal force, and steps on which a link (not a tip) or the floor touched
  the ball.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import mujoco
import numpy as np

from ..config import DaemonConfig
from ..plant import Plant
from ..quat import Quat, Vec
from ..schema import PlantFault, PlantFingerMode
from ..setpoint import FingerMeasured, FingerSetpoint, JointSetpoint, JointsMeasured, Measured, Setpoint
from .tracker import Tracker, TrackerSettings
from .trifinger_grasp import start_joints, holding_torques
from .trifinger_hand import F64, TriFingerHand, action_law_floats
from .trifinger_scene import SceneOptions, geom_name, load_hand

#: Seconds the start grasp settles under gravity before the first measurement.
SETTLE = 0.2


@dataclass
class Truth:
    """What really happened in the simulation (module docs); per joint arrays are finger by finger."""

    max_drift: float = 0.0  # largest |true centre − O| [m]
    feedforward_at_limit: list[int] = field(default_factory=list)  # per joint: steps commanded τ_ff = ± τ_max
    peak_normal_force: list[float] = field(default_factory=list)  # per finger [N]
    link_contact_steps: int = 0  # steps on which a link capsule touched the ball
    floor_contact_steps: int = 0  # steps on which the ball touched the floor
    tracker_max_angle: float = 0.0  # largest reported-vs-true orientation error [rad]
    tracker_max_offset: float = 0.0  # largest reported-vs-true centre error [m]
    settle_drift: float = 0.0  # the ball's motion while the start grasp settled [m]


class TriFingerPlant(Plant):
    """TriFingerPro in MuJoCo, commanded and measured by its joints (module docs)."""

    simulated = True

    def __init__(
        self,
        config: DaemonConfig,
        tracker: TrackerSettings | None = None,
        substeps: int = 1,
        settle: float = SETTLE,
        scene: SceneOptions | None = None,
        **plant_args: Any,
    ):
        super().__init__(config, **plant_args)
        hs = config.hand
        if hs is None or not config.chains:
            raise ValueError('the TriFingerPro plant needs a chain hand: [hand] kind = "chains"')
        if substeps < 1:
            raise ValueError(f"substeps {substeps}: at least 1")
        self.spec = load_hand(hs.description.parent, hs.description.name)
        if len(self.spec.fingers) != 3 or any(len(f.joints) != 3 for f in self.spec.fingers):
            raise ValueError(f"{hs.description}: the plant simulates three fingers of three joints")
        self.substeps = substeps
        options = replace(scene or SceneOptions(), timestep=self.period / substeps)
        self.hand = TriFingerHand(self.spec, options)
        self.model, self.data = self.hand.model, self.hand.data
        self.centre = np.asarray(self.spec.object_centre, dtype=np.float64)
        self._centre_vec: Vec = (float(self.centre[0]), float(self.centre[1]), float(self.centre[2]))
        self.start_q = start_joints(self.hand, hs.start_normals)
        hold = holding_torques(self.hand, self.start_q)
        h = self.hand
        # The action (torque, position, kp, kd per joint) and the law's constants, as plain floats.
        self._action = (hold.tolist(), self.start_q.tolist(), list(hs.joint_kp) * 3, list(hs.joint_kd) * 3)
        self._law = tuple(x.tolist() for x in (h.lower, h.upper, h.tau_max, h.default_kp, h.default_kd, h.safety_kd))
        self._tau = [0.0] * h.n
        self._limit = [float(x) - 1e-9 for x in h.tau_max]
        self._peak = [0.0] * h.n
        self._obj_adr = int(self.hand.qadr_object)
        self.diverged: str | None = None
        self.truth = Truth(feedforward_at_limit=[0] * self.hand.n, peak_normal_force=[0.0] * 3)
        self._ids()
        self._touching = [False, False, False]
        self._force = [0.0, 0.0, 0.0]
        self._wrench = np.zeros(6)
        self.time = 0.0
        self._initial = self._hold_setpoint(hold)
        start_centre = self.hand.object_position()
        for _ in range(round(settle / options.timestep)):
            self._physics()
        self.truth.settle_drift = float(np.linalg.norm(self.hand.object_position() - start_centre))
        self.hand.clip_count[:] = 0
        self.hand.limit_count[:] = 0
        self._peak = [0.0] * self.hand.n
        self.truth.max_drift = 0.0
        self.time = 0.0
        true_c, true_q = self.true_pose()
        self.start_object_q = true_q
        self.tracker = Tracker(tracker if tracker is not None else TrackerSettings(), true_c, true_q)
        self.tracker.observe(0.0, true_c, true_q)

    # ------------------------------------------------------------------ set-up

    def _ids(self) -> None:
        m = self.model

        def geom(name: str) -> int:
            return int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, name))

        self._obj_geom = geom("object")
        self._floor_geom = geom("floor") if self.hand.options.floor else -1
        self._tip_geoms = [geom(geom_name(f.tip, 0)) for f in self.spec.fingers]

    def _hold_setpoint(self, torque: F64) -> Setpoint:
        """The start grasp as a setpoint: every finger grasping, its joints held with ``torque``."""
        fingers = []
        for k in range(3):
            idx = slice(3 * k, 3 * k + 3)
            pos, orient = self._tip(k)
            joints = JointSetpoint(
                position=tuple(float(x) for x in self.start_q[idx]),
                velocity=(0.0, 0.0, 0.0),
                torque=tuple(float(x) for x in torque[idx]),
                kp=tuple(self._action[2][idx]),
                kd=tuple(self._action[3][idx]),
            )
            fingers.append(FingerSetpoint(PlantFingerMode.Grasping, pos, orient, joints=joints))
        return Setpoint(fingers=tuple(fingers))

    def _tip(self, k: int) -> tuple[Vec, Quat]:
        """Finger ``k``'s tip centre relative to O and the tip frame's orientation."""
        b = self.hand.tip_bodies[k]
        x, y, z = self.data.xpos[b].tolist()
        o = self._centre_vec
        w, i, j, kk = self.data.xquat[b].tolist()
        return (x - o[0], y - o[1], z - o[2]), (w, i, j, kk)

    def true_pose(self) -> tuple[Vec, Quat]:
        """The ball's true centre (hand frame) and orientation."""
        c, q = self.hand.object_position(), self.hand.object_quat()
        return (float(c[0]), float(c[1]), float(c[2])), (float(q[0]), float(q[1]), float(q[2]), float(q[3]))

    # ------------------------------------------------------------------ Plant

    def initial_setpoint(self) -> Setpoint:
        """The start grasp, held (module docs)."""
        return self._initial

    def check(self, setpoint: Setpoint) -> str | None:
        """Refuses fingertip commands (the daemon must run the same chain hand) and other joint counts."""
        if not setpoint.joints:
            return 'the daemon commands fingertips, not joints: run it with this [hand] (kind = "chains")'
        for i, f in enumerate(setpoint.fingers):
            if f.joints is None or len(f.joints.position) != 3:
                return f"finger {i}: {0 if f.joints is None else len(f.joints.position)} joints, the hand has 3"
        return None

    def apply(self, setpoint: Setpoint) -> None:
        """Takes each finger's joint setpoint as the action the next steps apply (module docs)."""
        torque, position, kp, kd = self._action
        counted = setpoint.enabled
        at_limit = self.truth.feedforward_at_limit
        for k, f in enumerate(setpoint.fingers):
            j = f.joints
            if j is None:
                continue
            s = slice(3 * k, 3 * k + 3)
            torque[s] = [t + g * v for t, g, v in zip(j.torque, j.kd, j.velocity)]
            position[s] = j.position
            kp[s] = j.kp
            kd[s] = j.kd
            if counted:
                for i, t in enumerate(j.torque):
                    if abs(t) >= self._limit[3 * k + i]:
                        at_limit[3 * k + i] += 1

    def step(self, dt: float) -> None:
        """Advances one control period (``substeps`` physics steps, the action law at each)."""
        for _ in range(self.substeps):
            self._physics()
            if self.diverged:
                return
        self.time += dt
        true_c, true_q = self.true_pose()
        seen = self.tracker.observe(self.time, true_c, true_q)
        t = self.truth
        off = math.dist(seen.centre, true_c)
        dot = abs(sum(x * y for x, y in zip(seen.orientation, true_q)))
        t.tracker_max_offset = max(t.tracker_max_offset, off)
        t.tracker_max_angle = max(t.tracker_max_angle, 2.0 * math.acos(min(1.0, dot)))

    def _physics(self) -> None:
        h, d = self.hand, self.data
        tau, clipped, limited = action_law_floats(
            self._action, d.qpos[h.qadr].tolist(), d.qvel[h.vadr].tolist(), *self._law
        )
        d.ctrl[h.act] = tau
        mujoco.mj_step(self.model, d)
        if any(clipped):
            h.clip_count += clipped
        if any(limited):
            h.limit_count += limited
        h.steps += 1
        self._tau = tau
        self._peak = [max(a, -b if b < 0.0 else b) for a, b in zip(self._peak, tau)]
        t = self.truth
        c = d.qpos[self._obj_adr : self._obj_adr + 3].tolist()
        t.max_drift = max(t.max_drift, math.dist(c, self._centre_vec))
        if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0:
            self.diverged = "MuJoCo reported bad accelerations (the simulation reset itself)"
        elif not all(math.isfinite(x) for x in c):
            self.diverged = "the object's state is not finite"
        self._contacts()

    def _contacts(self) -> None:
        """Per finger: touching and the normal force; links and floor on the ball counted."""
        m, d = self.model, self.data
        touching, force = [False, False, False], [0.0, 0.0, 0.0]
        link = floor = False
        for c in range(d.ncon):
            g1, g2 = int(d.contact.geom1[c]), int(d.contact.geom2[c])
            if self._obj_geom not in (g1, g2):
                continue
            other = g2 if g1 == self._obj_geom else g1
            if other == self._floor_geom:
                floor = True
            elif other in self._tip_geoms:
                k = self._tip_geoms.index(other)
                mujoco.mj_contactForce(m, d, c, self._wrench)
                touching[k] = True
                force[k] += float(self._wrench[0])
            else:
                link = True
        self._touching, self._force = touching, force
        t = self.truth
        t.link_contact_steps += link
        t.floor_contact_steps += floor
        for k in range(3):
            t.peak_normal_force[k] = max(t.peak_normal_force[k], force[k])

    def measure(self) -> Measured:
        """Joints, contacts and forces from the simulated state; the object as the tracker reports it."""
        h, d = self.hand, self.data
        q, dq, tau = d.qpos[h.qadr].tolist(), d.qvel[h.vadr].tolist(), self._tau
        fingers = []
        for k in range(3):
            idx = slice(3 * k, 3 * k + 3)
            pos, orient = self._tip(k)
            joints = JointsMeasured(position=tuple(q[idx]), velocity=tuple(dq[idx]), torque=tuple(tau[idx]))
            fingers.append(
                FingerMeasured(
                    position=pos,
                    orientation=orient,
                    contact=self._touching[k],
                    roll=0.0,
                    normal_force=self._force[k],
                    joints=joints,
                )
            )
        seen = self.tracker.reported
        return Measured(
            object_q=seen.orientation,
            fingers=tuple(fingers),
            object_center=seen.centre,
            fault=PlantFault.Diverged if self.diverged else PlantFault.None_,
            # The sample's age (the pose it was started on, before the first sample: still, so 0).
            object_age=self.time - seen.t if math.isfinite(seen.t) else 0.0,
        )

    # ------------------------------------------------------------------ reports

    def tip_gaps(self) -> list[float]:
        """Per finger, the tip sphere's distance from the ball's surface (negative: pressed in) [m]."""
        c = self.hand.object_position()
        R = self.spec.object_radius
        return [
            float(np.linalg.norm(self.hand.tip_position(k) - c)) - R - f.tip_radius
            for k, f in enumerate(self.spec.fingers)
        ]

    def report(self) -> dict[str, Any]:
        """The simulation's truth (module docs) as JSON-ready values."""
        c, q = self.true_pose()
        t, h = self.truth, self.hand
        return {
            "hand": "chains",
            "start_joints": self.start_q.tolist(),
            "start_object_q": list(self.start_object_q),
            "final_object_q": list(q),
            "final_object_center": list(c),
            "final_object_offset_m": math.dist(c, self._centre_vec),
            "max_object_drift_m": t.max_drift,
            "settle_drift_m": t.settle_drift,
            "physics_steps": int(h.steps),
            "clip_count": [int(x) for x in h.clip_count],
            "limit_count": [int(x) for x in h.limit_count],
            "peak_torque_Nm": list(self._peak),
            "torque_limit_Nm": [float(x) for x in h.tau_max],
            "feedforward_at_limit": t.feedforward_at_limit,
            "peak_normal_force_N": t.peak_normal_force,
            "final_normal_force_N": list(self._force),
            "final_contact": list(self._touching),
            "final_tip_gap_m": self.tip_gaps(),
            "link_contact_steps": t.link_contact_steps,
            "floor_contact_steps": t.floor_contact_steps,
            "tracker": {
                "rate_hz": self.tracker.settings.rate,
                "latency_s": self.tracker.settings.latency,
                "position_noise_m": self.tracker.settings.position_noise,
                "angle_noise_deg": math.degrees(self.tracker.settings.angle_noise),
                "samples": self.tracker.samples,
                "max_offset_m": t.tracker_max_offset,
                "max_angle_deg": math.degrees(t.tracker_max_angle),
            },
            "diverged": self.diverged,
        }

"""TriFingerPro in MuJoCo, driven as the real robot is: one joint-level action per step, the robot's action law.

Pure physics: no IPC, no daemon. The scene is ``trifinger_scene``'s (built
from the shipped URDF and ``hand.toml``). Every step:

1. ``action_law`` turns the action — per joint a torque, a position, kp and
   kd — into the motor torque from the state at the start of the step, as
   robot_fingers does (``process_desired_action``):

   * **soft limits**: a position command is clamped into the joint's soft
     limits; a joint that is beyond one gets a position command to that
     limit (if it had none), the default gains, and loses the part of its
     torque command that pushes further out;
   * **PD**: where a position is set, torque + kp·(position − q) − kd·q̇
     (a NaN gain means the default gain: kp 9, kd 0.01);
   * **clip** to ± τ_max (the URDF's effort, 0.396 N·m);
   * **velocity damping** − safety_kd·q̇ (0.09, 0.09, 0.05 per finger);
   * **clip** again.

2. The torque goes to the joint's motor (MuJoCo clamps it at ± effort too;
   after step 1 that clamp never acts) and the world advances one timestep.

The plant reports the torque it applied, counts each joint's steps on which
a clip acted and on which the soft-limit rule acted, and reads joint
positions, velocities and the object's pose from the simulated state.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import NDArray

from .trifinger_scene import DEFAULT_HAND_DIR, HandSpec, SceneOptions, build_xml, load_hand

F64 = NDArray[np.float64]

#: robot_fingers' defaults for TriFingerPro (``config/trifingerpro.yml``): position gains and safety damping.
DEFAULT_KP = (9.0, 9.0, 9.0)
DEFAULT_KD = (0.01, 0.01, 0.01)
SAFETY_KD = (0.09, 0.09, 0.05)


def _vec(x: float | Sequence[float] | F64, n: int) -> F64:
    a = np.asarray(x, dtype=np.float64)
    return np.full(n, float(a)) if a.ndim == 0 else a.astype(np.float64).reshape(n)


@dataclass
class Action:
    """One action for every joint (finger by finger, base to tip): NaN position = no position control,
    NaN gain = the default gain."""

    torque: F64
    position: F64
    kp: F64
    kd: F64

    @staticmethod
    def make(
        n: int,
        torque: float | Sequence[float] | F64 = 0.0,
        position: float | Sequence[float] | F64 = np.nan,
        kp: float | Sequence[float] | F64 = np.nan,
        kd: float | Sequence[float] | F64 = np.nan,
    ) -> Action:
        """An action for ``n`` joints; scalars apply to every joint."""
        return Action(_vec(torque, n), _vec(position, n), _vec(kp, n), _vec(kd, n))


@dataclass(frozen=True)
class LawResult:
    """What the action law made of one action: the motor torque and which rules acted, per joint."""

    torque: F64
    clipped: NDArray[np.bool_]  # the first or the second clip changed the torque
    limited: NDArray[np.bool_]  # the joint was beyond a soft limit


def action_law(
    action: Action,
    q: F64,
    dq: F64,
    lower: F64,
    upper: F64,
    tau_max: F64,
    default_kp: F64,
    default_kd: F64,
    safety_kd: F64,
) -> LawResult:
    """robot_fingers' processing of a desired action (see the module docs), for the state (q, q̇)."""
    torque = action.torque.copy()
    position = np.clip(action.position, lower, upper)  # NaN stays NaN
    kp = np.where(np.isnan(action.kp), default_kp, action.kp)
    kd = np.where(np.isnan(action.kd), default_kd, action.kd)
    below, above = q < lower, q > upper
    limited = below | above
    # beyond a limit: no torque further out, a position command to the limit, the default gains
    torque = np.where((below & (torque < 0.0)) | (above & (torque > 0.0)), 0.0, torque)
    position = np.where(limited & np.isnan(position), np.where(below, lower, upper), position)
    kp = np.where(limited, default_kp, kp)
    kd = np.where(limited, default_kd, kd)
    pd = kp * (position - q) - kd * dq
    torque = torque + np.where(np.isnan(pd), 0.0, pd)
    first = np.clip(torque, -tau_max, tau_max)
    damped = first - safety_kd * dq
    second = np.clip(damped, -tau_max, tau_max)
    clipped = (first != torque) | (second != damped)
    return LawResult(second, clipped, limited)


def action_law_floats(
    action: tuple[list[float], list[float], list[float], list[float]],
    q: list[float],
    dq: list[float],
    lower: list[float],
    upper: list[float],
    tau_max: list[float],
    default_kp: list[float],
    default_kd: list[float],
    safety_kd: list[float],
) -> tuple[list[float], list[bool], list[bool]]:
    """:func:`action_law` on plain floats, joint by joint: ``action`` is (torque, position, kp, kd);
    returns (torque, clipped, limited). The same rules in the same order; a plant's per-step path
    (nine joints: about 8 µs, against about 50 µs for the array form)."""
    torque, position, kp, kd = action
    out: list[float] = []
    clipped: list[bool] = []
    limited: list[bool] = []
    for i, x in enumerate(q):
        t, p, gp, gd, v = torque[i], position[i], kp[i], kd[i], dq[i]
        lo, hi, m = lower[i], upper[i], tau_max[i]
        if p == p:  # not NaN: clamped into the soft limits
            p = lo if p < lo else hi if p > hi else p
        gp = default_kp[i] if gp != gp else gp
        gd = default_kd[i] if gd != gd else gd
        below, above = x < lo, x > hi
        if (below and t < 0.0) or (above and t > 0.0):
            t = 0.0
        if below or above:
            if p != p:
                p = lo if below else hi
            gp, gd = default_kp[i], default_kd[i]
        if p == p:
            t = t + gp * (p - x) - gd * v
        first = -m if t < -m else m if t > m else t
        damped = first - safety_kd[i] * v
        second = -m if damped < -m else m if damped > m else damped
        out.append(second)
        clipped.append(first != t or second != damped)
        limited.append(below or above)
    return out, clipped, limited


@dataclass(frozen=True)
class Observation:
    """The state after a step, and the torque applied during it."""

    t: float
    q: F64  # joint positions [rad], finger by finger
    dq: F64  # joint velocities [rad/s]
    tau: F64  # the torque the motors applied [N·m]
    object_position: F64  # centre [m], hand frame
    object_quat: F64  # (w, x, y, z), world from object
    clipped: NDArray[np.bool_]
    limited: NDArray[np.bool_]


class TriFingerHand:
    """TriFingerPro and its object in MuJoCo, stepped one action at a time (see the module docs)."""

    def __init__(
        self,
        hand: HandSpec | None = None,
        options: SceneOptions | None = None,
        q0: Sequence[float] | F64 | None = None,
        default_kp: Sequence[float] = DEFAULT_KP,
        default_kd: Sequence[float] = DEFAULT_KD,
        safety_kd: Sequence[float] = SAFETY_KD,
    ):
        self.hand = hand if hand is not None else load_hand(DEFAULT_HAND_DIR)
        self.options = options if options is not None else SceneOptions()
        self.xml = build_xml(self.hand, self.options)
        self.model = mujoco.MjModel.from_xml_string(self.xml)
        self.data = mujoco.MjData(self.model)
        self._scratch = mujoco.MjData(self.model)
        m = self.model
        joints = self.hand.joints
        self.n = len(joints)
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j.name) for j in joints]
        self.qadr = np.array([m.jnt_qposadr[i] for i in ids])
        self.vadr = np.array([m.jnt_dofadr[i] for i in ids])
        self.act = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, j.name) for j in joints])
        self.lower = np.array([j.lower for j in joints])
        self.upper = np.array([j.upper for j in joints])
        self.tau_max = np.array([j.effort for j in joints])
        per_finger = [len(f.joints) for f in self.hand.fingers]
        if len(set(per_finger)) != 1 or per_finger[0] != len(default_kp):
            raise ValueError(f"gains are per finger joint ({len(default_kp)}); fingers have {per_finger} joints")
        k = len(self.hand.fingers)
        self.default_kp = np.tile(np.asarray(default_kp, dtype=np.float64), k)
        self.default_kd = np.tile(np.asarray(default_kd, dtype=np.float64), k)
        self.safety_kd = np.tile(np.asarray(safety_kd, dtype=np.float64), k)
        obj = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, "object")
        self._obj_q = int(m.jnt_qposadr[obj])
        self.qadr_object = self._obj_q  # the object's free joint in qpos: centre, then (w, x, y, z)
        self._obj_v = int(m.jnt_dofadr[obj])
        self.object_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "object")
        self.tip_bodies = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f.tip) for f in self.hand.fingers]
        self.finger_dofs = [self.vadr[3 * i : 3 * i + per_finger[i]] for i in range(k)]
        self.clip_count = np.zeros(self.n, dtype=np.int64)
        self.limit_count = np.zeros(self.n, dtype=np.int64)
        self.steps = 0
        self.reset(q0)

    # ------------------------------------------------------------------ state

    def reset(
        self,
        q: Sequence[float] | F64 | None = None,
        object_position: Sequence[float] | None = None,
    ) -> Observation:
        """Joints at ``q`` (default: zeros), at rest; the object at rest at ``object_position``
        (default: ``hand.toml``'s centre); counters cleared."""
        mujoco.mj_resetData(self.model, self.data)
        d = self.data
        d.qpos[self.qadr] = np.zeros(self.n) if q is None else np.asarray(q, dtype=np.float64)
        d.qpos[self._obj_q : self._obj_q + 3] = (
            self.hand.object_centre if object_position is None else np.asarray(object_position)
        )
        d.qpos[self._obj_q + 3 : self._obj_q + 7] = (1.0, 0.0, 0.0, 0.0)
        mujoco.mj_forward(self.model, d)
        self.clip_count[:] = 0
        self.limit_count[:] = 0
        self.steps = 0
        no = np.zeros(self.n, dtype=np.bool_)
        return self._observe(np.zeros(self.n), no, no)

    @property
    def q(self) -> F64:
        """Joint positions [rad]."""
        return np.array(self.data.qpos[self.qadr])

    @property
    def dq(self) -> F64:
        """Joint velocities [rad/s]."""
        return np.array(self.data.qvel[self.vadr])

    def object_position(self) -> F64:
        """The object's centre [m]."""
        return np.array(self.data.qpos[self._obj_q : self._obj_q + 3])

    def object_quat(self) -> F64:
        """The object's orientation (w, x, y, z), world from object."""
        return np.array(self.data.qpos[self._obj_q + 3 : self._obj_q + 7])

    def tip_position(self, finger: int) -> F64:
        """The tip frame's origin (the tip sphere's centre) of ``finger`` [m]."""
        return np.array(self.data.xpos[self.tip_bodies[finger]])

    def point_jacobian(self, finger: int, point: F64) -> F64:
        """The 3 × m Jacobian of the point ``point`` [m, world] fixed to ``finger``'s tip, over its joints."""
        jacp = np.zeros((3, self.model.nv))
        mujoco.mj_jac(self.model, self.data, jacp, None, np.asarray(point, dtype=np.float64), self.tip_bodies[finger])
        return np.asarray(jacp[:, self.finger_dofs[finger]])

    def gravity_torque(self, q: Sequence[float] | F64 | None = None) -> F64:
        """The joint torques that hold the links still against gravity at ``q`` (default: now): qfrc_bias at q̇ = 0."""
        s = self._scratch
        s.qpos[:] = self.data.qpos
        if q is not None:
            s.qpos[self.qadr] = np.asarray(q, dtype=np.float64)
        s.qvel[:] = 0.0
        mujoco.mj_forward(self.model, s)
        return np.array(s.qfrc_bias[self.vadr])

    # ------------------------------------------------------------------- step

    def law(self, action: Action) -> LawResult:
        """The action law for ``action`` at the current state (what ``step`` would apply)."""
        return action_law(
            action,
            self.q,
            self.dq,
            self.lower,
            self.upper,
            self.tau_max,
            self.default_kp,
            self.default_kd,
            self.safety_kd,
        )

    def step(self, action: Action) -> Observation:
        """Applies ``action`` through the action law for one timestep; the state after it."""
        r = self.law(action)
        self.data.ctrl[self.act] = r.torque
        mujoco.mj_step(self.model, self.data)
        self.clip_count += r.clipped
        self.limit_count += r.limited
        self.steps += 1
        return self._observe(r.torque, r.clipped, r.limited)

    def _observe(self, tau: F64, clipped: NDArray[np.bool_], limited: NDArray[np.bool_]) -> Observation:
        d = self.data
        return Observation(
            t=float(d.time),
            q=self.q,
            dq=self.dq,
            tau=np.array(tau),
            object_position=self.object_position(),
            object_quat=self.object_quat(),
            clipped=np.array(clipped),
            limited=np.array(limited),
        )

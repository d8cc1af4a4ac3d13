"""TriFingerPro in MuJoCo (``gaitd.plants.trifinger_scene``, ``trifinger_hand``), checked in physics.

The model is checked against the URDF as this file reads it (its own
ElementTree reading and chain product, not the package's), the action law
against robot_fingers' rules, and the hand against the one thing it is for:
holding the tennis ball with joint torques alone.
"""

from __future__ import annotations

import math
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

np = pytest.importorskip("numpy", reason="the TriFingerPro MuJoCo hand needs the [mujoco] extra (numpy)")
mujoco = pytest.importorskip("mujoco", reason="the TriFingerPro MuJoCo hand needs the [mujoco] extra (mujoco)")

from gaitd.plants.trifinger_hand import Action, TriFingerHand, action_law  # noqa: E402

HAND_DIR = Path(__file__).resolve().parents[3] / "deploy" / "hands" / "trifingerpro"
URDF = HAND_DIR / "trifingerpro.urdf"
FINGERS = ("0", "120", "240")
TAU_MAX = 0.396


# ----------------------------------------------------------- the test's own URDF reading


def _get(el: ET.Element, child: str, key: str) -> str:
    c = el.find(child)
    assert c is not None, (el.get("name"), child)
    v = c.get(key)
    assert v is not None, (el.get("name"), child, key)
    return v


def _nums(text: str | None) -> list[float]:
    return [0.0, 0.0, 0.0] if text is None else [float(s) for s in text.split()]


def _rot(axis: list[float], angle: float) -> Any:
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def _rpy(rpy: list[float]) -> Any:
    r, p, y = rpy
    return _rot([0, 0, 1], y) @ _rot([0, 1, 0], p) @ _rot([1, 0, 0], r)


def urdf_chain(finger: str) -> list[dict[str, Any]]:
    """Joints from base_link to finger's tip link, straight from the URDF file."""
    root = ET.parse(URDF).getroot()
    by_child = {_get(j, "child", "link"): j for j in root.findall("joint")}
    out = []
    link = f"finger_tip_link_{finger}"
    while link != "base_link":
        j = by_child[link]
        o = j.find("origin")
        ax = j.find("axis")
        out.append(
            {
                "type": j.get("type"),
                "xyz": _nums(None if o is None else o.get("xyz")),
                "rpy": _nums(None if o is None else o.get("rpy")),
                "axis": _nums(None if ax is None else ax.get("xyz")),
                "child": link,
            }
        )
        link = _get(j, "parent", "link")
    return out[::-1]


def urdf_frames(finger: str, q: list[float]) -> list[tuple[Any, Any, dict[str, Any]]]:
    """(R, p, joint) of every joint's child frame, base to tip, at joint angles q."""
    R, p = np.eye(3), np.zeros(3)
    frames = []
    qs = iter(q)
    for j in urdf_chain(finger):
        p = p + R @ np.asarray(j["xyz"])
        R = R @ _rpy(j["rpy"])
        if j["type"] == "revolute":
            R = R @ _rot(j["axis"], next(qs))
        frames.append((R, p, j))
    return frames


def urdf_tip(finger: str, q: list[float]) -> Any:
    return urdf_frames(finger, q)[-1][1]


def urdf_link_inertials() -> dict[str, tuple[float, list[float]]]:
    root = ET.parse(URDF).getroot()
    out = {}
    for link in root.findall("link"):
        ie = link.find("inertial")
        if ie is not None:
            out[link.get("name", "")] = (
                float(_get(ie, "mass", "value")),
                _nums(_get(ie, "origin", "xyz")),
            )
    return out


def urdf_gravity_torque(finger: str, q: list[float], g: list[float]) -> Any:
    """Joint torques that hold the finger's links against gravity g, from the URDF's masses and COMs."""
    inertials = urdf_link_inertials()
    frames = urdf_frames(finger, q)
    coms = []
    for R, p, j in frames:
        if j["child"] in inertials:
            m, c = inertials[j["child"]]
            coms.append((m, p + R @ np.asarray(c)))
    tau = []
    for i, (R, p, j) in enumerate(frames):
        if j["type"] != "revolute":
            continue
        axis = R @ np.asarray(j["axis"])
        below = {f[2]["child"] for f in frames[i:]}
        load = sum(
            np.dot(axis, np.cross(c - p, m * np.asarray(g)))
            for (m, c), (_, _, jj) in zip(coms, [f for f in frames if f[2]["child"] in inertials])
            if jj["child"] in below
        )
        tau.append(-load)
    return np.array(tau)


# ----------------------------------------------------------------- (a) the model is the URDF


CONFIGS = [
    [0.0, 0.0, 0.0],
    [0.0, 0.9, -1.7],  # upstream's initial pose
    [0.368, 0.883, -1.854],  # the README's tennis-ball grasp
    [-0.3, 1.5, -0.2],
    [0.9, 0.1, -2.6],
]


def test_tip_forward_kinematics_is_the_urdf_chain() -> None:
    h = TriFingerHand()
    rng = np.random.default_rng(7)
    configs = CONFIGS + [list(rng.uniform(h.lower[:3], h.upper[:3])) for _ in range(5)]
    worst = 0.0
    for q in configs:
        h.reset(q * 3)
        for k, f in enumerate(FINGERS):
            err = float(np.linalg.norm(h.tip_position(k) - urdf_tip(f, q)))
            worst = max(worst, err)
            assert err < 1e-9, (f, q, h.tip_position(k), urdf_tip(f, q))
    # q = 0: every link straight down; the closed-form IK's offsets (TIP_X_OFFSET 0.086,
    # JOINT1_Y_OFFSET 0.0505, two 0.16 m links below the 0.29 m holder).
    h.reset([0.0] * 9)
    assert np.allclose(h.tip_position(0), [0.086, 0.0505, 0.29 - 0.32], atol=1e-12)
    # The README's grasp (joints to 3 decimals): tip on the ball's equator at azimuth 75° (within 0.2 mm),
    # the other fingers the same point turned by -120° and -240°.
    h.reset([0.368, 0.883, -1.854] * 3)
    hand = h.hand
    reach = hand.object_radius + hand.fingers[0].tip_radius
    for k, az in enumerate((75.0, -45.0, -165.0)):
        a = math.radians(az)
        want = np.asarray(hand.object_centre) + reach * np.array([math.cos(a), math.sin(a), 0.0])
        assert np.linalg.norm(h.tip_position(k) - want) < 2e-4
    print(f"\ntip FK vs URDF chain: worst {worst:.1e} m over {len(configs)} configurations x 3 fingers")


def test_masses_limits_and_motors_are_the_urdf() -> None:
    h = TriFingerHand()
    m = h.model
    for name, (mass, com) in urdf_link_inertials().items():
        b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
        assert b >= 0, name
        assert m.body_mass[b] == pytest.approx(mass, abs=1e-12)
        assert np.allclose(m.body_ipos[b], com, atol=1e-12)
    root = ET.parse(URDF).getroot()
    revolute = [j for j in root.findall("joint") if j.get("type") == "revolute"]
    assert len(revolute) == 9 == m.nu
    for j in revolute:
        a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, j.get("name"))
        assert list(m.actuator_ctrlrange[a]) == [-float(_get(j, "limit", "effort")), float(_get(j, "limit", "effort"))]
        i = list(h.act).index(a)
        assert (h.lower[i], h.upper[i]) == (float(_get(j, "limit", "lower")), float(_get(j, "limit", "upper")))
    hand = h.hand
    ball = h.object_body
    assert m.body_mass[ball] == pytest.approx(hand.object_mass)
    assert np.allclose(h.object_position(), hand.object_centre)
    assert m.opt.timestep <= 0.001
    assert list(m.opt.gravity) == [0.0, 0.0, -9.81]


# ----------------------------------------------------------------- (b) gravity compensation


def _hold_finger(compensate: bool) -> float:
    """Largest joint drift [rad] over 1 s with torque = the links' gravity torques (or none), kp = kd = 0."""
    h = TriFingerHand()
    q0 = [0.0, 0.9, -1.7] * 3
    h.reset(q0, object_position=(0.5, 0.5, h.hand.object_radius))  # the ball out of reach, on the floor
    g = np.concatenate([urdf_gravity_torque(f, q0[:3], list(h.hand.gravity)) for f in FINGERS])
    assert np.allclose(g, h.gravity_torque(), atol=1e-9), (g, h.gravity_torque())
    assert np.max(np.abs(g)) > 0.05  # the links' weight matters at this pose
    drift = 0.0
    for _ in range(1000):
        obs = h.step(Action.make(9, torque=g if compensate else 0.0, kp=0.0, kd=0.0))
        drift = max(drift, float(np.max(np.abs(obs.q - q0))))
    return drift


def test_gravity_torques_hold_a_finger_still() -> None:
    drift = _hold_finger(compensate=True)
    print(f"\ngravity-compensated drift over 1 s: {drift:.2e} rad")
    assert drift < 1e-3


def test_without_gravity_torques_a_finger_falls() -> None:
    drift = _hold_finger(compensate=False)
    print(f"\nuncompensated drift over 1 s: {drift:.2f} rad")
    assert drift > 0.1


# ----------------------------------------------------------------- (c) the safety law


def test_torque_beyond_the_limit_is_clipped_and_counted() -> None:
    h = TriFingerHand()
    h.reset([0.0, 0.9, -1.7] * 3, object_position=(0.5, 0.5, h.hand.object_radius))
    tau = np.array([1.0, -1.0, 0.2, 0.5, -0.3964, 0.396, -0.396, 3.0, -0.1])
    beyond = np.abs(tau) > TAU_MAX
    obs = h.step(Action.make(9, torque=tau))
    want = np.clip(tau, -TAU_MAX, TAU_MAX)
    assert np.array_equal(obs.tau, want)  # exactly ±0.396 N·m where beyond, untouched within
    assert np.array_equal(h.data.actuator_force[h.act], want)  # and that is what the motors applied
    assert np.array_equal(obs.clipped, beyond)
    assert np.array_equal(h.clip_count, beyond.astype(int))
    h.step(Action.make(9, torque=tau))
    assert np.array_equal(h.clip_count, 2 * beyond.astype(int))


def test_safety_damping_then_the_second_clip() -> None:
    z = np.zeros(3)
    lo, hi = np.array([-0.33, 0.0, -2.7]), np.array([1.0, 1.57, 0.0])
    kd_safe = np.array([0.09, 0.09, 0.05])
    act = Action.make(3, torque=[0.396, 0.3, 0.0])
    q, dq = np.array([0.0, 0.9, -1.7]), np.array([-1.0, -1.0, 2.0])
    r = action_law(act, q, dq, lo, hi, np.full(3, TAU_MAX), np.full(3, 9.0), np.full(3, 0.01), kd_safe)
    # 0.396 + 0.09 clipped back to 0.396; 0.3 + 0.09 = 0.39 within; 0 - 0.05·2 = -0.1
    assert np.allclose(r.torque, [0.396, 0.39, -0.1], atol=1e-15)
    assert list(r.clipped) == [True, False, False]
    assert not r.limited.any()
    # the PD, with default gains where NaN: 9·(1.0 − 0.9) − 0.01·(−1.0) for the middle joint
    pd = Action.make(3, position=[np.nan, 1.0, np.nan], kp=np.nan, kd=np.nan)
    r = action_law(pd, q, dq, lo, hi, np.full(3, TAU_MAX), np.full(3, 0.1), np.full(3, 0.01), z)
    assert r.torque[1] == pytest.approx(0.1 * 0.1 + 0.01)
    assert r.torque[0] == 0.0 and r.torque[2] == 0.0
    # a position command beyond a soft limit is clamped to it: target 1.5 for the upper joint acts as 1.0
    far = Action.make(3, position=[1.5, np.nan, np.nan], kp=0.1, kd=0.0)
    r = action_law(far, np.array([0.5, 0.9, -1.7]), z, lo, hi, np.full(3, TAU_MAX), np.full(3, 9.0), z, z)
    assert r.torque[0] == pytest.approx(0.1 * (1.0 - 0.5))


def test_a_joint_beyond_a_soft_limit_is_pushed_back() -> None:
    h = TriFingerHand()
    h.model.opt.gravity[:] = 0.0  # the push-back alone, not its fight with the links' weight
    q0 = np.array([0.0, 0.9, -1.7] * 3)
    q0[0] = h.upper[0] + 0.1  # finger 0's upper joint 0.1 rad beyond its soft limit
    h.reset(q0, object_position=(0.5, 0.5, h.hand.object_radius))
    tau = np.zeros(9)
    tau[0] = 0.3  # a command pushing further out: the law discards it while the joint is beyond
    first = h.law(Action.make(9, torque=tau))
    assert first.limited[0] and not first.limited[1:].any()
    # a position command to the limit with the default kp 9: 9 · (1.0 − 1.1) = −0.9, clipped to −0.396
    assert first.torque[0] == -TAU_MAX and first.clipped[0]
    for _ in range(1000):
        obs = h.step(Action.make(9, torque=tau))
    print(
        f"\nupper joint {q0[0]:.3f} rad -> {obs.q[0]:.4f} rad (soft limit {h.upper[0]}), law acted {h.limit_count[0]}x"
    )
    assert h.limit_count[0] > 0
    assert h.upper[0] - 0.02 <= obs.q[0] <= h.upper[0] + 0.005


# ----------------------------------------------------------------- (d) the ball held by joint torques alone

AZIMUTHS = (75.0, -45.0, -165.0)  # finger 0's contact, the others turned with their fingers
SAFETY = 2.0  # the normal force is SAFETY × the least that friction needs


def grasp(h: TriFingerHand) -> Any:
    """Joints with every tip centre at R + r from the ball's centre on its equator (Newton on mj_jac)."""
    hand = h.hand
    reach = hand.object_radius + hand.fingers[0].tip_radius
    centre = np.asarray(hand.object_centre)
    targets = [centre + reach * np.array([math.cos(math.radians(a)), math.sin(math.radians(a)), 0.0]) for a in AZIMUTHS]
    q = np.array([0.37, 0.88, -1.85] * 3)
    for _ in range(20):
        h.reset(q)
        err = [targets[k] - h.tip_position(k) for k in range(3)]
        if max(float(np.max(np.abs(e))) for e in err) < 1e-12:
            break
        for k in range(3):
            q[3 * k : 3 * k + 3] += np.linalg.solve(h.point_jacobian(k, h.tip_position(k)), err[k])
    for k in range(3):
        assert np.linalg.norm(h.tip_position(k) - centre) == pytest.approx(reach, abs=1e-12)
    assert np.all(q > h.lower + 0.3) and np.all(q < h.upper - 0.3)
    return q


def hold(feed_forward: bool, seconds: float = 2.0) -> dict[str, float]:
    """The ball in the grasp with gravity on: τ = J_pᵀF + g (+ a light PD), or the PD and g alone."""
    h = TriFingerHand()
    q_grasp = grasp(h)
    h.reset(q_grasp)
    hand = h.hand
    r = hand.fingers[0].tip_radius
    weight = hand.object_mass * float(np.linalg.norm(hand.gravity))
    f_n = SAFETY * weight / (3.0 * hand.mu)
    up = np.array([0.0, 0.0, weight / 3.0])
    start = h.object_position()
    moved = tau_peak = wall = 0.0
    touching: set[str] = set()
    steps = round(seconds / h.model.opt.timestep)
    for _ in range(steps):
        t0 = time.perf_counter()
        centre = h.object_position()
        tau = h.gravity_torque()
        if feed_forward:
            for k in range(3):
                tip = h.tip_position(k)
                n = (tip - centre) / np.linalg.norm(tip - centre)  # the ball's outward normal at the contact
                jp = h.point_jacobian(k, tip - r * n)  # the contact point, fixed to the tip
                tau[3 * k : 3 * k + 3] += jp.T @ (-f_n * n + up)
        obs = h.step(Action.make(9, torque=tau, position=q_grasp, kp=0.5, kd=0.01))
        wall += time.perf_counter() - t0
        touching.update(
            mujoco.mj_id2name(h.model, mujoco.mjtObj.mjOBJ_GEOM, int(c.geom2)) for c in h.data.contact[: h.data.ncon]
        )
        moved = max(moved, float(np.linalg.norm(obs.object_position - start)))
        tau_peak = max(tau_peak, float(np.max(np.abs(obs.tau))))
    tips = {f"{f.tip}/0" for f in hand.fingers}  # the tip sphere, the tip link's only collision primitive
    return {
        "only_tips": float(touching <= tips),
        "moved": moved,
        "tau_peak": tau_peak,
        "clips": float(h.clip_count.sum()),
        "limits": float(h.limit_count.sum()),
        "contacts": float(h.data.ncon),
        "f_n": f_n,
        "rtf": seconds / wall,
    }


def test_the_ball_is_held_by_joint_torques_alone() -> None:
    r = hold(feed_forward=True)
    print(
        f"\nheld 2 s: ball moved {r['moved'] * 1e3:.3f} mm, |tau| <= {r['tau_peak']:.3f} N·m, "
        f"clips {r['clips']:.0f}, f_n {r['f_n']:.3f} N per tip, real-time factor {r['rtf']:.1f} (with the controller)"
    )
    assert r["moved"] < 0.005
    assert r["tau_peak"] <= TAU_MAX
    assert r["clips"] == 0 and r["limits"] == 0
    assert r["contacts"] >= 3
    assert r["only_tips"]  # no link capsule (nor the floor) ever touched the ball


def test_without_the_grip_force_the_ball_drops() -> None:
    r = hold(feed_forward=False)
    print(f"\nno feed-forward: ball moved {r['moved'] * 1e3:.1f} mm")
    assert r["moved"] > 0.005

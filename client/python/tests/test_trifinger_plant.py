"""TriFingerPro as gaitd's joint-level MuJoCo plant (``gaitd.plants.trifinger_plant``), without a daemon.

The plant is built from the shipped configuration (``deploy/hands/trifingerpro``)
and driven by setpoints as the daemon writes them: its start grasp is the
configured one and the daemon's feed-forward holds the ball there under
gravity; the measurement has every field the daemon reads; the motor torque
follows the setpoint's semantics and robot_fingers' safety law, and the
plant counts the law's clips and soft-limit push-backs.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

np = pytest.importorskip("numpy", reason="the TriFingerPro plant needs the [mujoco] extra (numpy)")
pytest.importorskip("mujoco", reason="the TriFingerPro plant needs the [mujoco] extra (mujoco)")

from gaitd import config  # noqa: E402
from gaitd.plants.tracker import TrackerSettings  # noqa: E402
from gaitd.plants.trifinger_plant import TriFingerPlant  # noqa: E402
from gaitd.setpoint import Setpoint  # noqa: E402

CONFIG = Path(__file__).resolve().parents[3] / "deploy" / "hands" / "trifingerpro" / "gaitd.toml"
TAU_MAX = 0.396


def plant(tracker: TrackerSettings | None = None) -> TriFingerPlant:
    return TriFingerPlant(config.load(CONFIG), tracker=tracker or TrackerSettings.exact())


def with_joints(sp: Setpoint, **fields: tuple[float, ...]) -> Setpoint:
    """``sp`` with the same joint fields set in every finger (``fields``: 9 values each, finger by finger)."""
    fingers = []
    for k, f in enumerate(sp.fingers):
        assert f.joints is not None
        part = {name: tuple(v[3 * k : 3 * k + 3]) for name, v in fields.items()}
        fingers.append(replace(f, joints=replace(f.joints, **part)))
    return replace(sp, fingers=tuple(fingers))


def daemon_feed_forward(p: TriFingerPlant, grip: float) -> tuple[float, ...]:
    """The daemon's feed-forward at the start joints: J_pᵀ(−grip·n) + g(q), n from the commanded tip
    (the contact target), J_p the contact point's Jacobian (PLANT-GUIDE, "A hand of finger chains")."""
    h = p.hand
    h_q = p.start_q
    saved = (np.array(p.data.qpos), np.array(p.data.qvel))
    h.reset(h_q)
    tau = h.gravity_torque()
    normals = p.config.hand.start_normals if p.config.hand else ()
    for k, n0 in enumerate(normals):
        n = np.asarray(n0) / np.linalg.norm(n0)
        tip = h.tip_position(k)
        jp = h.point_jacobian(k, tip - p.spec.fingers[k].tip_radius * n)
        tau[3 * k : 3 * k + 3] += jp.T @ (-grip * n)
    p.data.qpos[:], p.data.qvel[:] = saved
    import mujoco

    mujoco.mj_forward(p.model, p.data)
    return tuple(float(x) for x in np.clip(tau, -TAU_MAX, TAU_MAX))


def run(p: TriFingerPlant, sp: Setpoint, seconds: float) -> None:
    for _ in range(round(seconds / p.period)):
        p.apply(sp)
        p.step(p.period)


def test_it_starts_in_the_configured_grasp_and_measures_what_the_daemon_reads() -> None:
    p = plant()
    spec = p.spec
    cfg = p.config.hand
    assert cfg is not None
    m = p.measure()
    reach = spec.object_radius + spec.fingers[0].tip_radius
    for k, f in enumerate(m.fingers):
        n = np.asarray(cfg.start_normals[k]) / np.linalg.norm(cfg.start_normals[k])
        assert f.joints is not None and f.joints.velocity is not None and f.joints.torque is not None
        assert len(f.joints.position) == len(f.joints.velocity) == len(f.joints.torque) == 3
        q = np.array(f.joints.position)
        # Settled under gravity: the tip within 0.1 mm of the configured contact, the joints inside the limits.
        assert np.linalg.norm(np.array(f.position) - reach * n) < 1e-4
        assert np.all(q > p.hand.lower[3 * k : 3 * k + 3] + 0.05) and np.all(q < p.hand.upper[3 * k : 3 * k + 3] - 0.05)
        assert np.linalg.norm(p.start_q[3 * k : 3 * k + 3] - q) < 2e-3
        assert f.contact and f.normal_force is not None and f.normal_force > 0.05
        assert max(abs(t) for t in f.joints.torque) < TAU_MAX
    # The object where the description puts it, in the hand frame, as the tracker reports it.
    assert m.object_center is not None
    assert math.dist(m.object_center, spec.object_centre) < 1e-4
    assert abs(m.object_q[0]) > math.cos(math.radians(0.1) / 2)
    # The start joints put the tips exactly on the contacts (before settling).
    p.hand.reset(p.start_q)
    for k in range(3):
        n = np.asarray(cfg.start_normals[k]) / np.linalg.norm(cfg.start_normals[k])
        assert np.linalg.norm(p.hand.tip_position(k) - np.asarray(spec.object_centre) - reach * n) < 1e-10


def test_the_plants_own_hold_keeps_the_ball_still() -> None:
    """Until the daemon commands, balanced contact forces (the weight's share included) hold the ball."""
    p = plant()
    run(p, p.initial_setpoint(), 1.0)
    r = p.report()
    assert r["max_object_drift_m"] < 1e-4
    assert all(r["final_contact"]) and sum(r["clip_count"]) == 0


def test_the_daemons_feed_forward_holds_the_start_grasp_under_gravity() -> None:
    """The daemon's feed-forward (normal grips of 1 N, links' weight) and its PD hold the ball; the grips
    are not balanced (the normals do not cancel) and carry no share of the weight, so the PD takes the
    rest up: the ball settles about a millimetre lower."""
    grip = 1.0
    p = plant()
    sp = with_joints(
        p.initial_setpoint(),
        torque=daemon_feed_forward(p, grip),
        kp=(9.0,) * 9,
        kd=(0.01,) * 9,
    )
    run(p, sp, 1.0)
    r = p.report()
    print(
        f"\ngrip {grip} N: drift {1e3 * r['max_object_drift_m']:.3f} mm, peak |tau| {max(r['peak_torque_Nm']):.3f}, "
        f"clips {sum(r['clip_count'])}, normal forces {[round(f, 3) for f in r['final_normal_force_N']]}"
    )
    assert r["max_object_drift_m"] < 0.002
    assert all(r["final_contact"])
    assert sum(r["clip_count"]) == 0 and sum(r["limit_count"]) == 0
    assert r["link_contact_steps"] == 0 and r["floor_contact_steps"] == 0


def test_without_the_links_weight_the_fingers_sag_and_the_ball_falls() -> None:
    """The same command less g(q): the PD alone does not hold fingers and ball (gravity is on)."""
    p = plant()
    g = p.hand.gravity_torque(p.start_q)
    tau = np.array(daemon_feed_forward(p, 0.5)) - g
    run(p, with_joints(p.initial_setpoint(), torque=tuple(float(x) for x in tau)), 1.0)
    assert p.report()["max_object_drift_m"] > 0.002


def test_the_velocity_term_is_kd_times_the_velocity_error() -> None:
    """At rest, kp = 0: the motor torque is torque + kd·velocity (then the safety damping, zero at rest)."""
    p = plant()
    sp = p.initial_setpoint()
    assert sp.fingers[0].joints is not None
    tau0 = sp.fingers[0].joints.torque
    finger0 = replace(sp.fingers[0].joints, kp=(0.0,) * 3, kd=(0.01,) * 3, velocity=(5.0, -5.0, 2.0))
    one = replace(sp, fingers=(replace(sp.fingers[0], joints=finger0), *sp.fingers[1:]))
    dq = p.measure().fingers[0].joints
    assert dq is not None and dq.velocity is not None
    p.apply(one)
    p.step(p.period)
    applied = p.measure().fingers[0].joints
    assert applied is not None and applied.torque is not None
    for i, v in enumerate((5.0, -5.0, 2.0)):
        want = tau0[i] + 0.01 * (v - dq.velocity[i]) - (0.09, 0.09, 0.05)[i] * dq.velocity[i]
        assert applied.torque[i] == pytest.approx(want, abs=1e-12)


def test_clips_and_soft_limit_push_backs_are_counted() -> None:
    p = plant()
    sp = p.initial_setpoint()
    # Finger 0's upper joint: a feed-forward beyond the motor's limit, pushing towards its lower limit.
    torque = [j for f in sp.fingers for j in (f.joints.torque if f.joints else ())]
    torque[0] = -1.0
    run(p, with_joints(sp, torque=tuple(torque), kp=(0.0,) + (9.0,) * 8), 0.5)
    r = p.report()
    assert r["clip_count"][0] > 0 and sum(r["clip_count"][1:]) == 0
    assert r["peak_torque_Nm"][0] == pytest.approx(TAU_MAX, abs=1e-12)
    assert r["feedforward_at_limit"][0] == 500  # every step's command asked for more than the motor has
    assert r["limit_count"][0] > 0  # it went beyond −0.33 rad and was pushed back
    q = p.measure().fingers[0].joints
    assert q is not None
    assert q.position[0] > p.hand.lower[0] - 0.1


def test_fingertip_commands_are_refused() -> None:
    p = plant()
    sp = p.initial_setpoint()
    assert p.check(sp) is not None  # no JOINTS flag: the daemon runs another hand
    fingers = tuple(replace(f, joints=None) for f in sp.fingers)
    assert "joints" in (p.check(replace(sp, fingers=fingers, flags=sp.flags | 8)) or "")
    assert p.check(replace(sp, flags=sp.flags | 8)) is None


def test_the_tracker_reports_the_ball_late_and_noisy() -> None:
    p = plant(TrackerSettings(rate=30.0, latency=0.01, position_noise=0.001, angle_noise=math.radians(1.0)))
    run(p, p.initial_setpoint(), 0.5)
    t = p.report()["tracker"]
    assert t["samples"] == 16  # t = 0, 1/30, …, 15/30
    assert 0.0002 < t["max_offset_m"] < 0.005
    assert 0.2 < t["max_angle_deg"] < 5.0


def test_a_finger_off_the_ball_reports_no_contact_and_no_force() -> None:
    """Finger 0 commanded 5 mm out along its normal, without grip: its contact and force go to zero."""
    from gaitd.plants.trifinger_grasp import _solve, contact_targets

    p = plant()
    cfg = p.config.hand
    assert cfg is not None
    n = np.asarray(cfg.start_normals[0]) / np.linalg.norm(cfg.start_normals[0])
    target = contact_targets(p.hand, cfg.start_normals)[0] + 0.005 * n
    saved = (np.array(p.data.qpos), np.array(p.data.qvel))
    out = _solve(p.hand, 0, target, p.start_q.copy(), p.start_q[0:3])
    assert out is not None
    g = p.hand.gravity_torque(np.concatenate([out, p.start_q[3:]]))
    p.data.qpos[:], p.data.qvel[:] = saved
    import mujoco

    mujoco.mj_forward(p.model, p.data)
    sp = p.initial_setpoint()
    assert sp.fingers[0].joints is not None
    lifted = replace(
        sp.fingers[0].joints, position=tuple(out.tolist()), torque=tuple(g[0:3].tolist()), velocity=(0.0,) * 3
    )
    run(p, replace(sp, fingers=(replace(sp.fingers[0], joints=lifted), *sp.fingers[1:])), 0.3)
    m = p.measure()
    assert not m.fingers[0].contact and m.fingers[0].normal_force == 0.0
    assert m.fingers[1].contact and m.fingers[2].contact
    assert p.tip_gaps()[0] > 0.003


def test_the_object_pose_is_the_trackers_not_the_simulators() -> None:
    p = plant(TrackerSettings(rate=30.0, latency=0.01, position_noise=0.001, angle_noise=math.radians(1.0)))
    run(p, p.initial_setpoint(), 0.1)
    m = p.measure()
    true_c, true_q = p.true_pose()
    seen = p.tracker.reported
    assert m.object_q == seen.orientation and m.object_center == seen.centre
    assert p.tracker.reported.t <= p.time - 0.01  # at least the latency old
    # The measurement says how old the sample is: the latency at least, less than latency + 1/rate.
    assert m.object_age == pytest.approx(p.time - seen.t)
    assert 0.01 - 1e-9 <= m.object_age < 0.01 + 1.0 / 30.0 + 1e-9
    assert math.degrees(2.0 * math.acos(min(1.0, abs(sum(a * b for a, b in zip(m.object_q, true_q)))))) > 0.01
    assert m.object_center is not None and math.dist(m.object_center, true_c) > 1e-5


def test_the_plants_float_action_law_is_the_array_law() -> None:
    """``action_law_floats`` (the plant's per-step path) gives what ``action_law`` gives: random actions
    and states, joints inside and beyond their soft limits, NaN positions and gains, commands beyond the clip."""
    from gaitd.plants.trifinger_hand import Action, action_law, action_law_floats

    p = plant()
    h = p.hand
    consts = (h.lower, h.upper, h.tau_max, h.default_kp, h.default_kd, h.safety_kd)
    rng = np.random.default_rng(3)
    for _ in range(2000):
        a = Action(
            rng.normal(0.0, 0.4, 9),
            np.where(rng.random(9) < 0.2, np.nan, rng.normal(0.3, 1.5, 9)),
            np.where(rng.random(9) < 0.2, np.nan, rng.uniform(0.0, 20.0, 9)),
            np.where(rng.random(9) < 0.2, np.nan, rng.uniform(0.0, 0.1, 9)),
        )
        q, dq = rng.normal(0.0, 1.5, 9), rng.normal(0.0, 3.0, 9)
        want = action_law(a, q, dq, *consts)
        got = action_law_floats(
            (a.torque.tolist(), a.position.tolist(), a.kp.tolist(), a.kd.tolist()),
            q.tolist(),
            dq.tolist(),
            *(c.tolist() for c in consts),
        )
        assert got[0] == pytest.approx(want.torque.tolist(), abs=1e-15)
        assert got[1] == want.clipped.tolist() and got[2] == want.limited.tolist()

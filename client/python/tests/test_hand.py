"""The paper's start grasp (``gaitd.hand``): where every fingertip is and how it is turned."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from gaitd import config, hand, quat
from gaitd.schema import CommandFlags, PlantFingerMode
from gaitd.setpoint import Setpoint, Vec


@pytest.mark.parametrize("azimuths", [(0.0, 120.0, 240.0), (10.0, 100.0, 250.0)])
def test_paper_start(azimuths: tuple[float, float, float]) -> None:
    model = config.Model(object_radius=0.05, fingertip_radius=0.01, finger_azimuth_deg=azimuths)
    sp = hand.paper_start(model, grips=(1.0, 2.0, 3.0))
    assert sp.flags == int(CommandFlags.ENABLE)
    assert len(sp.fingers) == 3
    for f, azimuth, grip in zip(sp.fingers, azimuths, (1.0, 2.0, 3.0)):
        d = (math.cos(math.radians(azimuth)), math.sin(math.radians(azimuth)), 0.0)
        assert f.position == pytest.approx(tuple(0.06 * c for c in d), abs=1e-15)
        assert quat.norm(f.orientation) == pytest.approx(1.0)
        # The pole (fingertip z) points at the object centre; the fingertip x is the hand's z.
        assert quat.rotate(f.orientation, (0.0, 0.0, 1.0)) == pytest.approx(tuple(-c for c in d), abs=1e-12)
        assert quat.rotate(f.orientation, (1.0, 0.0, 0.0)) == pytest.approx((0.0, 0.0, 1.0), abs=1e-12)
        assert f.mode == PlantFingerMode.Grasping
        assert f.grip_force == grip
        assert f.roll == 0.0
        assert f.velocity == f.angular_velocity == f.acceleration == (0.0, 0.0, 0.0)
    assert sp.object_q == quat.IDENTITY


def test_holding_grip_carries_twice_the_weight_within_the_bounds() -> None:
    model = config.Model()  # μ = tan 20°
    weight = 0.1 * 9.81
    want = 2.0 * weight / (3.0 * model.mu)
    assert hand.holding_grip(model, 0.1, (0.0, 0.0, -9.81), 0.1, 20.0) == pytest.approx(want)
    assert hand.holding_grip(model, 0.1, (0.0, -9.81, 0.0), 0.1, 20.0) == pytest.approx(want)  # any direction
    assert hand.holding_grip(model, 0.1, (0.0, 0.0, 0.0), 1.0, 20.0) == 1.0  # at least min_grip
    assert hand.holding_grip(model, 100.0, (0.0, 0.0, -9.81), 1.0, 20.0) == 20.0  # at most max_grip


def _moving(sp: Setpoint, k: int, velocity: Vec, omega: Vec, mode: PlantFingerMode | None = None) -> Setpoint:
    """``sp`` with finger k moving at ``velocity`` and turning at ``omega`` (and in ``mode``)."""
    fingers = list(sp.fingers)
    f = fingers[k]
    fingers[k] = replace(f, velocity=velocity, angular_velocity=omega, mode=mode or f.mode)
    return replace(sp, fingers=tuple(fingers))


def _cross(a: Vec, b: Vec) -> Vec:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@pytest.mark.parametrize("free", [None, 0, 1, 2])
def test_grasping_fingertips_that_move_with_the_object_turn_it(free: int | None) -> None:
    model = config.Model()
    w: Vec = (0.3, -0.7, 1.1)
    sp = hand.paper_start(model)
    for k, f in enumerate(sp.fingers):
        mode = PlantFingerMode.Free if k == free else None
        sp = _moving(sp, k, _cross(w, f.position), w, mode)
    # Two fingers: the turn about the chord through them comes from their own (no spin).
    assert hand.object_rate(model, sp) == pytest.approx(w, abs=1e-12)


def test_a_fingertip_rolling_or_spinning_on_the_object_leaves_it_still() -> None:
    model = config.Model()
    big_r, r = model.object_radius, model.fingertip_radius
    sp = hand.paper_start(model)
    # Finger 0 rolls about the hand's z at contact rate 0.4 rad/s: centre on the
    # circle of radius R + r, turning (R + r) / r times as fast; finger 1 spins
    # about its contact normal (three fingers grasp: hard contacts may spin).
    roll = _moving(sp, 0, _cross((0.0, 0.0, 0.4), sp.fingers[0].position), (0.0, 0.0, 0.4 * (big_r + r) / r))
    n1 = tuple(c / (big_r + r) for c in sp.fingers[1].position)
    both = _moving(roll, 1, (0.0, 0.0, 0.0), (0.9 * n1[0], 0.9 * n1[1], 0.9 * n1[2]))
    assert hand.object_rate(model, both) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)


def test_fewer_than_two_grasping_fingertips_turn_nothing() -> None:
    model = config.Model()
    sp = hand.paper_start(model)
    for k in (0, 1):
        sp = _moving(sp, k, (0.1, 0.0, 0.0), (0.0, 0.0, 1.0), PlantFingerMode.Free)
    assert hand.object_rate(model, sp) == (0.0, 0.0, 0.0)

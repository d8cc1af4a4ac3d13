"""The paper's start grasp (``gaitd.hand``): where every fingertip is and how it is turned."""

from __future__ import annotations

import math

import pytest

from gaitd import config, hand, quat
from gaitd.schema import CommandFlags, PlantFingerMode


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

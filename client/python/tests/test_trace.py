"""``gait-trajectory/1`` traces as setpoints (``gaitd.trace``): reading, the finger modes derived
from contacts and phases, backward-difference velocities."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import pytest

from gaitd import quat, trace
from gaitd.schema import CommandFlags, PlantFingerMode

G, L, P, F = PlantFingerMode.Grasping, PlantFingerMode.Lifting, PlantFingerMode.Placing, PlantFingerMode.Free
DT = 0.001
#: Finger 0 lets go in the lift phase and comes back in the place phase; finger 1 always grasps;
#: finger 2 is free throughout, a place phase included (it never touches: not Placing).
PHASES = ["hold", "hold", "lift", "lift", "place", "place", "hold"]
CONTACT_0 = [True, True, False, False, False, True, True]
SPIN = 10.0  # object angular velocity about z [rad/s]


def sample(k: int) -> dict[str, Any]:
    x = 0.6 + 0.001 * k  # finger 0 moves at 1 m/s along x from k = 0
    q = quat.from_axis_angle((0.0, 0.0, 1.0), SPIN * DT * k)
    return {
        "t": k * DT,
        "phase": PHASES[k],
        "object_q": list(q),
        "fingers": [
            {"p": [x, 0.0, 0.0], "q": [1.0, 0.0, 0.0, 0.0], "contact": CONTACT_0[k], "grip_force": 2.0, "roll": 0.5},
            {"p": [0.0, 0.6, 0.0], "q": [1.0, 0.0, 0.0, 0.0], "contact": True, "grip_force": 3.0},
            {"p": [0.0, -0.6, 0.1], "q": [1.0, 0.0, 0.0, 0.0], "contact": False, "grip_force": 4.0},
        ],
    }


@pytest.fixture
def path(tmp_path: Path) -> Path:
    p = tmp_path / "plan.jsonl"
    lines = [json.dumps({"format": "gait-trajectory/1", "dt": DT})]
    lines += [json.dumps(sample(k)) for k in range(len(PHASES))]
    p.write_text("\n".join(lines) + "\n\n", encoding="utf-8")
    return p


def test_read(path: Path) -> None:
    t = trace.read(path)
    assert t.dt == DT
    assert len(t.samples) == len(PHASES)
    assert t.samples[2]["phase"] == "lift"


def test_read_refuses_other_formats(tmp_path: Path) -> None:
    other = tmp_path / "other.jsonl"
    other.write_text(json.dumps({"format": "gait-trajectory/2", "dt": DT}) + "\n", encoding="utf-8")
    with pytest.raises(ValueError, match="not a gait-trajectory/1 trace"):
        trace.read(other)
    empty = tmp_path / "empty.jsonl"
    empty.write_text("\n", encoding="utf-8")
    with pytest.raises(ValueError, match="not a gait-trajectory/1 trace"):
        trace.read(empty)


def test_finger_modes(path: Path) -> None:
    modes = trace.finger_modes(trace.read(path))
    assert [m[0] for m in modes] == [G, G, L, L, P, G, G]
    assert [m[1] for m in modes] == [G] * len(PHASES)
    assert [m[2] for m in modes] == [F] * len(PHASES)


def test_setpoints_velocities_are_backward_differences(path: Path) -> None:
    sps = trace.setpoints(trace.read(path))
    assert len(sps) == len(PHASES)
    assert all(sp.flags == int(CommandFlags.ENABLE | CommandFlags.LOCKSTEP) for sp in sps)
    f0 = [sp.fingers[0] for sp in sps]
    assert f0[0].velocity == (0.0, 0.0, 0.0)  # the first sample has no predecessor
    for f in f0[1:]:
        assert f.velocity == pytest.approx((1.0, 0.0, 0.0))
    assert f0[1].acceleration == pytest.approx((1.0 / DT, 0.0, 0.0))
    for f in f0[2:]:
        assert f.acceleration == pytest.approx((0.0, 0.0, 0.0), abs=1e-6)
    for sp in sps[1:]:
        assert sp.object_omega == pytest.approx((0.0, 0.0, SPIN))
        assert quat.norm(sp.object_q) == pytest.approx(1.0)
    assert sps[0].object_omega == (0.0, 0.0, 0.0)
    assert sps[3].object_q == pytest.approx(quat.from_axis_angle((0.0, 0.0, 1.0), 3 * SPIN * DT))


def test_setpoints_grip_only_in_contact_and_roll_default(path: Path) -> None:
    sps = trace.setpoints(trace.read(path), lockstep=False)
    assert all(sp.flags == int(CommandFlags.ENABLE) for sp in sps)
    assert [sp.fingers[0].grip_force for sp in sps] == [2.0, 2.0, 0.0, 0.0, 0.0, 2.0, 2.0]
    assert all(sp.fingers[2].grip_force == 0.0 for sp in sps)
    assert sps[0].fingers[0].roll == 0.5
    assert sps[0].fingers[1].roll == 0.0
    assert sps[4].fingers[0].mode == P
    assert all(math.isfinite(c) for sp in sps for f in sp.fingers for c in f.angular_velocity)

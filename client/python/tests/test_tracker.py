"""The tracker model (``gaitd.plants.tracker``): its rate, its latency and its noise, measured on a moving object."""

from __future__ import annotations

import math

import pytest

from gaitd import quat
from gaitd.plants.tracker import Tracker, TrackerSettings

DT = 0.001


def moving(t: float) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """A pose that moves every step: the centre along x at 1 m/s, turning about z at 1 rad/s."""
    return (t, 0.0, 0.08), quat.from_axis_angle((0.0, 0.0, 1.0), t)


def run(settings: TrackerSettings, seconds: float) -> list[tuple[float, float, float]]:
    """Per step: (time, the reported centre's x, the reported angle about z)."""
    c0, q0 = moving(0.0)
    tr = Tracker(settings, c0, q0)
    out = []
    for k in range(round(seconds / DT) + 1):
        t = k * DT
        c, q = moving(t)
        seen = tr.observe(t, c, q)
        out.append((t, seen.centre[0], 2.0 * math.atan2(seen.orientation[3], seen.orientation[0])))
    return out


def test_the_exact_tracker_reports_the_true_pose_every_step() -> None:
    for t, x, a in run(TrackerSettings.exact(), 0.1):
        assert x == pytest.approx(t, abs=1e-15)
        assert a == pytest.approx(t, abs=1e-12)


def test_samples_come_at_the_rate_and_arrive_after_the_latency() -> None:
    s = TrackerSettings(rate=30.0, latency=0.010, position_noise=0.0, angle_noise=0.0)
    rows = run(s, 1.0)
    # The reported pose is the one sampled at the newest instant k/30 that is at least 10 ms old.
    for t, x, a in rows:
        k = math.floor((t - s.latency) * s.rate + 1e-9)
        if k < 0:
            assert x == 0.0  # the start pose until the first sample arrives (at 10 ms)
            continue
        sampled = math.ceil(k / s.rate / DT - 1e-9) * DT  # taken at the first step at or after k/30
        assert x == pytest.approx(sampled, abs=1e-12), t
        assert a == pytest.approx(sampled, abs=1e-12), t
    ages = [t - x for t, x, _ in rows if t >= s.latency]
    assert min(ages) == pytest.approx(s.latency, abs=1e-12)
    assert max(ages) == pytest.approx(s.latency + 1.0 / s.rate, abs=DT + 1e-12)
    # One new pose per sample: 30 in a second (the first, taken at t = 0, is the start pose).
    assert len({x for _, x, _ in rows}) == 30


def test_noise_has_the_set_rms_and_is_seeded() -> None:
    s = TrackerSettings(rate=0.0, latency=0.0, position_noise=0.001, angle_noise=math.radians(1.0), seed=7)
    c, q = (0.0, 0.0, 0.08), quat.IDENTITY
    tr = Tracker(s, c, q)
    offsets, angles = [], []
    for k in range(20000):
        seen = tr.observe(k * DT, c, q)
        offsets.append(math.dist(seen.centre, c))
        angles.append(quat.angle_between(seen.orientation, q))
    rms = math.sqrt(sum(o * o for o in offsets) / len(offsets))
    rms_angle = math.sqrt(sum(a * a for a in angles) / len(angles))
    assert rms == pytest.approx(0.001, rel=0.03)
    assert rms_angle == pytest.approx(math.radians(1.0), rel=0.03)
    again = Tracker(s, c, q)
    first = [again.observe(k * DT, c, q).centre for k in range(5)]
    tr2 = Tracker(s, c, q)
    assert first == [tr2.observe(k * DT, c, q).centre for k in range(5)]


def test_negative_settings_are_refused() -> None:
    with pytest.raises(ValueError):
        TrackerSettings(latency=-0.01)

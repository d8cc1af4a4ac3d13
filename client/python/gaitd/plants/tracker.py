"""The object's pose as a tracking system gives it: sampled at a rate, delivered late, with noise.

A camera tracker (the TriFinger platform's is a set of cameras and an
object-pose estimator) does not see the object every millisecond: it takes a
picture every 1/rate seconds, its estimate is ready ``latency`` seconds
later, and it is off by a few millimetres and degrees. :class:`Tracker`
models exactly that, on the simulator's true pose:

* **rate**: a sample of the true pose at t = 0, 1/rate, 2/rate, … (taken at
  the first step at or after each instant);
* **latency**: each sample becomes the reported pose ``latency`` seconds
  after it was taken; until the next one arrives the last stays reported
  (zero-order hold), so the reported pose is between ``latency`` and
  ``latency + 1/rate`` old;
* **noise**: each sample's centre is off by a Gaussian vector whose RMS
  length is ``position_noise`` [m] (``position_noise/√3`` per axis), its
  orientation by a rotation exp(ξ) ⊗ q whose rotation vector ξ is Gaussian
  with RMS angle ``angle_noise`` [rad]; independent from sample to sample,
  from a seeded generator, so that a lockstep run replays bit for bit.

``TrackerSettings()`` (its defaults) is a realistic camera tracker: 30 Hz,
10 ms, 1 mm and 1° RMS. ``TrackerSettings.exact()`` is the simulator's
truth every step (rate 0 = every call, no latency, no noise).
"""

from __future__ import annotations

import math
import random
from collections import deque
from dataclasses import dataclass

from .. import quat
from ..quat import Quat, Vec


@dataclass(frozen=True)
class TrackerSettings:
    """Rate [Hz] (0: every step), latency [s], RMS position [m] and angle [rad] noise, seed."""

    rate: float = 30.0
    latency: float = 0.010
    position_noise: float = 0.001
    angle_noise: float = math.radians(1.0)
    seed: int = 1

    @staticmethod
    def exact() -> TrackerSettings:
        """The simulator's true pose, every step."""
        return TrackerSettings(rate=0.0, latency=0.0, position_noise=0.0, angle_noise=0.0)

    def __post_init__(self) -> None:
        if not (self.rate >= 0.0 and self.latency >= 0.0 and self.position_noise >= 0.0 and self.angle_noise >= 0.0):
            raise ValueError(f"tracker settings must be ≥ 0: {self}")


@dataclass(frozen=True)
class Pose:
    """A tracked pose: the centre [m] and orientation (w, x, y, z), and when it was sampled [s]."""

    t: float
    centre: Vec
    orientation: Quat


class Tracker:
    """The tracking system's view of one object (module docs)."""

    def __init__(self, settings: TrackerSettings, centre: Vec, orientation: Quat):
        self.settings = settings
        self._rng = random.Random(settings.seed)
        self._pending: deque[tuple[float, Pose]] = deque()
        self._next = 0.0
        # Before its first sample arrives it reports the pose it was started on (a still object).
        self.reported = Pose(-math.inf, centre, orientation)
        self.samples = 0

    def _noisy(self, t: float, centre: Vec, orientation: Quat) -> Pose:
        s = self.settings
        sp, sa = s.position_noise / math.sqrt(3.0), s.angle_noise / math.sqrt(3.0)
        g = self._rng.gauss
        c = (centre[0] + g(0.0, sp), centre[1] + g(0.0, sp), centre[2] + g(0.0, sp)) if sp > 0 else centre
        if sa > 0:
            xi = (g(0.0, sa), g(0.0, sa), g(0.0, sa))
            orientation = quat.normalize(quat.mul(quat.from_rotvec(xi), orientation))
        return Pose(t, c, orientation)

    def observe(self, t: float, centre: Vec, orientation: Quat) -> Pose:
        """Given the true pose at time ``t`` [s] (non-decreasing from call to call): the pose reported then."""
        s = self.settings
        if s.rate <= 0.0 or t >= self._next - 1e-12:
            self._pending.append((t + s.latency, self._noisy(t, centre, orientation)))
            self.samples += 1
            if s.rate > 0.0:
                # The next instant on the tracker's own grid (never two samples for one call).
                self._next = (math.floor(t * s.rate + 1e-9) + 1) / s.rate
        while self._pending and self._pending[0][0] <= t + 1e-12:
            self.reported = self._pending.popleft()[1]
        return self.reported

#!/usr/bin/env python3
"""A complete gaitd plant: an exact kinematic hand.

The fingertips are exactly where they are commanded; the object turns only
as the grasping fingertips roll it (it never copies the commanded one, which
would hide every tracking error). Run it against a daemon with ``[plant] kind = "shm"``:

    python kinematic_hand.py --config gaitd.toml [--timing lockstep|realtime]
"""

import argparse
import math

from gaitd import config, hand, quat
from gaitd.plant import Plant
from gaitd.setpoint import FingerMeasured, Measured


class KinematicHand(Plant):
    simulated = True  # no hardware: the plant's clock is simulated time
    object_q = quat.IDENTITY  # where the start grasp holds the object

    def initial_setpoint(self):
        return hand.paper_start(self.config.model, grips=(1.0, 1.0, 1.0))

    def apply(self, setpoint):
        self.setpoint = setpoint

    def step(self, dt):
        w = hand.object_rate(self.config.model, self.setpoint)  # rolling without slipping
        self.object_q = quat.normalize(quat.mul(quat.from_rotvec([c * dt for c in w]), self.object_q))

    def measure(self):
        m = self.config.model
        surface = m.object_radius + m.fingertip_radius

        def tip(f):
            touching = abs(math.dist(f.position, (0, 0, 0)) - surface) <= m.contact_tolerance
            return FingerMeasured(f.position, f.orientation, touching, f.roll, normal_force=f.grip_force)

        return Measured(self.object_q, tuple(tip(f) for f in self.setpoint.fingers))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", required=True, help="the daemon's gaitd.toml")
    ap.add_argument("--timing", choices=["lockstep", "realtime"], help="default: [plant] timing")
    a = ap.parse_args()
    KinematicHand(config.load(a.config), timing=a.timing).run()

#!/usr/bin/env python3
"""A complete gaitd plant: an exact kinematic hand.

The fingertips are exactly where they are commanded, and the object turns
with the grasp: while at least two fingers grasp it, it takes the commanded
orientation. Run it against a daemon with ``[plant] kind = "shm"``:

    python kinematic_hand.py --config gaitd.toml [--timing lockstep|realtime]
"""

import argparse
import math

from gaitd import config, hand
from gaitd.plant import Plant
from gaitd.schema import PlantFingerMode
from gaitd.setpoint import FingerMeasured, Measured


class KinematicHand(Plant):
    simulated = True  # no hardware: the plant's clock is simulated time

    def initial_setpoint(self):
        return hand.paper_start(self.config.model, grips=(1.0, 1.0, 1.0))

    def apply(self, setpoint):
        self.setpoint = setpoint
        grasping = sum(f.mode == PlantFingerMode.Grasping for f in setpoint.fingers)
        if grasping >= 2 or not hasattr(self, "object_q"):
            self.object_q = setpoint.object_q

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

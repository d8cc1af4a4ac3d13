"""``python -m gaitd.plants.mujoco --config gaitd.toml``: the MuJoCo hand as gaitd's plant.

Builds the scene from the daemon's configuration file (the same file the
daemon reads: ``[model]``, ``[load]``, ``[control]``, ``[ipc]``, ``[plant]``),
starts in the paper start grasp, attaches to the daemon's plant services and
runs until SIGTERM/SIGINT. Where the file's ``[hand]`` is a chain hand
(``kind = "chains"``) the plant is that hand at the joint level
(``trifinger_plant``: the description's scene, the configured start grasp,
the object's pose through a tracker model whose rate, latency and noise the
``--tracker-*`` options set). Progress and the real-time factor (simulated
seconds per wall second) go to stderr every 10 s and at the end;
``--report FILE`` writes what happened as JSON at exit (for tests and
scripts: final object orientation and centre, largest object-centre drift,
sessions seen, counters; on a chain hand the simulator's truth — the ball's
true pose, the action law's clip and soft-limit counts, the largest applied
torques, the tracker's errors).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from .. import config as gaitd_config
from ..ipc import IpcError
from ..plant import LOCKSTEP, REALTIME
from ..setpoint import Measured
from .mujoco_plant import MujocoPlant
from .tracker import TrackerSettings
from .trifinger_main import run_chains


class ReportingPlant(MujocoPlant):
    """The MuJoCo plant, remembering what a report needs as it runs."""

    def __init__(self, *a: Any, **kw: Any) -> None:
        super().__init__(*a, **kw)
        self.max_drift = 0.0

    def measure(self) -> Measured:
        m = super().measure()
        c = m.object_center
        if c is not None:
            self.max_drift = max(self.max_drift, math.sqrt(sum(x * x for x in c)))
        return m


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m gaitd.plants.mujoco", description=__doc__.splitlines()[0])
    ap.add_argument("--config", required=True, help="the daemon's gaitd.toml")
    ap.add_argument("--timing", choices=[LOCKSTEP, REALTIME], help="default: [plant] timing of the config")
    ap.add_argument(
        "--lockstep-timeout",
        type=float,
        default=None,
        help="wall-clock wait for the daemon's answer [s] (default: [plant] lockstep_timeout_ms)",
    )
    ap.add_argument(
        "--open-timeout", type=float, default=60.0, help="how long to wait for the daemon's plant services [s]"
    )
    ap.add_argument(
        "--initial-grip",
        type=float,
        default=None,
        help="grip per finger until the first command [N] (default: twice what holds the weight)",
    )
    ap.add_argument("--max-steps", type=int, default=None, help="stop after this many steps")
    ap.add_argument("--report", default=None, help="write a JSON report here at exit")
    chains = ap.add_argument_group('a chain hand ([hand] kind = "chains")')
    d = TrackerSettings()
    chains.add_argument(
        "--tracker-rate", type=float, default=d.rate, help="object pose samples per second (0: every step)"
    )
    chains.add_argument("--tracker-latency", type=float, default=d.latency, help="a sample's delay [s]")
    chains.add_argument(
        "--tracker-position-noise", type=float, default=d.position_noise, help="RMS error of the centre [m]"
    )
    chains.add_argument(
        "--tracker-angle-noise-deg", type=float, default=math.degrees(d.angle_noise), help="RMS orientation error [°]"
    )
    chains.add_argument("--tracker-seed", type=int, default=d.seed, help="the noise's seed")
    chains.add_argument("--exact-tracker", action="store_true", help="the simulator's true pose every step")
    chains.add_argument("--substeps", type=int, default=1, help="physics steps per control period")
    a = ap.parse_args(argv)

    cfg = gaitd_config.load(a.config)
    if cfg.chains:
        tracker = (
            TrackerSettings.exact()
            if a.exact_tracker
            else TrackerSettings(
                a.tracker_rate,
                a.tracker_latency,
                a.tracker_position_noise,
                math.radians(a.tracker_angle_noise_deg),
                a.tracker_seed,
            )
        )
        return run_chains(cfg, a, tracker)
    plant = ReportingPlant(
        cfg,
        timing=a.timing,
        lockstep_timeout=a.lockstep_timeout,
        open_timeout=a.open_timeout,
        initial_grip=a.initial_grip,
        node_name="gaitd-mujoco-plant",
    )
    p = plant.params
    print(
        f"plant: MuJoCo {plant_version()} scene R={p.object_radius} r={p.fingertip_radius} mu={p.mu:.4f} "
        f"torsion={p.torsion:.5f} m mass={p.object_mass} kg gravity={list(p.gravity)} timestep={p.timestep} s "
        f"({plant.substeps} per period), contact stiffness {plant.contact_stiffness:.4g} N/m",
        file=sys.stderr,
        flush=True,
    )
    try:
        stats = plant.run(max_steps=a.max_steps)
    except IpcError as e:
        print(f"plant: {e}", file=sys.stderr)
        return 2
    m = plant.measure()
    if a.report:
        report = {
            "timing": plant.timing,
            **stats.summary(),
            "final_object_q": list(m.object_q),
            "final_object_center": list(m.object_center) if m.object_center is not None else None,
            "max_object_drift_m": plant.max_drift,
            "final_normal_force": [f.normal_force for f in m.fingers],
            "final_contact": [f.contact for f in m.fingers],
            "diverged": plant.diverged,
        }
        with open(a.report, "w", encoding="utf-8") as fh:
            json.dump(report, fh, indent=1)
    return 3 if plant.diverged else 0


def plant_version() -> str:
    """The MuJoCo version simulated."""
    import mujoco

    return str(mujoco.__version__)


if __name__ == "__main__":
    sys.exit(main())

"""``python -m gaitd.plants.mujoco`` on a chain hand: runs :class:`~.trifinger_plant.TriFingerPlant`.

Prints the scene and the tracker on stderr, runs the plant until
SIGTERM/SIGINT (or ``--max-steps``), prints the real-time factor and the
simulator's truth in one line, and with ``--report FILE`` writes the run's
counters with the plant's truth (``TriFingerPlant.report``) as JSON.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

import mujoco

from ..config import DaemonConfig
from ..ipc import IpcError
from .tracker import TrackerSettings
from .trifinger_plant import TriFingerPlant


def run_chains(cfg: DaemonConfig, a: argparse.Namespace, tracker: TrackerSettings) -> int:
    """Runs the chain hand's plant with the parsed options ``a``; the exit status."""
    if a.initial_grip is not None:
        print("plant: --initial-grip is for free fingertips; a chain hand starts in its holding grasp", file=sys.stderr)
        return 2
    plant = TriFingerPlant(
        cfg,
        tracker=tracker,
        substeps=a.substeps,
        timing=a.timing,
        lockstep_timeout=a.lockstep_timeout,
        open_timeout=a.open_timeout,
        node_name="gaitd-mujoco-plant",
    )
    s = plant.spec
    t = plant.tracker.settings
    where = cfg.hand.description if cfg.hand else ""
    print(
        f"plant: MuJoCo {mujoco.__version__} TriFingerPro (joint level) from {where}: "
        f"ball R={s.object_radius} m, {s.object_mass} kg at {list(s.object_centre)}, mu={s.mu} torsion={s.torsion} m, "
        f"gravity={list(s.gravity)}, timestep={plant.hand.model.opt.timestep} s ({plant.substeps} per period); "
        f"start joints {[round(float(x), 4) for x in plant.start_q]}; tracker {t.rate:g} Hz, {1e3 * t.latency:g} ms, "
        f"{1e3 * t.position_noise:g} mm / {math.degrees(t.angle_noise):g}° RMS",
        file=sys.stderr,
        flush=True,
    )
    try:
        stats = plant.run(max_steps=a.max_steps)
    except IpcError as e:
        print(f"plant: {e}", file=sys.stderr)
        return 2
    r = plant.report()
    print(
        f"plant: real-time factor {stats.real_time_factor:.2f}; truth: largest centre drift "
        f"{1e3 * r['max_object_drift_m']:.2f} mm, clip acted {sum(r['clip_count'])} joint-steps, soft limits "
        f"{sum(r['limit_count'])}, peak |tau| {max(r['peak_torque_Nm']):.3f} N·m of {max(r['torque_limit_Nm']):.3f}, "
        f"feed-forward at the limit {sum(r['feedforward_at_limit'])} joint-commands, link contacts "
        f"{r['link_contact_steps']} steps, floor {r['floor_contact_steps']} steps",
        file=sys.stderr,
        flush=True,
    )
    if a.report:
        with open(a.report, "w", encoding="utf-8") as fh:
            json.dump({"timing": plant.timing, **stats.summary(), **r}, fh, indent=1)
    return 3 if plant.diverged else 0

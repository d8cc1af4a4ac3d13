#!/usr/bin/env python3
"""Drives the MuJoCo plant open loop with the setpoints of a ``gaitctl plan`` trace.

No daemon and no IPC: every trace sample becomes a setpoint, the plant
applies it and steps one period, and what it *measures* is compared with
the plan. Prints one JSON object (run by ``tests/tests/python_plant.rs``,
which asserts on it):

* ``orientation``: angle between the measured and the planned object
  orientation, max and final [deg];
* ``drift``: largest distance of the object centre from the origin [m];
* ``slip``: per finger and planned contact phase, the net slip of the
  contact point over the object surface — the relative tangential
  velocity of the two material points at the contact, from the measured
  object and fingertip states, integrated in the object frame (as the
  MuJoCo oracle measures it); ``max_net_m`` is the largest;
* ``contact``: time a finger planned in contact read as not touching (or
  the reverse), outside 50 ms around each planned make or break [s];
* ``rest_force``: the normal forces after holding the start grasp still
  for 0.2 s (the preload must make the contact carry exactly the grip);
* ``real_time_factor``: simulated seconds per wall second of the loop;
* ``feedback``: what gaitd's feedback checks would see open loop (largest
  fingertip tracking error, ticks a fingertip "stalled" by the
  ``stall_ratio`` rule, largest contact drift in the object frame), to size
  ``[feedback]`` for a physics plant.

Usage: mujoco_open_loop.py --trace T.jsonl --config gaitd.toml [--mutate NAME]
``--mutate`` breaks the plant on purpose (to watch the test fail):
``no-preload`` (press force = grip, not grip · (1 + k_s/K)), ``no-qvel``
(mount velocities not overwritten), ``frozen-tip`` (fingertip orientation
never follows the command).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

import numpy as np

from gaitd import config, quat, trace
from gaitd.plants import mujoco_plant
from gaitd.plants.mujoco_plant import MujocoPlant
from gaitd.schema import PlantFingerMode


def mutate(plant: MujocoPlant, name: str | None) -> None:
    """Breaks one thing the design relies on (NOTES.md), for the test's negative control."""
    if name is None:
        return
    if name == "no-preload":
        plant._preload = 1.0
        for fs in plant.fingers:  # undo the initial penetration's preload too
            plant.data.qfrc_applied[fs.qvel_press] = fs.engaged * fs.grip
    elif name == "no-qvel":
        original = plant._drive

        def drive(fs, p1, q1, h, rate):
            original(fs, p1, q1, h, rate)
            plant.data.qvel[fs.qvel_mount : fs.qvel_mount + 6] = 0.0
            plant.data.qvel[fs.qvel_ball : fs.qvel_ball + 3] = 0.0
            # the mount still lands on p1 only if qvel carries it: now it stays at p0

        plant._drive = drive
    elif name == "frozen-tip":
        original_apply = plant.apply

        def apply(sp):
            kept = [fs.target_orientation for fs in plant.fingers]
            original_apply(sp)
            for fs, q in zip(plant.fingers, kept):
                fs.target_orientation = q

        plant.apply = apply
    else:
        raise SystemExit(f"unknown mutation {name}")


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trace", required=True)
    ap.add_argument("--config", required=True)
    ap.add_argument("--mutate", default=None)
    ap.add_argument("--grace", type=float, default=0.05)
    a = ap.parse_args()

    cfg = config.load(a.config)
    tr = trace.read(a.trace)
    sps = trace.setpoints(tr, lockstep=False)
    if abs(tr.dt - cfg.period) > 1e-12:
        raise SystemExit(f"trace dt {tr.dt} != control period {cfg.period}")
    # At rest, the contact (not the press spring) must carry exactly the commanded grip.
    rest = MujocoPlant(cfg, initial=sps[0])
    mutate(rest, a.mutate)
    for _ in range(200):
        rest.apply(rest.initial_setpoint())
        rest.step(rest.period)
    rest_force = [f.normal_force for f in rest.measure().fingers]

    plant = MujocoPlant(cfg, initial=sps[0])
    mutate(plant, a.mutate)
    plant.apply(plant.initial_setpoint())
    h = plant.period
    n = len(sps)
    R = cfg.model.object_radius
    oq = np.empty((n, 4))
    ow = np.empty((n, 3))
    oc = np.empty((n, 3))
    fp = np.empty((n, 3, 3))
    fv = np.empty((n, 3, 3))
    fw = np.empty((n, 3, 3))
    fn = np.empty((n, 3))
    touching = np.empty((n, 3), bool)

    def record(k: int) -> None:
        m = plant.measure()
        oq[k], ow[k], oc[k] = m.object_q, m.object_omega, m.object_center
        for i, f in enumerate(m.fingers):
            fp[k, i], fv[k, i], fw[k, i] = f.position, f.velocity, f.angular_velocity
            fn[k, i], touching[k, i] = f.normal_force, f.contact

    record(0)
    t0 = time.perf_counter()
    for k in range(1, n):
        plant.apply(sps[k])
        plant.step(h)
        record(k)
        if plant.diverged:
            n = k + 1
            break
    wall = time.perf_counter() - t0
    oq, ow, oc, fp, fv, fw, fn, touching = (x[:n] for x in (oq, ow, oc, fp, fv, fw, fn, touching))

    planned_q = np.array([sp.object_q for sp in sps[:n]])
    ang = np.array([math.degrees(quat.angle_between(oq[k], planned_q[k])) for k in range(n)])
    drift = np.linalg.norm(oc[:n], axis=1)
    planned = np.array([[f.mode == PlantFingerMode.Grasping for f in sp.fingers] for sp in sps[:n]])

    # slip: relative tangential velocity of the material points at the contact (oracle's definition)
    ov = np.vstack([np.zeros((1, 3)), np.diff(oc[:n], axis=0) / h])
    rel = fp[:n] - oc[:n, None, :]
    dist = np.linalg.norm(rel, axis=-1)
    nrm = rel / dist[..., None]
    gap = dist - R - cfg.model.fingertip_radius
    c = oc[:n, None, :] + nrm * (R + 0.5 * gap)[..., None]
    vo_c = ov[:, None, :] + np.cross(ow[:n, None, :], c - oc[:n, None, :])
    vf_c = fv[:n] + np.cross(fw[:n], c - fp[:n])
    vrel = vo_c - vf_c
    vt = vrel - np.sum(vrel * nrm, -1, keepdims=True) * nrm
    vt_obj = np.stack([np.array([quat.rotate(quat.conj(oq[k]), vt[k, i]) for i in range(3)]) for k in range(n)])

    grace = int(round(a.grace / h))
    in_grace = np.zeros(planned.shape, bool)
    phases = []
    for i in range(3):
        flips = np.flatnonzero(planned[1:, i] != planned[:-1, i]) + 1
        for k in flips:
            in_grace[max(0, k - grace) : k + grace + 1, i] = True
        edges = np.flatnonzero(np.diff(np.concatenate([[0], planned[:, i].astype(int), [0]])))
        for s, e in zip(edges[::2], edges[1::2]):
            sel = np.zeros(n, bool)
            sel[s:e] = True
            sel &= touching[:, i]
            net = float(np.linalg.norm(vt_obj[sel, i].sum(axis=0)) * h)
            phases.append(
                {
                    "finger": i,
                    "t_start": float(s * h),
                    "t_end": float(e * h),
                    "net_slip_m": net,
                    "max_normal_force": float(fn[s:e, i].max()),
                }
            )
    missing = planned & ~touching & ~in_grace
    extra = ~planned & touching & ~in_grace

    # What gaitd's feedback check (gait/src/executor/feedback.rs) would see, to size [feedback]:
    # fingertip tracking error, stalled fingertips, contact drift in the object frame.
    cmd_p = np.array([[f.position for f in sp.fingers] for sp in sps[:n]])
    track = np.linalg.norm(fp - cmd_p, axis=-1)
    moved = np.linalg.norm(np.diff(fp, axis=0), axis=-1)
    commanded = np.linalg.norm(np.diff(cmd_p, axis=0), axis=-1)
    stalls = (commanded > 1e-6) & (moved < 0.1 * commanded)
    drift_c = np.zeros((n, 3))
    for k in range(n):
        for i in range(3):
            if planned[k, i]:
                a_ = quat.rotate(quat.conj(planned_q[k]), cmd_p[k, i] / np.linalg.norm(cmd_p[k, i]))
                b_ = quat.rotate(quat.conj(oq[k]), fp[k, i] / np.linalg.norm(fp[k, i]))
                drift_c[k, i] = R * math.dist(a_, b_)
    feedback = {
        "max_tip_tracking_m": float(track.max()),
        "stalled_ticks": stalls.sum(axis=0).tolist(),
        "max_contact_drift_m": float(drift_c.max()),
    }

    out = {
        "samples": n,
        "feedback": feedback,
        "simulated_s": (n - 1) * h,
        "wall_s": wall,
        "real_time_factor": (n - 1) * h / wall,
        "orientation": {
            "max_error_deg": float(ang.max()),
            "max_error_t": float(ang.argmax() * h),
            "final_error_deg": float(ang[-1]),
        },
        "drift": {"max_m": float(drift.max()), "final_m": float(drift[-1])},
        "slip": {"max_net_m": max(p["net_slip_m"] for p in phases), "phases": phases},
        "contact": {"missing_s": (missing.sum(axis=0) * h).tolist(), "unexpected_s": (extra.sum(axis=0) * h).tolist()},
        "rest_force": {"measured": rest_force, "planned": [f.grip_force for f in sps[0].fingers]},
        "roll_error_max": float(max(abs(plant.fingers[i].roll - sps[n - 1].fingers[i].roll) for i in range(3))),
        "diverged": plant.diverged,
        "contact_stiffness": plant.contact_stiffness,
        "mutation": a.mutate,
        "timestep": plant.params.timestep,
        "torsion": plant.params.torsion,
    }
    json.dump(out, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    _ = mujoco_plant  # the module under test
    sys.exit(main())

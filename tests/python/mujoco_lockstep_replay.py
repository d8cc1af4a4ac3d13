#!/usr/bin/env python3
"""The MuJoCo plant's command line, in lockstep over iceoryx2, replays a plan bit for bit.

A stand-in for the daemon's side (``plant_protocol.StandIn``: the four
plant services, created here) answers every measurement k of
``python -m gaitd.plants.mujoco --timing lockstep`` with the setpoint of
trace sample k, as gaitd would in lockstep. The same setpoints are also
applied to a ``MujocoPlant`` in this process, without IPC. Lockstep makes
the plant deterministic, so both must agree exactly (PLANT-GUIDE.md: "with
the same commands a deterministic simulator replays bit for bit"), and the
object must follow the plan. Prints one JSON object (asserted by
``tests/tests/python_plant.rs``).

Usage: mujoco_lockstep_replay.py --trace T --dir D --prefix P --root R --file-prefix F
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from plant_protocol import StandIn

from gaitd import config, quat, trace
from gaitd.plants.mujoco_plant import MujocoPlant
from gaitd.setpoint import decode_command, encode_command

REPO = Path(__file__).resolve().parents[2]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--trace", required=True)
    ap.add_argument("--dir", required=True)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--file-prefix", required=True)
    a = ap.parse_args()
    d = Path(a.dir)
    d.mkdir(parents=True, exist_ok=True)
    cfg_path = d / "gaitd.toml"
    cfg_path.write_text(
        f'[ipc]\nservice_prefix = "{a.prefix}"\nroot_path = "{a.root}"\nfile_prefix = "{a.file_prefix}"\n'
        '[load]\ngravity = [0.0, 0.0, 0.0]\n[plant]\nkind = "shm"\ntiming = "lockstep"\nlockstep_timeout_ms = 5000\n'
    )
    cfg = config.load(cfg_path)
    tr = trace.read(a.trace)
    sps = trace.setpoints(tr, lockstep=True)
    grip = sps[0].fingers[0].grip_force
    settings = cfg.ipc_settings()
    s = StandIn(settings, measurement_publishers=2)
    report = d / "plant-report.json"
    env = dict(os.environ, PYTHONPATH=str(REPO / "client/python"))
    plant = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "gaitd.plants.mujoco",
            "--config",
            str(cfg_path),
            "--timing",
            "lockstep",
            "--initial-grip",
            repr(grip),
            "--report",
            str(report),
        ],
        env=env,
        stderr=subprocess.PIPE,
        text=True,
    )

    # The same setpoints in this process, no IPC: the reference run.
    local = MujocoPlant(cfg, initial_grip=grip)
    local.apply(local.initial_setpoint())

    session = 0x5EED
    errors, mismatches, echo_errors = [], 0, 0
    t0 = None
    last = None
    n = len(sps)
    for k in range(1, n):
        got = s.wait(1, timeout=60.0 if k == 1 else 10.0)
        if not got:
            break
        if t0 is None:
            t0 = time.perf_counter()
        m = got[-1]
        if m.seq != k or (k > 1 and m.applied != k - 1) or (k > 1 and m.session != session):
            echo_errors += 1
        if k > 1:
            errors.append(math.degrees(quat.angle_between(m.object_q, sps[k - 1].object_q)))
            lm = local.measure()
            if tuple(m.object_q) != quat.normalize(lm.object_q) or any(
                tuple(a.position) != tuple(b.position) for a, b in zip(m.fingers, lm.fingers)
            ):
                mismatches += 1
        c = encode_command(sps[k])
        c.session, c.seq, c.answers = session, k, m.seq
        c.target_time_ns, c.period_ns = m.time_ns + cfg.period_ns, cfg.period_ns
        s.send(c)
        local.apply(decode_command(c))  # exactly what the plant process decodes
        local.step(local.period)
        last = m
    final = s.wait(1, timeout=10.0)
    wall = time.perf_counter() - t0 if t0 else 0.0
    if final:
        m = final[-1]
        errors.append(math.degrees(quat.angle_between(m.object_q, sps[-1].object_q)))
        lm = local.measure()
        if tuple(m.object_q) != quat.normalize(lm.object_q):
            mismatches += 1
        last = m
    plant.send_signal(signal.SIGTERM)
    try:
        _, err = plant.communicate(timeout=20)
    except subprocess.TimeoutExpired:
        plant.kill()
        _, err = plant.communicate()
    rep = json.loads(report.read_text()) if report.exists() else {}
    out = {
        "samples": n,
        "exchanged": len(errors),
        "exit_code": plant.returncode,
        "echo_errors": echo_errors,
        "bitwise_mismatches": mismatches,
        "max_error_deg": max(errors) if errors else None,
        "final_error_deg": errors[-1] if errors else None,
        "final_seq": last.seq if last else None,
        "exchange_wall_s": wall,
        "exchanges_per_s": len(errors) / wall if wall else None,
        "plant_report": rep,
        "stderr": err[-2500:],
    }
    json.dump(out, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())

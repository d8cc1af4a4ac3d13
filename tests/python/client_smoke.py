#!/usr/bin/env python3
"""Drives a running gaitd through the ``gaitd`` Python package and prints one JSON object.

Run by ``tests/tests/python_client.rs`` (which asserts on the output): checks
the ctypes mirror against LAYOUT.md, connects, reads the status, sends a
hold, a 90° relative goal (and waits for its outcome) and a NaN goal,
then reads the events and the counters. Usage::

    client_smoke.py --layout LAYOUT.md --prefix P --root R --file-prefix F
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import math
import sys

from gaitd.client import Client
from gaitd.schema import EventKind, GoalFrame, GoalState, check_layout


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--layout", required=True)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--file-prefix", required=True)
    ap.add_argument("--timeout", type=float, default=10.0)
    a = ap.parse_args()

    check_layout(a.layout)
    with Client.connect(prefix=a.prefix, root_path=a.root, file_prefix=a.file_prefix, timeout=a.timeout) as c:
        st = c.wait_status(a.timeout)
        result: dict = {
            "iceoryx2": importlib.metadata.version("iceoryx2"),
            "status": {
                "tick": st.tick,
                "daemon_state": st.daemon_state,
                "phase": st.phase,
                "contact_radii": [math.sqrt(sum(x * x for x in f.contact_hand)) for f in st.fingers],
                "period_ns": st.timing.period_ns,
            },
        }

        def reply(r) -> dict:
            return {"code": r.code, "reason": r.reason.name.rstrip("_"), "goal_id": r.goal_id, "tick": r.tick}

        result["hold"] = reply(c.hold(a.timeout))
        half = math.pi / 4  # 90° about z
        goal = c.goal((math.cos(half), 0.0, 0.0, math.sin(half)), GoalFrame.Relative, goal_id=1, timeout=a.timeout)
        result["goal"] = reply(goal)
        result["nan_goal"] = reply(
            c.goal((float("nan"), 0.0, 0.0, 0.0), GoalFrame.Absolute, goal_id=2, timeout=a.timeout)
        )
        outcome = c.wait_outcome(1, timeout=60.0)
        result["goal_outcome"] = {"state": outcome.state.name, "reason": outcome.reason.name}
        later = c._wait_until(
            a.timeout, "the counters", lambda: s if (s := c.latest_status()) and s.commands >= 3 else None
        )
        result["status_after"] = {"commands": later.commands, "rejected": later.rejected, "tick": later.tick}
        transitions = [
            GoalState(e.state).name
            for e in c.events()
            if e.kind == EventKind.GoalTransition and e.goal_id == 1 and e.client_id == c.client_id
        ]
        result["goal_transitions"] = transitions
        result["bad_samples"] = c.bad_samples
    json.dump(result, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())

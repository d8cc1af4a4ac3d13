#!/usr/bin/env python3
"""A remote client through gaitd-bridge (``gaitd.remote``): reads the status, sends a goal, waits for it.

Run by ``tests/tests/remote/python.rs``, which asserts on the one JSON object
printed last; it also reports what a user is told for an endpoint where no
bridge listens (``NO_BRIDGE``) and for a protocol the bridge does not speak.
Usage::

    remote_goal.py ENDPOINT PKI_DIR IDENTITY PREFIX NO_BRIDGE
"""

from __future__ import annotations

import json
import math
import sys
import time

from gaitd.remote import RemoteClient, RemoteError
from gaitd.schema import DaemonState


def refusal(endpoint: str, pki: str, name: str) -> str:
    """The message of the RemoteError that connecting to ``endpoint`` raises."""
    try:
        RemoteClient.connect(endpoint, f"{pki}/ca.pem", f"{pki}/{name}.pem", f"{pki}/{name}.key", timeout=1.0)
    except RemoteError as e:
        return str(e)
    return "connected"


def main() -> int:
    endpoint, pki, name, prefix, no_bridge = sys.argv[1:6]
    refusals = {
        "no_bridge_error": refusal(no_bridge, pki, name),
        "tcp_error": refusal("tcp/127.0.0.1:7447", pki, name),
    }
    t0 = time.monotonic()
    stamps = {}
    with RemoteClient.connect(
        endpoint, f"{pki}/ca.pem", f"{pki}/{name}.pem", f"{pki}/{name}.key", prefix=prefix, timeout=10.0
    ) as c:
        stamps["connected_s"] = time.monotonic() - t0
        first = c.wait_status(5.0)
        time.sleep(0.2)
        later = c.wait_status(5.0)
        stamps["status_s"] = time.monotonic() - t0
        reply = c.turn((0.0, 0.0, 1.0), math.pi / 4, timeout=10.0)
        stamps["answer_s"] = time.monotonic() - t0
        outcome = c.wait_outcome(reply.goal_id, timeout=60.0) if reply.accepted else None
        stamps["outcome_s"] = time.monotonic() - t0
        print(
            json.dumps(
                {
                    "daemon_state": DaemonState(first.daemon_state).name,
                    "status_ticks_advance": later.tick > first.tick,
                    "accepted": reply.accepted,
                    "reason": reply.reason.name,
                    "outcome": outcome.state.name if outcome else None,
                    "client_id": f"{c.client_id:x}",
                    "bad_samples": c.bad_samples,
                    **refusals,
                    # Seconds since start, for a slow run's diagnosis.
                    **{k: round(v, 3) for k, v in stamps.items()},
                }
            )
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())

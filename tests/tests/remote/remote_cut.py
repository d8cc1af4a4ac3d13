#!/usr/bin/env python3
"""A remote Python client whose link is cut with a command in flight (``gaitd.remote``).

Run by ``tests/tests/remote/python.rs`` through the cutting forwarder of
``cut.rs``: connects, prints ``connected``, waits for ``go`` on stdin (the
test arms the forwarder meanwhile), sends a hold and prints one JSON object
with what came back; then a monitor's hold, which access control drops,
must still end soon as unanswered (not be sent again). Usage::

    remote_cut.py ENDPOINT PKI_DIR IDENTITY PREFIX
"""

from __future__ import annotations

import json
import sys
import time

from gaitd.remote import NoAnswer, RemoteClient


def main() -> int:
    endpoint, pki, name, prefix = sys.argv[1:5]

    def connect(who: str) -> RemoteClient:
        return RemoteClient.connect(
            endpoint, f"{pki}/ca.pem", f"{pki}/{who}.pem", f"{pki}/{who}.key", prefix=prefix, timeout=10.0
        )

    with connect(name) as c:
        c.wait_status(5.0)
        print("connected", flush=True)
        if sys.stdin.readline().strip() != "go":
            return 2
        t0 = time.monotonic()
        out: dict[str, object] = {}
        try:
            reply = c.hold()
            out.update(accepted=reply.accepted, reason=reply.reason.name, request_id=reply.request_id)
        except Exception as e:  # noqa: BLE001 - reported to the test
            out["error"] = f"{type(e).__name__}: {e}"
        out.update(answer_s=round(time.monotonic() - t0, 3), reconnects=c.reconnects)
    with connect("dash") as m:
        t0 = time.monotonic()
        try:
            m.hold()
            out["monitor"] = "answered"
        except NoAnswer:
            out["monitor"] = "NoAnswer"
        except Exception as e:  # noqa: BLE001 - reported to the test
            out["monitor"] = f"{type(e).__name__}: {e}"
        out["monitor_s"] = round(time.monotonic() - t0, 3)
    print(json.dumps(out), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

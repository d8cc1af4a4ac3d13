#!/usr/bin/env python3
"""A Python client of gaitd built only from the documented layout.

Mirrors the payloads of shm_schema/LAYOUT.md with ctypes, checks every
field's offset and size against that document, then talks to a running
daemon over iceoryx2 (PyPI ``iceoryx2``, the same version as the daemon):
reads the status, sends a hold, a goal and a malformed goal, and prints
what came back as one JSON object.

Usage: gaitd_client.py --layout LAYOUT.md --prefix P --root R --file-prefix F
"""

import argparse
import ctypes
import importlib.metadata
import json
import math
import re
import sys
import time

import iceoryx2 as iox2

ICEORYX2_VERSION = "0.10.0"

u32, u64, f64 = ctypes.c_uint32, ctypes.c_uint64, ctypes.c_double


def named(type_name):
    """Class decorator: the iceoryx2 type name (must equal the Rust one)."""

    def wrap(cls):
        cls.type_name = staticmethod(lambda: type_name)
        return cls

    return wrap


@named("gaitd::MotionLimits.v2")
class MotionLimits(ctypes.Structure):
    _fields_ = [("velocity", f64), ("acceleration", f64), ("jerk", f64)]


@named("gaitd::Command.v2")
class Command(ctypes.Structure):
    _fields_ = [
        ("kind", u32),
        ("frame", u32),
        ("client_id", u64),
        ("request_id", u64),
        ("goal_id", u64),
        ("target", f64 * 4),
        ("limit_mask", u32),
        ("reserved", u32),
        ("object_limits", MotionLimits),
        ("fingertip_limits", MotionLimits),
        ("rolling_limits", MotionLimits),
    ]


@named("gaitd::Answer.v2")
class Answer(ctypes.Structure):
    _fields_ = [
        ("client_id", u64),
        ("request_id", u64),
        ("goal_id", u64),
        ("command", u32),
        ("code", u32),
        ("reason", u32),
        ("reserved", u32),
        ("tick", u64),
        ("instance", u64),
    ]


@named("gaitd::GoalStatus.v2")
class GoalStatus(ctypes.Structure):
    _fields_ = [
        ("goal_id", u64),
        ("client_id", u64),
        ("state", u32),
        ("reason", u32),
        ("remaining_angle", f64),
        ("eta", f64),
        ("gaits_done", u32),
        ("gaits_planned", u32),
        ("active_finger", u32),
        ("reserved", u32),
    ]


@named("gaitd::FingerStatus.v2")
class FingerStatus(ctypes.Structure):
    _fields_ = [
        ("state", u32),
        ("measured_contact", u32),
        ("contact_hand", f64 * 3),
        ("contact_object", f64 * 3),
        ("commanded_tip_position", f64 * 3),
        ("commanded_tip_orientation", f64 * 4),
        ("tip_contact", f64 * 3),
        ("roll", f64),
        ("workspace_margin", f64),
        ("commanded_normal_force", f64),
        ("measured_tip_position", f64 * 3),
        ("measured_tip_orientation", f64 * 4),
        ("measured_normal_force", f64),
        ("tip_error", f64),
    ]


@named("gaitd::Timing.v2")
class Timing(ctypes.Structure):
    _fields_ = [
        ("period_ns", u64),
        ("compute_last_ns", u64),
        ("compute_p50_ns", u64),
        ("compute_p99_ns", u64),
        ("compute_max_ns", u64),
        ("jitter_last_ns", u64),
        ("jitter_p99_ns", u64),
        ("jitter_max_ns", u64),
        ("overruns", u64),
        ("jitter_hist", u64 * 16),
    ]


@named("gaitd::Status.v2")
class Status(ctypes.Structure):
    _fields_ = [
        ("tick", u64),
        ("time_ns", u64),
        ("publish_time_ns", u64),
        ("instance", u64),
        ("daemon_state", u32),
        ("phase", u32),
        ("fault", u32),
        ("grasp", u32),
        ("grasp_margin", f64),
        ("commanded_object_q", f64 * 4),
        ("commanded_object_omega", f64 * 3),
        ("measured_object_q", f64 * 4),
        ("object_error", f64),
        ("measured_tick", u64),
        ("measured_mask", u32),
        ("reserved0", u32),
        ("goal", GoalStatus),
        ("fingers", FingerStatus * 3),
        ("timing", Timing),
        ("commands", u64),
        ("rejected", u64),
        ("clients", u32),
        ("reserved", u32),
    ]


@named("gaitd::Event.v2")
class Event(ctypes.Structure):
    _fields_ = [
        ("seq", u64),
        ("tick", u64),
        ("time_ns", u64),
        ("instance", u64),
        ("kind", u32),
        ("finger", u32),
        ("state", u32),
        ("reason", u32),
        ("goal_id", u64),
        ("client_id", u64),
        ("fault", u32),
        ("reserved", u32),
        ("count", u64),
        ("value", f64),
    ]


PAYLOADS = [MotionLimits, Command, Answer, GoalStatus, FingerStatus, Timing, Status, Event]


def parse_layout(path):
    """Payload tables and code tables of LAYOUT.md."""
    types, codes, current, kind = {}, {}, None, None
    head = re.compile(r"^### `(\w+)`(?: \(`([^`]+)`, (\d+) bytes, align (\d+)\))?$")
    row = re.compile(r"^\| (\d+) \| (\d+) \| `(\w+)` \|")
    code_row = re.compile(r"^\| (\d+) \| `(\w+)` \|")
    for line in open(path, encoding="utf-8"):
        line = line.rstrip("\n")
        m = head.match(line)
        if m:
            name, tname, size, align = m.groups()
            if tname:
                current, kind = name, "type"
                types[name] = {"type_name": tname, "size": int(size), "align": int(align), "fields": []}
            else:
                current, kind = name, "code"
                codes[name] = {}
            continue
        if kind == "type" and (m := row.match(line)):
            off, size, field = m.groups()
            types[current]["fields"].append((field, int(off), int(size)))
        elif kind == "code" and (m := code_row.match(line)):
            value, cname = m.groups()
            codes[current][cname] = int(value)
    return types, codes


def check_layout(types):
    """Every ctypes mirror matches the document exactly."""
    for cls in PAYLOADS:
        doc = types.get(cls.__name__)
        if doc is None:
            raise SystemExit(f"{cls.__name__} missing from the layout document")
        if cls.type_name() != doc["type_name"]:
            raise SystemExit(f"{cls.__name__}: type name {cls.type_name()} != {doc['type_name']}")
        if ctypes.sizeof(cls) != doc["size"] or ctypes.alignment(cls) != doc["align"]:
            raise SystemExit(f"{cls.__name__}: size/align {ctypes.sizeof(cls)}/{ctypes.alignment(cls)} "
                             f"!= {doc['size']}/{doc['align']}")
        mine = [(n, getattr(cls, n).offset, getattr(cls, n).size) for n, _ in cls._fields_]
        if mine != doc["fields"]:
            raise SystemExit(f"{cls.__name__}: fields {mine} != documented {doc['fields']}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--layout", required=True)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--file-prefix", required=True)
    ap.add_argument("--timeout", type=float, default=10.0)
    a = ap.parse_args()

    version = importlib.metadata.version("iceoryx2")
    if version != ICEORYX2_VERSION:
        raise SystemExit(f"iceoryx2 {version} installed, the daemon uses {ICEORYX2_VERSION}")
    types, codes = parse_layout(a.layout)
    check_layout(types)
    cmd_kind, reason, answer_code = codes["CommandKind"], codes["ReasonCode"], codes["AnswerCode"]
    reason_name = {v: k for k, v in reason.items()}

    iox2.set_log_level(iox2.LogLevel.Error)
    config = iox2.config.default()
    config.global_cfg.root_path = iox2.Path.new(a.root)
    config.global_cfg.prefix = iox2.FileName.new(a.file_prefix)
    node = iox2.NodeBuilder.new().config(config).create(iox2.ServiceType.Ipc)

    def service(name, payload):
        return node.service_builder(iox2.ServiceName.new(f"{a.prefix}/{name}")).publish_subscribe(payload).open()

    commands = service("commands", Command).publisher_builder().create()
    answers = service("answers", Answer).subscriber_builder().create()
    status = service("status", Status).subscriber_builder().create()
    listener = (node.service_builder(iox2.ServiceName.new(f"{a.prefix}/notify"))
                .event().open().listener_builder().create())
    deadline = time.monotonic() + a.timeout

    def wait(take):
        """Blocks on the daemon's notifications until take() returns a value."""
        while True:
            v = take()
            if v is not None:
                return v
            left = deadline - time.monotonic()
            if left <= 0:
                raise SystemExit("timed out waiting for the daemon")
            listener.timed_wait(iox2.Duration.from_millis(int(min(left, 0.1) * 1000) + 1))

    def latest_status():
        last = None
        while (s := status.receive()) is not None:
            last = Status.from_buffer_copy(s.payload().contents)
        return last

    st = wait(latest_status)
    client_id = 0x5059_7468_6F6E  # "Python"
    request = [0]

    def send(kind, goal_id=0, frame=0, target=(0.0, 0.0, 0.0, 0.0)):
        request[0] += 1
        c = Command(kind=cmd_kind[kind], frame=frame, client_id=client_id,
                    request_id=request[0], goal_id=goal_id)
        for i, v in enumerate(target):
            c.target[i] = v
        sample = commands.loan_uninit()
        sample = sample.write_payload(c)
        sample.send()
        rid = request[0]

        def take():
            while (s := answers.receive()) is not None:
                ans = Answer.from_buffer_copy(s.payload().contents)
                if (ans.client_id, ans.request_id) == (client_id, rid):
                    return ans
            return None

        ans = wait(take)
        return {"code": "Accepted" if ans.code == answer_code["Accepted"] else "Rejected",
                "reason": reason_name[ans.reason], "goal_id": ans.goal_id, "tick": ans.tick}

    half = math.pi / 4  # 90 degrees about z
    result = {
        "iceoryx2": version,
        "status": {
            "tick": st.tick,
            "daemon_state": st.daemon_state,
            "phase": st.phase,
            "contact_radii": [math.sqrt(sum(x * x for x in f.contact_hand)) for f in st.fingers],
            "period_ns": st.timing.period_ns,
        },
        "hold": send("Hold"),
        "goal": send("Goal", goal_id=1, frame=codes["GoalFrame"]["Relative"],
                     target=(math.cos(half), 0.0, 0.0, math.sin(half))),
        "nan_goal": send("Goal", goal_id=2, frame=codes["GoalFrame"]["Absolute"],
                         target=(float("nan"), 0.0, 0.0, 0.0)),
    }
    later = wait(lambda: (s if (s := latest_status()) is not None and s.commands >= 3 else None))
    result["status_after"] = {"commands": later.commands, "rejected": later.rejected, "tick": later.tick}
    json.dump(result, sys.stdout)
    print()


if __name__ == "__main__":
    main()

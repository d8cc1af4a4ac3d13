#!/usr/bin/env python3
"""The ``Plant`` base class against a stand-in for the daemon's side of the plant services.

This is a test fixture for the base class (not a replacement for gaitd):
it creates the four plant services itself, with the settings
PLANT-GUIDE.md gives the daemon's, runs the example plant
(``client/python/examples/kinematic_hand.py``, a ``Plant`` subclass) as a
separate process, and plays the daemon's part by hand: it checks the
plant's numbering, echo and timing, and sends it good, bad and stale
commands. Prints one JSON object ``{"checks": {name: {"ok", "detail"}}}``
(``tests/tests/python_plant_protocol.rs`` asserts every check).

Usage: plant_protocol.py --dir D --prefix P --root R --file-prefix F [--mutate NAME]

``--mutate`` breaks the base class in the plant process on purpose:
``no-validation`` (commands are not checked), ``no-echo`` (``applied``
stays 0), ``no-wait`` (lockstep does not wait for the answer).
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

from gaitd import ipc
from gaitd.config import Model
from gaitd.hand import paper_start
from gaitd.schema import (
    CommandFlags,
    PlantCommand,
    PlantMeasurement,
    PlantState,
    ServiceNames,
    VALID_REQUIRED,
)
from gaitd.setpoint import encode_command

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "client/python/examples/kinematic_hand.py"
PERIOD_NS = 1_000_000
TIMEOUT_MS = 400

# The plant process with a mutation applied before the example runs.
MUTATED = """
import runpy, sys
from gaitd import plant, setpoint
mode = sys.argv.pop(1)
if mode == "no-validation":
    plant.check_setpoint = setpoint.check_setpoint = lambda c: None
    plant.check_header = lambda *a: None
elif mode == "no-echo":
    original = plant.Exchange.take
    def take(self, c, check=None):
        sp = original(self, c, check)
        self.applied = 0
        return sp
    plant.Exchange.take = take
elif mode == "no-wait":
    plant.Plant._block = lambda self, s: None
    original_receive = plant.Plant._receive
    def receive(self):
        sp, _ = original_receive(self)
        return sp, True
    plant.Plant._receive = receive
sys.argv[0] = sys.argv[1]
del sys.argv[1]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


class StandIn:
    """The daemon's side of the four plant services."""

    def __init__(self, settings: ipc.IpcSettings, measurement_publishers: int):
        iox2 = ipc.iceoryx2()
        self.iox2 = iox2
        names = ServiceNames(settings.service_prefix)
        self.node = ipc.create_node(settings, "standin-daemon")
        sn = ipc.service_name
        cmd = (
            self.node.service_builder(sn(names.plant_command))
            .publish_subscribe(PlantCommand)
            .max_publishers(1)
            .max_subscribers(2)
            .history_size(1)
            .subscriber_max_buffer_size(2)
            .enable_safe_overflow(True)
            .create()
        )
        meas = (
            self.node.service_builder(sn(names.plant_measurement))
            .publish_subscribe(PlantMeasurement)
            .max_publishers(measurement_publishers)
            .max_subscribers(1)
            .history_size(0)
            .subscriber_max_buffer_size(256)
            .enable_safe_overflow(True)
            .create()
        )
        commanded = (
            self.node.service_builder(sn(names.plant_commanded)).event().max_notifiers(1).max_listeners(2).create()
        )
        measured = (
            self.node.service_builder(sn(names.plant_measured)).event().max_notifiers(2).max_listeners(1).create()
        )
        self.pub = cmd.publisher_builder().create()
        self.sub = meas.subscriber_builder().buffer_size(256).create()
        self.notifier = commanded.notifier_builder().default_event_id(iox2.EventId.new(1)).create()
        self.listener = measured.listener_builder().create()
        self.seen: list[PlantMeasurement] = []

    def drain(self) -> list[PlantMeasurement]:
        out = []
        while (s := self.sub.receive()) is not None:
            out.append(PlantMeasurement.from_buffer_copy(s.payload().contents))
        self.seen += out
        return out

    def wait(self, count: int = 1, timeout: float = 5.0) -> list[PlantMeasurement]:
        """At least ``count`` new measurements (fewer if ``timeout`` passes)."""
        got: list[PlantMeasurement] = []
        deadline = time.monotonic() + timeout
        while len(got) < count:
            got += self.drain()
            left = deadline - time.monotonic()
            if len(got) >= count or left <= 0:
                break
            self.listener.timed_wait(self.iox2.Duration.from_secs_f64(min(left, 0.05)))
        return got

    def quiet(self, seconds: float) -> list[PlantMeasurement]:
        """Whatever arrives within ``seconds`` (used to show that nothing does)."""
        time.sleep(seconds)
        return self.drain()

    def send(self, c: PlantCommand) -> None:
        self.pub.loan_uninit().write_payload(c).send()
        self.notifier.notify()


def command(
    session: int,
    seq: int,
    answering: PlantMeasurement | None,
    lockstep: bool,
    shift: float = 0.0,
    flags: int | None = None,
) -> PlantCommand:
    """A valid command: the start grasp, finger 0 moved by ``shift`` along z, object turned by shift rad.

    No fingertip moves with a velocity, so a plant that turns the object as
    its grasping fingertips roll it (the example) leaves it at identity.
    """
    sp = paper_start(Model(), grips=(2.0, 2.0, 2.0))
    c = encode_command(sp)
    c.session, c.seq, c.period_ns = session, seq, PERIOD_NS
    c.flags = int(CommandFlags.ENABLE | (CommandFlags.LOCKSTEP if lockstep else 0)) if flags is None else flags
    if answering is not None:
        c.answers = answering.seq
        c.target_time_ns = answering.time_ns + PERIOD_NS
    c.fingers[0].position[2] = shift
    c.object_q[:] = (math.cos(shift / 2), 0.0, 0.0, math.sin(shift / 2))
    return c


def spawn(plant_dir: Path, settings: ipc.IpcSettings, timing: str, mutate: str | None) -> subprocess.Popen:
    cfg = plant_dir / f"gaitd-{timing}.toml"
    cfg.write_text(
        f'[ipc]\nservice_prefix = "{settings.service_prefix}"\nroot_path = "{settings.root_path}"\n'
        f'file_prefix = "{settings.file_prefix}"\n[control]\ntick_hz = 1000.0\n'
        f'[plant]\nkind = "shm"\ntiming = "{timing}"\nlockstep_timeout_ms = {TIMEOUT_MS}\n'
    )
    env = dict(os.environ, PYTHONPATH=str(REPO / "client/python"))
    args = [sys.executable, str(EXAMPLE), "--config", str(cfg)]
    if mutate:
        args = [sys.executable, "-c", MUTATED, mutate, str(EXAMPLE), "--config", str(cfg)]
    return subprocess.Popen(args, env=env, stderr=subprocess.PIPE, text=True)


class Checks:
    def __init__(self) -> None:
        self.items: dict[str, dict] = {}

    def __call__(self, name: str, ok: bool, detail) -> None:
        self.items[name] = {"ok": bool(ok), "detail": detail}


def seqs(ms: list[PlantMeasurement]) -> list[int]:
    return [m.seq for m in ms]


def lockstep_checks(check: Checks, s: StandIn, settings, plant_dir: Path, mutate: str | None) -> str:
    plant = spawn(plant_dir, settings, "lockstep", mutate)
    first = s.wait(1, timeout=30.0)
    m1 = first[0] if first else None
    check(
        "first measurement: seq 1, session id 0, applied 0, time one period, required fields, simulated",
        m1 is not None
        and (m1.seq, m1.session, m1.applied, m1.time_ns) == (1, 0, 0, PERIOD_NS)
        and m1.valid & VALID_REQUIRED == VALID_REQUIRED
        and m1.state & PlantState.SIMULATED,
        None
        if m1 is None
        else {
            "seq": m1.seq,
            "session": m1.session,
            "applied": m1.applied,
            "time_ns": m1.time_ns,
            "valid": m1.valid,
            "state": m1.state,
        },
    )
    early = s.quiet(TIMEOUT_MS / 1000 / 3)
    check(
        "lockstep: nothing more before the command answering measurement 1 (within the timeout)",
        early == [],
        seqs(early),
    )
    late = s.wait(3, timeout=5.0)
    check(
        "lockstep timeout: the plant holds and keeps publishing, seq +1 each, time increasing, applied 0",
        len(late) >= 3
        and seqs(late) == list(range(2, 2 + len(late)))
        and all(b.time_ns > a.time_ns for a, b in zip([m1] + late, late))
        and all(m.applied == 0 for m in late)
        and all(list(m.fingers[0].position) == list(m1.fingers[0].position) for m in late),
        seqs(late),
    )
    seq = 0

    def in_step(session: int, shift: float, name: str) -> PlantMeasurement | None:
        """Answers the newest measurement until the plant is back in step; returns its next measurement."""
        nonlocal seq
        for _ in range(50):
            newest = (s.wait(1, timeout=2.0) or s.seen[-1:])[-1]
            newest = (s.drain() or [newest])[-1]
            seq += 1
            s.send(command(session, seq, newest, True, shift=shift))
            nxt = s.wait(1, timeout=2.0)
            if nxt and nxt[0].seq == newest.seq + 1 and nxt[0].applied == seq and not s.quiet(0.03):
                m = nxt[-1]
                check(
                    name,
                    m.session == session
                    and abs(m.fingers[0].position[2] - shift) < 1e-12
                    and list(m.object_q) == [1.0, 0.0, 0.0, 0.0],
                    {"seq": m.seq, "session": m.session, "applied": m.applied, "tip_z": m.fingers[0].position[2]},
                )
                return m
        check(name, False, "the plant did not come back in step")
        return None

    last = in_step(
        7,
        0.001,
        "a good command is applied: session and seq echoed, numbering goes on, fingertip where commanded, "
        "object not copied from the command",
    )
    extra = s.quiet(TIMEOUT_MS / 1000 / 3)
    check("lockstep: after an answer the plant waits again (no step without the next answer)", extra == [], seqs(extra))
    rejected = 0

    def exchange(name: str, mutate_cmd, echoed: bool, moves: bool, shift: float) -> None:
        """Answers the plant's newest measurement with a (mutated) command and checks the next one."""
        nonlocal seq, last, rejected
        seq += 1
        c = command(7, seq, last, True, shift=shift)
        mutate_cmd(c)
        s.send(c)
        got = s.wait(1, timeout=3.0)
        m = got[-1] if got else None
        before = last
        if m is not None:
            last = m
        if not echoed:
            rejected += 1
        ok = (
            m is not None
            and m.seq == before.seq + 1
            and (m.applied == seq) == echoed
            and (abs(m.fingers[0].position[2] - shift) < 1e-12) == moves
            and (moves or list(m.fingers[0].position) == list(before.fingers[0].position))
        )
        check(
            name,
            ok,
            None
            if m is None
            else {
                "seq": m.seq,
                "after": before.seq,
                "applied": m.applied,
                "cmd_seq": seq,
                "tip_z": m.fingers[0].position[2],
            },
        )

    nan = float("nan")
    bad = [
        ("NaN fingertip position", lambda c: c.fingers[0].position.__setitem__(0, nan)),
        (
            "non-unit fingertip quaternion",
            lambda c: c.fingers[1].orientation.__setitem__(slice(0, 4), [1.1 * v for v in c.fingers[1].orientation]),
        ),
        ("non-unit object quaternion", lambda c: c.object_q.__setitem__(0, 2.0)),
        ("NaN object angular velocity", lambda c: c.object_omega.__setitem__(1, nan)),
        ("unknown finger mode 9", lambda c: setattr(c.fingers[2], "mode", 9)),
        ("finger mode 0", lambda c: setattr(c.fingers[2], "mode", 0)),
        ("unknown flag bit", lambda c: setattr(c, "flags", c.flags | 1 << 5)),
        ("non-zero padding", lambda c: setattr(c, "reserved", 1)),
        ("a finger joint count beyond the arrays", lambda c: setattr(c.fingers[0], "joint_count", 5)),
        ("infinite grip force", lambda c: setattr(c.fingers[1], "grip_force", float("inf"))),
        ("negative grip force", lambda c: setattr(c.fingers[1], "grip_force", -1.0)),
        ("wrong period", lambda c: setattr(c, "period_ns", 2 * PERIOD_NS)),
        ("wrong target time", lambda c: setattr(c, "target_time_ns", c.target_time_ns + 1)),
        ("realtime command to a lockstep plant", lambda c: setattr(c, "flags", int(CommandFlags.ENABLE))),
    ]
    for i, (what, mutate_cmd) in enumerate(bad):
        exchange(
            f"lockstep refuses a command with {what}: not applied, not echoed, the grasp holds",
            mutate_cmd,
            echoed=False,
            moves=False,
            shift=0.002 + 0.001 * i,
        )
    exchange("a good command after bad ones is applied", lambda c: None, echoed=True, moves=True, shift=0.03)
    exchange(
        "HOLD: echoed, the last setpoint held (the command's pose not used)",
        lambda c: setattr(c, "flags", c.flags | CommandFlags.HOLD),
        echoed=True,
        moves=False,
        shift=0.031,
    )
    exchange(
        "without ENABLE: echoed, nothing moves",
        lambda c: setattr(c, "flags", int(CommandFlags.LOCKSTEP)),
        echoed=True,
        moves=False,
        shift=0.032,
    )
    # A repeated sequence number (same session) is ignored: no answer, so the plant times out and holds.
    s.send(command(7, seq, last, True, shift=0.033))
    got = s.wait(3, timeout=3.0)
    check(
        "a repeated command (same session, same seq) is not applied again; the plant times out and holds",
        len(got) >= 3 and all(m.applied == seq and abs(m.fingers[0].position[2] - 0.033) > 1e-9 for m in got),
        [{"seq": m.seq, "applied": m.applied} for m in got[:3]],
    )
    # A command answering a measurement not sent yet is refused.
    seq += 1
    future = command(7, seq, s.seen[-1], True, shift=0.034)
    future.answers = s.seen[-1].seq + 1000
    s.send(future)
    got = s.wait(3, timeout=3.0)
    rejected += 1
    check(
        "a command answering a future measurement is refused",
        len(got) >= 3 and all(m.applied != seq and abs(m.fingers[0].position[2] - 0.034) > 1e-9 for m in got),
        [{"seq": m.seq, "applied": m.applied} for m in got[:3]],
    )
    seq += 1
    zero = command(0, seq, s.seen[-1], True, shift=0.036)
    s.send(zero)
    got = s.wait(3, timeout=3.0)
    rejected += 1
    check(
        "a command of session id 0 is refused",
        len(got) >= 3 and all(abs(m.fingers[0].position[2] - 0.036) > 1e-9 for m in got),
        [{"seq": m.seq, "applied": m.applied} for m in got[:3]],
    )
    # A new daemon session (a restarted daemon) starts its own numbering.
    seq = 0
    in_step(99, 0.035, "a new daemon session is taken: session echoed, its own numbering applied")
    plant.send_signal(signal.SIGTERM)
    try:
        _, err = plant.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        plant.kill()
        _, err = plant.communicate()
    check("SIGTERM: the plant exits cleanly", plant.returncode == 0, err[-2000:])
    stats = [line for line in err.splitlines() if "real-time factor" in line]
    want = f"{rejected} rejected"
    check(
        f"the plant counted every refused command ({want}) and printed its real-time factor",
        bool(stats) and want in stats[-1],
        stats[-1:] + [line for line in err.splitlines() if "not applied" in line][:30],
    )
    return err


def realtime_checks(check: Checks, s: StandIn, settings, plant_dir: Path, mutate: str | None) -> str:
    plant = spawn(plant_dir, settings, "realtime", mutate)
    got = s.wait(20, timeout=30.0)
    check(
        "realtime: measurements every period without any command, seq 1, 2, 3, …, time increasing",
        len(got) >= 20
        and seqs(got) == list(range(1, len(got) + 1))
        and all(b.time_ns > a.time_ns for a, b in zip(got, got[1:]))
        and all(m.applied == 0 for m in got),
        seqs(got)[:25],
    )
    c = command(5, 1, got[-1], False, shift=0.002)
    s.send(c)
    t0 = time.monotonic()
    applied = None
    while time.monotonic() - t0 < 5.0 and applied is None:
        for m in s.wait(1, timeout=1.0):
            if m.applied == 1:
                applied = m
    check(
        "realtime: the newest command is applied and echoed",
        applied is not None and applied.session == 5 and abs(applied.fingers[0].position[2] - 0.002) < 1e-12,
        None if applied is None else {"seq": applied.seq, "applied": applied.applied},
    )
    c = command(5, 2, s.seen[-1], True, shift=0.003)  # LOCKSTEP flag to a realtime plant
    s.send(c)
    later = s.wait(30, timeout=5.0)
    check(
        "realtime: a lockstep command is refused",
        later
        and all(m.applied == 1 for m in later)
        and all(abs(m.fingers[0].position[2] - 0.002) < 1e-12 for m in later),
        seqs(later)[:5],
    )
    plant.send_signal(signal.SIGTERM)
    _, err = plant.communicate(timeout=10)
    check("realtime: SIGTERM exits cleanly", plant.returncode == 0, err[-1000:])
    return err


def restart_checks(check: Checks, s: StandIn, settings, plant_dir: Path, mutate: str | None) -> str:
    """A killed plant's publisher keeps its slot (one here) until the new plant's retry cleans it up."""
    first = spawn(plant_dir, settings, "realtime", mutate)
    got = s.wait(5, timeout=30.0)
    first.send_signal(signal.SIGKILL)
    first.wait()
    s.quiet(0.1)
    second = spawn(plant_dir, settings, "realtime", mutate)
    fresh: list[PlantMeasurement] = []
    deadline = time.monotonic() + 30.0
    while time.monotonic() < deadline and not any(m.seq == 1 for m in fresh):
        fresh += s.wait(1, timeout=1.0)
    check(
        "restart: a new plant takes the dead one's publisher slot and numbers from 1",
        len(got) >= 5 and any(m.seq == 1 and m.applied == 0 and m.session == 0 for m in fresh),
        {"before": seqs(got)[:5], "after": seqs(fresh)[:5]},
    )
    second.send_signal(signal.SIGTERM)
    _, err = second.communicate(timeout=10)
    return err


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", required=True)
    ap.add_argument("--prefix", required=True)
    ap.add_argument("--root", required=True)
    ap.add_argument("--file-prefix", required=True)
    ap.add_argument("--mutate", default=None)
    ap.add_argument("--only", default=None, help="lockstep | realtime | restart")
    a = ap.parse_args()
    plant_dir = Path(a.dir)
    plant_dir.mkdir(parents=True, exist_ok=True)
    check = Checks()
    logs = {}
    for name, run, publishers in (
        ("lockstep", lockstep_checks, 2),
        ("realtime", realtime_checks, 2),
        ("restart", restart_checks, 1),
    ):
        if a.only and a.only != name:
            continue
        suffix = {"lockstep": "ls", "realtime": "rt", "restart": "rs"}[name]
        settings = ipc.IpcSettings(f"{a.prefix}-{suffix}", a.root, f"{a.file_prefix}{suffix}_")
        s = StandIn(settings, publishers)
        try:
            logs[name] = run(check, s, settings, plant_dir, a.mutate)
        except Exception as e:  # a broken plant must fail the checks, not hang or crash the fixture
            check(f"{name}: fixture ran to the end", False, repr(e))
    json.dump({"checks": check.items, "logs": {k: v[-3000:] for k, v in logs.items()}}, sys.stdout)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())

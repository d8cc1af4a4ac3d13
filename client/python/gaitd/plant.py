"""Attach a hand or a simulator to gaitd: subclass :class:`Plant`.

The base class implements ``shm_schema/PLANT-GUIDE.md`` so that a subclass
only says what its hand does::

    class MyHand(Plant):
        def initial_setpoint(self): ...   # the grasp it starts in (e.g. hand.paper_start)
        def apply(self, setpoint): ...    # command the fingertips
        def step(self, dt): ...           # simulators only: advance dt seconds
        def measure(self): ...            # -> setpoint.Measured

    MyHand(config.load("gaitd.toml")).run()

A hand of finger chains (the daemon's ``[hand] kind = "chains"``) gets each
finger's joint setpoint in ``setpoint.fingers[k].joints``
(:class:`~gaitd.setpoint.JointSetpoint`: position, velocity, feed-forward
torque, gains; ``setpoint.joints`` is true) and reports its joints in
``FingerMeasured.joints`` (:class:`~gaitd.setpoint.JointsMeasured`): the
daemon makes the tips from them (``shm_schema/PLANT-GUIDE.md``, "A hand of
finger chains").

What the base class does, and why:

* opens the four plant services the daemon created (``plant/command``
  subscriber, ``plant/measurement`` publisher, ``plant/commanded``
  listener, ``plant/measured`` notifier), retrying while they do not exist
  yet or while a dead predecessor still holds the publisher slot (the
  daemon's housekeeping frees it about once a second; the plant also runs
  dead-node cleanup itself);
* numbers measurements from 1, stamps them, echoes the session and the
  sequence number of the last command it applied;
* checks every command before using it (codes, padding, finiteness, unit
  quaternions, period, timing, echo numbers): a command that fails is not
  applied, the hand holds its last setpoint, and the reason is counted and
  printed (rate-limited);
* keeps the grasp whenever the daemon is not driving: before the first
  command, on HOLD, without ENABLE, after a bad command and while the
  daemon is gone, ``apply`` receives the last setpoint with zero velocity;
* runs one of the two timings: **lockstep** — publish measurement k,
  notify, wait (bounded in wall-clock time) for the command answering k,
  apply, step one period, measure k + 1; if no answer comes within
  ``lockstep_timeout`` it holds and publishes every period until the
  daemon answers again — and **realtime** — on absolute wall-clock
  deadlines every period: take the newest command, apply, step, measure,
  publish (missed periods are counted and skipped, never caught up in a burst).

Plant time (``time_ns``): simulated time in lockstep (measurement k at
k · period, so the daemon's clock is the plant's); CLOCK_MONOTONIC in
realtime (both run on the wall clock).
"""

from __future__ import annotations

import signal
import sys
import time
from dataclasses import dataclass, field
from typing import Any
from collections.abc import Callable

from . import ipc
from .config import DaemonConfig
from .schema import PLANT_EVENT_ID, CommandFlags, PlantCommand, PlantFault, PlantMeasurement, ServiceNames
from .setpoint import (
    BadCommand,
    Measured,
    Setpoint,
    check_header,
    check_setpoint,
    decode_command,
    encode_measurement,
    measured_problem,
)

LOCKSTEP = "lockstep"
REALTIME = "realtime"
#: Longest single block on the listener: bounds the effect of a lost wake-up and of a signal.
MAX_BLOCK = 0.1
#: Seconds between progress lines on stderr.
REPORT_EVERY = 10.0


@dataclass
class PlantStats:
    """What a run did (printed at the end; tests read it)."""

    steps: int = 0
    measurements: int = 0
    commands: int = 0
    applied: int = 0
    rejected: int = 0
    last_rejection: str = ""
    timeouts: int = 0
    overruns: int = 0
    wall_s: float = 0.0
    compute_s: float = 0.0
    sim_s: float = 0.0
    sessions: list[int] = field(default_factory=list)

    @property
    def real_time_factor(self) -> float:
        """Simulated seconds per wall-clock second."""
        return self.sim_s / self.wall_s if self.wall_s > 0 else 0.0

    def summary(self) -> dict[str, Any]:
        """The counters and timing as JSON-ready values (a plant's ``--report``)."""
        return {
            "steps": self.steps,
            "measurements": self.measurements,
            "commands": self.commands,
            "applied": self.applied,
            "rejected": self.rejected,
            "last_rejection": self.last_rejection,
            "lockstep_timeouts": self.timeouts,
            "overruns": self.overruns,
            "simulated_s": self.sim_s,
            "wall_s": self.wall_s,
            "real_time_factor": self.real_time_factor,
            "compute_us_per_step": 1e6 * self.compute_s / max(1, self.steps),
            "sessions": self.sessions,
        }

    def line(self) -> str:
        """One human line."""
        return (
            f"{self.sim_s:.3f} s simulated in {self.wall_s:.3f} s wall: real-time factor "
            f"{self.real_time_factor:.2f} (compute {1e6 * self.compute_s / max(1, self.steps):.0f} µs/step); "
            f"{self.measurements} measurements, {self.commands} commands, {self.applied} applied, "
            f"{self.rejected} rejected, {self.timeouts} lockstep timeouts, {self.overruns} overruns"
        )


class Exchange:
    """The protocol's bookkeeping, without any IPC (so that it can be tested on its own).

    Tracks the measurement numbers, the daemon session and the last command
    taken, and decides for each received command whether it is new, stale
    or invalid.
    """

    def __init__(self, period_ns: int, lockstep: bool):
        self.period_ns = period_ns
        self.lockstep = lockstep
        self.seq = 0  # last measurement sent
        self.time_ns = 0  # its plant time
        self.session = 0  # session of the last command applied
        self.applied = 0  # seq of the last command applied
        self._last_cmd: tuple[int, int] = (0, 0)  # (session, seq) of the newest command taken

    def next_measurement(self, time_ns: int) -> int:
        """Numbers a new measurement taken at ``time_ns`` (strictly later than the last one)."""
        if time_ns <= self.time_ns:
            time_ns = self.time_ns + 1
        self.seq += 1
        self.time_ns = time_ns
        return self.seq

    def take(self, c: PlantCommand, check: Callable[[Setpoint], str | None] | None = None) -> Setpoint | None:
        """The setpoint of a new, valid command; None for a stale or repeated one.

        Raises :class:`BadCommand` for a command that must not be applied
        (``check`` adds the plant's own limits). A command without ENABLE or
        with HOLD carries no usable setpoint: only its header is checked and
        the result has no fingers (the hand holds). A command of another
        session (a restarted daemon) is new. Only a taken command is echoed
        in ``applied``.
        """
        check_header(c, self.period_ns, self.seq, self.lockstep)
        if c.session == self._last_cmd[0] and c.seq <= self._last_cmd[1]:
            return None
        if self.lockstep and c.answers >= 1 and c.answers == self.seq:
            want = self.time_ns + self.period_ns
            if c.target_time_ns != want:
                raise BadCommand(f"target_time_ns {c.target_time_ns}, measurement {c.answers} + period is {want}")
        if c.flags & CommandFlags.ENABLE and not c.flags & CommandFlags.HOLD:
            check_setpoint(c)
            sp = decode_command(c)
            why = check(sp) if check is not None else None
            if why is not None:
                raise BadCommand(why)
        else:
            sp = Setpoint(
                fingers=(),
                flags=c.flags,
                session=c.session,
                seq=c.seq,
                answers=c.answers,
                target_time_ns=c.target_time_ns,
                period_ns=c.period_ns,
            )
        self._last_cmd = (c.session, c.seq)
        self.session, self.applied = c.session, c.seq
        return sp


class Plant:
    """Base class of every plant; see the module docs. Subclasses set ``simulated`` for a simulator."""

    #: The plant is a simulator (state bit SIMULATED; plant clock = simulated time).
    simulated = False

    def __init__(
        self,
        config: DaemonConfig,
        timing: str | None = None,
        lockstep_timeout: float | None = None,
        open_timeout: float = 30.0,
        node_name: str = "gaitd-plant",
        settings: ipc.IpcSettings | None = None,
        log: Callable[[str], None] | None = None,
    ):
        self.config = config
        self.timing = timing or config.plant.timing
        if self.timing not in (LOCKSTEP, REALTIME):
            raise ValueError(f"timing {self.timing!r}: lockstep or realtime")
        self.period_ns = config.period_ns
        self.period = self.period_ns * 1e-9
        self.lockstep_timeout = (
            config.plant.lockstep_timeout_ms / 1000.0 if lockstep_timeout is None else lockstep_timeout
        )
        self.open_timeout = open_timeout
        self.node_name = node_name
        self.settings = settings
        self.stats = PlantStats()
        self.exchange = Exchange(self.period_ns, self.timing == LOCKSTEP)
        self._log = log or (lambda s: print(s, file=sys.stderr, flush=True))
        self._stop = False
        self._held: Setpoint | None = None
        self._still: Setpoint | None = None
        self._last_good: Measured | None = None
        self._last_complaint = 0.0
        self._ports: dict[str, Any] = {}

    # ------------------------------------------------------------------ the subclass's part

    def initial_setpoint(self) -> Setpoint:
        """The grasp the hand starts in and holds until the first command (e.g. ``hand.paper_start``)."""
        raise NotImplementedError

    def apply(self, setpoint: Setpoint) -> None:
        """Commands the fingertips: a checked setpoint, or the held one (velocities zero)."""
        raise NotImplementedError

    def step(self, dt: float) -> None:
        """Simulators: advance the simulation by ``dt`` seconds. A real hand moves on its own."""

    def measure(self) -> Measured:
        """The hand's state now."""
        raise NotImplementedError

    def check(self, setpoint: Setpoint) -> str | None:
        """Plant-specific limits (reach, grip); a string says why ``setpoint`` must not be applied."""
        return None

    # ------------------------------------------------------------------ running

    def stop(self) -> None:
        """Ends :meth:`run` after the current step (safe from a signal handler)."""
        self._stop = True

    def run(self, max_steps: int | None = None, install_signals: bool = True) -> PlantStats:
        """Runs the exchange until :meth:`stop`, SIGTERM/SIGINT, or ``max_steps`` steps."""
        if install_signals:
            for s in (signal.SIGTERM, signal.SIGINT):
                signal.signal(s, lambda *_: self.stop())
        self._held = self.initial_setpoint().still()
        self.apply(self._held)
        try:
            self._open()
        except ipc.Cancelled:
            self._log("plant: stopped before the daemon's services appeared")
            self._close()
            return self.stats
        t0 = time.perf_counter()
        self._report_at = t0 + REPORT_EVERY
        try:
            if self.timing == LOCKSTEP:
                self._run_lockstep(max_steps, t0)
            else:
                self._run_realtime(max_steps, t0)
        finally:
            self.stats.wall_s = time.perf_counter() - t0
            self._log(f"plant: {self.stats.line()}")
            self._close()
        return self.stats

    def _open(self) -> None:
        iox2 = ipc.iceoryx2()
        settings = self.settings or self.config.ipc_settings()
        names = ServiceNames(settings.service_prefix)
        node = ipc.create_node(settings, self.node_name)
        self._ports["node"] = node

        def attempt(make: Callable[[], Any]) -> Callable[[], Any]:
            def go() -> Any:
                try:
                    return make()
                except Exception:
                    # A dead predecessor's ports keep their slots until cleaned up.
                    node.try_cleanup_dead_nodes()
                    raise

            return go

        def pubsub(name: str, payload: type) -> Any:
            sn = ipc.service_name(name)
            return node.service_builder(sn).publish_subscribe(payload).open()

        def event(name: str) -> Any:
            return node.service_builder(ipc.service_name(name)).event().open()

        def get(what: str, make: Callable[[], Any]) -> Any:
            # SIGTERM while waiting for the daemon ends the wait (ipc.Cancelled).
            return ipc.retry(what, attempt(make), self.open_timeout, cancelled=lambda: self._stop)

        self._log(f"plant: waiting for gaitd's plant services under {settings.service_prefix!r} ({settings.root_path})")
        hint = '(is gaitd running with [plant] kind = "shm" and this [ipc] namespace?)'
        # A daemon of another schema says so (its services' types would only be "incompatible").
        from .client import daemon_schema

        daemon_schema(node, names)
        cmd = get(f"{names.plant_command} {hint}", lambda: pubsub(names.plant_command, PlantCommand))
        meas = get(names.plant_measurement, lambda: pubsub(names.plant_measurement, PlantMeasurement))
        commanded = get(names.plant_commanded, lambda: event(names.plant_commanded))
        measured = get(names.plant_measured, lambda: event(names.plant_measured))
        eid = iox2.EventId.new(PLANT_EVENT_ID)
        self._ports["sub"] = get("plant command subscriber", lambda: cmd.subscriber_builder().buffer_size(2).create())
        self._ports["pub"] = get(
            "plant measurement publisher (a dead plant may still hold its slot)",
            lambda: meas.publisher_builder().max_loaned_samples(1).create(),
        )
        self._ports["listener"] = get("plant commanded listener", lambda: commanded.listener_builder().create())
        self._ports["notifier"] = get(
            "plant measured notifier", lambda: measured.notifier_builder().default_event_id(eid).create()
        )
        self._duration = iox2.Duration
        self._log(f"plant: attached ({self.timing}, period {self.period_ns} ns)")

    def _close(self) -> None:
        for k in ("sub", "pub", "listener", "notifier"):
            p = self._ports.pop(k, None)
            if p is not None:
                p.delete()
        self._ports.clear()

    # ------------------------------------------------------------------ one exchange

    def _complain(self, text: str) -> None:
        now = time.monotonic()
        if now - self._last_complaint >= 1.0:
            self._last_complaint = now
            self._log(f"plant: {text}")

    def _receive(self) -> tuple[Setpoint | None, bool]:
        """Drains the command subscriber: (newest new command, whether one answered the newest measurement)."""
        newest, answered = None, False
        sub = self._ports["sub"]
        while (s := sub.receive()) is not None:
            c = PlantCommand.from_buffer_copy(s.payload().contents)
            del s
            self.stats.commands += 1
            try:
                sp = self.exchange.take(c, self.check)
            except BadCommand as e:
                self.stats.rejected += 1
                self.stats.last_rejection = str(e)
                self._complain(f"command {c.seq} not applied: {e}")
                # In lockstep a refused answer still ends the wait: the hand holds, time goes on.
                answered |= c.session != 0 and c.answers == self.exchange.seq
                continue
            if sp is None:
                continue
            if sp.session not in self.stats.sessions:
                self.stats.sessions.append(sp.session)
            answered |= sp.answers == self.exchange.seq
            newest = sp
        return newest, answered

    def _take(self, sp: Setpoint | None) -> None:
        """Makes ``sp`` the hand's setpoint; without one (HOLD, no ENABLE) the hand keeps holding."""
        if sp is None or not sp.fingers:
            return
        self._held = sp
        self.stats.applied += 1

    def _advance(self) -> None:
        """Applies the current setpoint and steps one period."""
        t = time.perf_counter()
        sp = self._held
        if sp is None:
            raise RuntimeError("no setpoint to apply: run() starts from initial_setpoint()")
        self.apply(sp)
        self.step(self.period)
        # From now on, unless a new command comes, hold this pose still.
        # (A held setpoint is already still: made once per new command, not every step.)
        if sp is not self._still:
            self._still = sp.still()
        self._held = self._still
        self.stats.steps += 1
        self.stats.sim_s += self.period
        self.stats.compute_s += time.perf_counter() - t

    def _publish(self, time_ns: int) -> None:
        t = time.perf_counter()
        m = self.measure()
        problem = measured_problem(m)
        if problem is not None:
            self._complain(f"measurement unusable ({problem}): reporting a fault")
            fault = PlantFault.Diverged if self.simulated else PlantFault.Other
            base = self._last_good or m
            m = Measured(base.object_q, base.fingers, base.object_omega, base.object_center, fault, base.object_age)
            if measured_problem(m) is not None:
                raise RuntimeError(f"plant measurement unusable from the start: {problem}")
        else:
            self._last_good = m
        seq = self.exchange.next_measurement(time_ns)
        ex = self.exchange
        out = encode_measurement(m, seq, ex.time_ns, ex.session, ex.applied, self.simulated)
        self._ports["pub"].loan_uninit().write_payload(out).send()
        self._ports["notifier"].notify()
        self.stats.measurements += 1
        self.stats.compute_s += time.perf_counter() - t
        now = time.perf_counter()
        if now >= self._report_at:
            self._report_at = now + REPORT_EVERY
            self.stats.wall_s = now - self._t0
            self._log(f"plant: {self.stats.line()}")

    def _block(self, seconds: float) -> None:
        """Sleeps on the ``commanded`` listener (a command wakes it) for at most ``seconds``."""
        if seconds <= 0:
            return
        try:
            self._ports["listener"].timed_wait(self._duration.from_secs_f64(min(seconds, MAX_BLOCK)))
        except Exception as e:  # a signal interrupts the wait; the handler has asked to stop
            if "Interrupt" not in repr(e):
                raise

    # ------------------------------------------------------------------ timings

    def _run_lockstep(self, max_steps: int | None, t0: float) -> None:
        self._t0 = t0
        sim_ns = self.period_ns  # measurement 1 at one period: no zero time stamp
        absent = False
        while not self._stop:
            self._publish(sim_ns)
            k = self.exchange.seq
            deadline = time.monotonic() + (self.period if absent else self.lockstep_timeout)
            answered = False
            while not self._stop:
                sp, answered = self._receive()
                self._take(sp)
                if answered:
                    break
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                self._block(left)
            if self._stop:
                break
            if not answered:
                if not absent:
                    self.stats.timeouts += 1
                    self._log(
                        f"plant: no command answering measurement {k} within "
                        f"{self.lockstep_timeout:g} s: holding the grasp, publishing every period"
                    )
                absent = True
            elif absent:
                self._log(f"plant: the daemon answers again (measurement {k})")
                absent = False
            self._advance()
            sim_ns += self.period_ns
            if max_steps is not None and self.stats.steps >= max_steps:
                break

    def _run_realtime(self, max_steps: int | None, t0: float) -> None:
        self._t0 = t0
        period = self.period
        self._publish(ipc.monotonic_ns())
        next_t = time.monotonic() + period
        while not self._stop:
            now = time.monotonic()
            while now < next_t and not self._stop:
                # Sleep to the deadline; wake on commands only to keep the newest.
                time.sleep(min(next_t - now, MAX_BLOCK))
                now = time.monotonic()
            if now - next_t >= period:
                missed = int((now - next_t) / period)
                self.stats.overruns += missed
                next_t += missed * period
            next_t += period
            sp, _ = self._receive()
            self._take(sp)
            self._advance()
            self._publish(ipc.monotonic_ns())
            if max_steps is not None and self.stats.steps >= max_steps:
                break

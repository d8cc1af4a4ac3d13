"""A synchronous Python client of gaitd, the counterpart of the Rust ``gaitd_client``.

It opens the services the daemon created (never creates them), matches
answers by ``(client_id, request_id)``, keeps the newest status and a
backlog of events, and blocks on the daemon's ``notify`` event service
instead of spinning. Every received sample is copied out of shared memory
and its codes are checked before use (bad samples are counted and dropped):
the daemon's bytes are not trusted blindly.

Example::

    from gaitd.client import Client
    with Client.connect() as c:                 # GAITD_* environment, then defaults
        ticket = c.turn((0, 0, 1), math.pi)     # half a turn about z
        outcome = c.wait_outcome(ticket.goal_id, timeout=30)
"""

from __future__ import annotations

import collections
import math
import os
import time
from dataclasses import dataclass
from typing import Any, TypeVar
from collections.abc import Callable, Iterator, Sequence

from . import ipc
from .schema import (
    Answer,
    AnswerCode,
    Command,
    CommandKind,
    DaemonState,
    Event,
    EventKind,
    FaultCode,
    FingerPhase,
    GoalFrame,
    GoalState,
    GraspState,
    LimitKind,
    LimitOrder,
    MeasuredMask,
    Payload,
    Phase,
    ReasonCode,
    SCHEMA_VERSION,
    ServiceNames,
    Status,
    VERSION_ATTRIBUTE_BUILD,
    VERSION_ATTRIBUTE_SCHEMA,
    decode,
    limit_bit,
)

#: Longest single block on the listener: bounds the effect of a lost wake-up.
MAX_BLOCK = 0.1
#: Events kept when nobody reads them.
EVENT_BACKLOG = 4096


_T = TypeVar("_T")


class ClientError(Exception):
    """The daemon is not there, timed out, or refused the connection."""


class NoDaemon(ClientError):
    """No fresh status within the connect timeout."""


class Timeout(ClientError):
    """A wait ran out."""


class SchemaMismatch(ClientError):
    """The daemon's services carry another schema version (type name, size or alignment)."""


def daemon_schema(node: Any, names: ServiceNames) -> tuple[str, str] | None:
    """The daemon's (schema, build) from its ``version`` service, None without one.

    Raises :class:`SchemaMismatch` naming both versions when the schema is not this
    package's (the services' type names would only say "incompatible").
    """
    iox2 = ipc.iceoryx2()
    try:
        factory = node.service_builder(ipc.service_name(names.version)).event().open()
    except iox2.EventOpenError as e:
        if "DoesNotExist" in repr(e):
            return None
        raise

    def value(key: str) -> str:
        found = factory.attributes.key_values(iox2.AttributeKey.new(key))
        return found[0].to_string() if found else "?"

    schema, build = value(VERSION_ATTRIBUTE_SCHEMA), value(VERSION_ATTRIBUTE_BUILD)
    if schema != str(SCHEMA_VERSION):
        raise SchemaMismatch(
            f"the daemon speaks schema v{schema} ({build}), this client v{SCHEMA_VERSION}: "
            f"use a client built for the daemon's schema (LAYOUT.md, Schema versions)"
        )
    return schema, build


@dataclass(frozen=True)
class Reply:
    """The daemon's answer to one command."""

    accepted: bool
    reason: ReasonCode
    goal_id: int
    tick: int
    request_id: int

    @property
    def code(self) -> str:
        """``"Accepted"`` or ``"Rejected"``."""
        return "Accepted" if self.accepted else "Rejected"


@dataclass(frozen=True)
class Outcome:
    """How a goal ended."""

    goal_id: int
    state: GoalState
    reason: ReasonCode


def _status_ok(s: Status) -> bool:
    tables = [
        (DaemonState, s.daemon_state),
        (Phase, s.phase),
        (FaultCode, s.fault),
        (GraspState, s.grasp),
        (GoalState, s.goal.state),
        (ReasonCode, s.goal.reason),
    ] + [(FingerPhase, f.state) for f in s.fingers]
    if any(decode(t, v) is None for t, v in tables):
        return False
    if any(f.measured_contact > 1 for f in s.fingers):
        return False
    return int(s.measured_mask) & ~int(MeasuredMask(15)) == 0


def _event_ok(e: Event) -> bool:
    tables = [(EventKind, e.kind), (GoalState, e.state), (ReasonCode, e.reason), (FaultCode, e.fault)]
    return all(decode(t, v) is not None for t, v in tables) and (e.finger == 0xFFFF_FFFF or e.finger < 3)


def _answer_ok(a: Answer) -> bool:
    return decode(AnswerCode, a.code) is not None and decode(ReasonCode, a.reason) is not None


def quat_from_axis_angle(axis: Sequence[float], angle: float) -> tuple[float, float, float, float]:
    """The unit quaternion of a rotation by ``angle`` [rad] about ``axis``."""
    n = math.sqrt(sum(a * a for a in axis))
    if not (math.isfinite(n) and n > 1e-12 and math.isfinite(angle)):
        raise ValueError("axis must be finite and non-zero, angle finite")
    s, c = math.sin(angle / 2), math.cos(angle / 2)
    return (c, s * axis[0] / n, s * axis[1] / n, s * axis[2] / n)


class Client:
    """A connection to a running gaitd (bound to the creating thread, like iceoryx2 ports)."""

    def __init__(self, settings: ipc.IpcSettings, timeout: float, max_status_age: float, node_name: str):
        self.settings = settings
        self.timeout = timeout
        self.max_status_age = max_status_age
        self.node_name = node_name
        self.client_id = int.from_bytes(os.urandom(8), "little") | 1
        self.bad_samples = 0
        self.reconnects = 0
        self._next_request = 1
        self._next_goal = 1
        self._last_status: Status | None = None
        self._events: collections.deque[Event] = collections.deque(maxlen=EVENT_BACKLOG)
        self._answers: dict[int, Answer] = {}
        self._outstanding: set[int] = set()
        self._open(timeout)

    # ------------------------------------------------------------------ connection

    @classmethod
    def connect(
        cls,
        prefix: str | None = None,
        root_path: str | None = None,
        file_prefix: str | None = None,
        iceoryx2_config: str | None = None,
        timeout: float = 2.0,
        max_status_age: float = 1.0,
        node_name: str = "gaitd-py-client",
    ) -> Client:
        """Opens the daemon's services and waits for a fresh status, within ``timeout`` [s].

        Unset values come from ``GAITD_PREFIX``, ``GAITD_IPC_ROOT``,
        ``GAITD_IPC_FILE_PREFIX``, ``GAITD_IPC_CONFIG``, then the iceoryx2
        config file, then the defaults — as the daemon resolves them.
        """
        settings = ipc.resolve(prefix, root_path, file_prefix, iceoryx2_config)
        return cls(settings, timeout, max_status_age, node_name)

    def _open(self, timeout: float) -> None:
        iox2 = ipc.iceoryx2()
        names = ServiceNames(self.settings.service_prefix)
        deadline = ipc.monotonic_ns() + int(timeout * 1e9)
        self._node = ipc.create_node(self.settings, self.node_name)

        def open_pubsub(name: str, payload: type[Payload]) -> Any:
            sn = ipc.service_name(name)
            while True:
                try:
                    return self._node.service_builder(sn).publish_subscribe(payload).open()
                except iox2.PublishSubscribeOpenError as e:
                    text = repr(e)
                    if "IncompatibleTypes" in text:
                        raise SchemaMismatch(
                            f"service {name} does not carry {payload.type_name()} "
                            f"(the daemon speaks another schema version)"
                        ) from e
                    if "DoesNotExist" not in text or ipc.monotonic_ns() >= deadline:
                        raise NoDaemon(
                            f"no gaitd with prefix {self.settings.service_prefix!r} under "
                            f"{self.settings.root_path} ({name}: {text})"
                        ) from e
                    time.sleep(0.01)

        def open_event(name: str) -> Any:
            sn = ipc.service_name(name)
            return ipc.retry(
                f"open {name}",
                lambda: self._node.service_builder(sn).event().open(),
                max(0.0, (deadline - ipc.monotonic_ns()) / 1e9),
            )

        # Which schema the daemon speaks, before a type name says "incompatible".
        versioned = daemon_schema(self._node, names) is not None
        try:
            commands = open_pubsub(names.commands, Command)
        except SchemaMismatch as e:
            if versioned:
                raise
            raise SchemaMismatch(
                f"the daemon speaks schema v3 or older (it has no version service), "
                f"this client v{SCHEMA_VERSION}: use a client built for the daemon's schema"
            ) from e
        answers = open_pubsub(names.answers, Answer)
        status = open_pubsub(names.status, Status)
        events = open_pubsub(names.events, Event)
        notify = open_event(names.notify)
        # A full daemon queue refuses the send instead of blocking this client.
        self._commands = (
            commands.publisher_builder()
            .backpressure_strategy(iox2.BackpressureStrategy.DiscardData)
            .max_loaned_samples(1)
            .create()
        )
        self._answers_sub = answers.subscriber_builder().create()
        # Latest value only: one receive per pump is the newest status.
        self._status_sub = status.subscriber_builder().buffer_size(1).create()
        self._events_sub = events.subscriber_builder().create()
        self._listener = notify.listener_builder().create()
        self._wait_fresh_status(timeout)

    def close(self) -> None:
        """Releases the ports and the node."""
        for port in ("_commands", "_answers_sub", "_status_sub", "_events_sub", "_listener"):
            p = getattr(self, port, None)
            if p is not None:
                p.delete()
                setattr(self, port, None)
        self._node = None

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def reconnect(self, timeout: float | None = None) -> None:
        """Drops the connection and opens it again (e.g. after a daemon restart)."""
        self.close()
        self._last_status = None
        self._answers.clear()
        self._outstanding.clear()
        self.reconnects += 1
        self._open(self.timeout if timeout is None else timeout)

    # ------------------------------------------------------------------ receiving

    def _pump(self) -> None:
        while (s := self._events_sub.receive()) is not None:
            e = Event.from_buffer_copy(s.payload().contents)
            if _event_ok(e):
                self._events.append(e)
            else:
                self.bad_samples += 1
        while (s := self._answers_sub.receive()) is not None:
            a = Answer.from_buffer_copy(s.payload().contents)
            # Answers to every client arrive here: keep ours.
            if a.client_id == self.client_id and a.request_id in self._outstanding:
                if _answer_ok(a):
                    self._answers[a.request_id] = a
                else:
                    self.bad_samples += 1
        if (s := self._status_sub.receive()) is not None:
            st = Status.from_buffer_copy(s.payload().contents)
            if _status_ok(st):
                self._last_status = st
            else:
                self.bad_samples += 1

    def _wait_until(self, timeout: float, what: str, check: Callable[[], _T | None]) -> _T:
        """Blocks on the daemon's notifications (not spinning) until ``check()`` yields a value."""
        deadline = ipc.monotonic_ns() + int(timeout * 1e9)
        iox2 = ipc.iceoryx2()
        while True:
            self._pump()
            v = check()
            if v is not None:
                return v
            left = (deadline - ipc.monotonic_ns()) / 1e9
            if left <= 0:
                raise Timeout(f"timed out after {timeout:g} s waiting for {what}")
            self._listener.timed_wait(iox2.Duration.from_secs_f64(min(left, MAX_BLOCK)))

    def _fresh(self, s: Status) -> bool:
        return ipc.monotonic_ns() - int(s.publish_time_ns) <= int(self.max_status_age * 1e9)

    def _wait_fresh_status(self, timeout: float) -> Status:
        try:
            return self._wait_until(
                timeout,
                "a fresh status",
                lambda: self._last_status if self._last_status is not None and self._fresh(self._last_status) else None,
            )
        except Timeout as e:
            raise NoDaemon(
                f"no fresh status from gaitd (prefix {self.settings.service_prefix!r}, root "
                f"{self.settings.root_path}) within {timeout:g} s"
            ) from e

    def daemon_alive(self) -> bool:
        """Whether the daemon published a status recently."""
        self._pump()
        return self._last_status is not None and self._fresh(self._last_status)

    # ------------------------------------------------------------------ status and events

    def latest_status(self) -> Status | None:
        """The newest status received so far, without waiting."""
        self._pump()
        return self._last_status

    def wait_status(self, timeout: float = 1.0) -> Status:
        """Waits for a status newer than the one seen last."""
        self._pump()
        seen = (self._last_status.instance, self._last_status.tick) if self._last_status else None
        return self._wait_until(
            timeout,
            "a new status",
            lambda: (
                self._last_status
                if self._last_status is not None and (self._last_status.instance, self._last_status.tick) != seen
                else None
            ),
        )

    def events(self) -> Iterator[Event]:
        """Every event received so far (oldest first), without waiting."""
        self._pump()
        while self._events:
            yield self._events.popleft()

    def next_event(self, timeout: float = 1.0) -> Event | None:
        """The next event, or None after ``timeout``."""
        try:
            return self._wait_until(timeout, "an event", lambda: self._events.popleft() if self._events else None)
        except Timeout:
            return None

    # ------------------------------------------------------------------ commands

    def send_command(self, cmd: Command) -> int:
        """Sends ``cmd`` as it is (only ``request_id`` filled in) and returns the request id.

        For tools and tests that send anything; see :meth:`goal`, :meth:`hold`, … otherwise.
        """
        cmd.request_id = self._next_request
        self._next_request += 1
        self._outstanding.add(cmd.request_id)
        delivered = self._commands.loan_uninit().write_payload(cmd).send()
        if delivered == 0:
            self._outstanding.discard(cmd.request_id)
            if self.daemon_alive():
                raise ClientError("the daemon's command queue for this client is full")
            raise NoDaemon("no daemon subscribed to the commands service")
        return int(cmd.request_id)

    def wait_answer(self, request_id: int, timeout: float | None = None) -> Reply:
        """Waits for the answer to ``request_id``."""
        timeout = self.timeout if timeout is None else timeout
        try:
            a = self._wait_until(timeout, "the daemon's answer", lambda: self._answers.pop(request_id, None))
        finally:
            self._outstanding.discard(request_id)
        return Reply(a.code == AnswerCode.Accepted, ReasonCode(a.reason), a.goal_id, a.tick, a.request_id)

    def command(self, cmd: Command, timeout: float | None = None) -> Reply:
        """Sends a command and waits for its answer, reconnecting once if the daemon restarted."""
        if not self.daemon_alive():
            self.reconnect(timeout)
        try:
            rid = self.send_command(cmd)
        except NoDaemon:
            self.reconnect(timeout)
            rid = self.send_command(cmd)
        return self.wait_answer(rid, timeout)

    def _goal(
        self,
        frame: GoalFrame,
        target: Sequence[float],
        limits: dict[tuple[LimitKind, LimitOrder], float] | None,
        goal_id: int | None,
    ) -> Command:
        if goal_id is None:
            goal_id = self._next_goal
            self._next_goal += 1
        c = Command(kind=CommandKind.Goal, frame=frame, client_id=self.client_id, goal_id=goal_id)
        for i, v in enumerate(target):
            c.target[i] = float(v)
        for (kind, order), value in (limits or {}).items():
            c.limit_mask |= limit_bit(LimitKind(kind), LimitOrder(order))
            slot = (c.object_limits, c.fingertip_limits, c.rolling_limits)[int(kind)]
            setattr(slot, LimitOrder(order).name.lower(), float(value))
        return c

    def goal(
        self,
        target: Sequence[float],
        frame: GoalFrame = GoalFrame.Absolute,
        limits: dict[tuple[LimitKind, LimitOrder], float] | None = None,
        goal_id: int | None = None,
        timeout: float | None = None,
    ) -> Reply:
        """Sends a reorientation goal (a new goal id unless given) and waits for its answer.

        ``target``: the quaternion [w, x, y, z] (Absolute, Relative) or
        ``[angle, x, y, z]`` (AxisAngle). ``limits``: overrides that may only
        lower the configured limits, e.g. ``{(LimitKind.Object, LimitOrder.Velocity): 0.5}``.
        """
        return self.command(self._goal(frame, target, limits, goal_id), timeout)

    def turn(self, axis: Sequence[float], angle: float, timeout: float | None = None) -> Reply:
        """Turns the object by ``angle`` [rad] about the hand-frame ``axis`` (2π is a full turn)."""
        n = math.sqrt(sum(a * a for a in axis))
        return self.goal((angle, axis[0] / n, axis[1] / n, axis[2] / n), GoalFrame.AxisAngle, timeout=timeout)

    def cancel(self, goal_id: int = 0, timeout: float | None = None) -> Reply:
        """Cancels ``goal_id`` (0: whichever goal is active)."""
        return self.command(Command(kind=CommandKind.Cancel, client_id=self.client_id, goal_id=goal_id), timeout)

    def hold(self, timeout: float | None = None) -> Reply:
        """Stops any motion and holds the grasp."""
        return self.command(Command(kind=CommandKind.Hold, client_id=self.client_id), timeout)

    def reset(self, timeout: float | None = None) -> Reply:
        """Clears a fault."""
        return self.command(Command(kind=CommandKind.Reset, client_id=self.client_id), timeout)

    def wait_outcome(self, goal_id: int, timeout: float = 60.0) -> Outcome:
        """Waits until this client's goal ``goal_id`` reaches a terminal state (events, else status)."""
        me = self.client_id

        def check() -> Outcome | None:
            for e in self._events:
                if (
                    e.kind == EventKind.GoalTransition
                    and (e.client_id, e.goal_id) == (me, goal_id)
                    and GoalState(e.state).terminal
                ):
                    return Outcome(goal_id, GoalState(e.state), ReasonCode(e.reason))
            s = self._last_status
            if (
                s is not None
                and (s.goal.client_id, s.goal.goal_id) == (me, goal_id)
                and GoalState(s.goal.state).terminal
            ):
                return Outcome(goal_id, GoalState(s.goal.state), ReasonCode(s.goal.reason))
            return None

        return self._wait_until(timeout, f"goal {goal_id}'s outcome", check)

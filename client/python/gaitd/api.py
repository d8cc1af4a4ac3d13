"""The command API of a gaitd client, one implementation over any transport.

:class:`ClientApi` holds everything a client does with the daemon's
commands, status and events — goals, cancel, hold, reset, waiting for a
status, for events and for a goal's outcome — in terms of a
:class:`Transport`'s few primitives: send a command, get its answer, take
what arrived (the newest status and the events), wait until something may
have arrived. Two transports implement them: iceoryx2 on the daemon's host
(:class:`gaitd.client.Client`) and Zenoh through ``gaitd-bridge`` from
another host (:class:`gaitd.remote.RemoteClient`).

A client is used from one thread (iceoryx2 ports belong to the thread that
created them); a transport that receives on threads of its own hands over
what arrived in :meth:`Transport.receive`.
"""

from __future__ import annotations

import collections
import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, Self, TypeVar

from . import ipc
from .schema import (
    MEASURED_MASK_ALL,
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
    Phase,
    ReasonCode,
    Status,
    decode,
    limit_bit,
)

#: Longest single block while waiting: bounds the effect of a lost wake-up.
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


class NotDelivered(ClientError):
    """A transport could not hand a command to the daemon (no subscriber took it)."""


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

    @staticmethod
    def of(a: Answer, request_id: int) -> Reply:
        """The reply an answer carries (its codes checked with :func:`answer_ok`)."""
        return Reply(a.code == AnswerCode.Accepted, ReasonCode(a.reason), int(a.goal_id), int(a.tick), request_id)


@dataclass(frozen=True)
class Outcome:
    """How a goal ended."""

    goal_id: int
    state: GoalState
    reason: ReasonCode


# --------------------------------------------------------------------------- sample checks


def status_ok(s: Status) -> bool:
    """Whether every code and flag of a status is one this package knows (never trust the bytes)."""
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
    return int(s.measured_mask) & ~MEASURED_MASK_ALL == 0


def event_ok(e: Event) -> bool:
    """Whether every code of an event is known and its finger is one of the three or none."""
    tables = [(EventKind, e.kind), (GoalState, e.state), (ReasonCode, e.reason), (FaultCode, e.fault)]
    return all(decode(t, v) is not None for t, v in tables) and (e.finger == 0xFFFF_FFFF or e.finger < 3)


def answer_ok(a: Answer) -> bool:
    """Whether the codes of an answer are known."""
    return decode(AnswerCode, a.code) is not None and decode(ReasonCode, a.reason) is not None


# --------------------------------------------------------------------------- transport


@dataclass
class Received:
    """What a transport received since it was last asked."""

    #: The newest status (codes checked), or None if none came.
    status: Status | None = None
    #: When that status was current, on this host's CLOCK_MONOTONIC [ns].
    status_time_ns: int = 0
    #: The events (codes checked, each once), oldest first.
    events: list[Event] = field(default_factory=list)


class Transport(ABC):
    """The primitives a client needs from its way to the daemon."""

    #: Samples dropped because their size, encoding or codes were wrong.
    bad_samples: int = 0
    #: Times the connection was made again (a restarted daemon or bridge).
    reconnects: int = 0

    @abstractmethod
    def send(self, cmd: Command) -> int:
        """Sends ``cmd`` with a new ``request_id`` filled in and returns that id.

        Raises :class:`NotDelivered` when nobody took it.
        """

    @abstractmethod
    def answer(self, request_id: int, timeout: float) -> Reply:
        """Waits for the daemon's answer to ``request_id``; raises :class:`Timeout` without one."""

    @abstractmethod
    def receive(self) -> Received:
        """The status and events that arrived since the last call, without waiting."""

    @abstractmethod
    def wait(self, seconds: float) -> None:
        """Blocks until something may have arrived, for at most ``seconds``."""

    @abstractmethod
    def close(self) -> None:
        """Releases what the transport holds (ports, sessions); idempotent."""


# --------------------------------------------------------------------------- the client


class ClientApi:
    """Commands, status and events of gaitd over a :class:`Transport` (see the module docs)."""

    def __init__(self, transport: Transport, client_id: int, timeout: float, max_status_age: float, first_goal: int):
        self._transport = transport
        #: This client's id in every command (the bridge uses the identity's own).
        self.client_id = client_id
        #: Default wait for an answer [s].
        self.timeout = timeout
        #: A status older than this [s] means the daemon is gone.
        self.max_status_age = max_status_age
        self._next_goal = first_goal
        self._status: Status | None = None
        self._status_time_ns = 0
        self._status_seq = 0
        self._events: collections.deque[Event] = collections.deque(maxlen=EVENT_BACKLOG)

    # ------------------------------------------------------------------ connection

    @property
    def bad_samples(self) -> int:
        """Received samples dropped because their codes (size, encoding) were wrong."""
        return self._transport.bad_samples

    @property
    def reconnects(self) -> int:
        """Times the connection was made again."""
        return self._transport.reconnects

    def close(self) -> None:
        """Releases the connection."""
        self._transport.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def _forget_status(self) -> None:
        """Drops the status seen (a new connection waits for a fresh one)."""
        self._status, self._status_time_ns = None, 0

    # ------------------------------------------------------------------ receiving

    def _take(self) -> None:
        got = self._transport.receive()
        if got.status is not None:
            self._status, self._status_time_ns = got.status, got.status_time_ns
            self._status_seq += 1
        self._events.extend(got.events)

    def _wait_until(self, timeout: float, what: str, check: Callable[[], _T | None]) -> _T:
        """Waits (on the transport, not spinning) until ``check()`` yields a value.

        Raises :class:`Timeout` after ``timeout`` [s].
        """
        deadline = ipc.monotonic_ns() + int(timeout * 1e9)
        while True:
            self._take()
            v = check()
            if v is not None:
                return v
            left = (deadline - ipc.monotonic_ns()) / 1e9
            if left <= 0:
                raise Timeout(f"timed out after {timeout:g} s waiting for {what}")
            self._transport.wait(min(left, MAX_BLOCK))

    def _fresh(self) -> bool:
        return self._status is not None and ipc.monotonic_ns() - self._status_time_ns <= int(self.max_status_age * 1e9)

    def _wait_fresh_status(self, timeout: float) -> Status:
        """A status at most ``max_status_age`` old; :class:`Timeout` if none comes within ``timeout``."""
        return self._wait_until(timeout, "a fresh status", lambda: self._status if self._fresh() else None)

    def daemon_alive(self) -> bool:
        """Whether the daemon's status arrived recently."""
        self._take()
        return self._fresh()

    # ------------------------------------------------------------------ status and events

    def latest_status(self) -> Status | None:
        """The newest status received so far, without waiting."""
        self._take()
        return self._status

    def wait_status(self, timeout: float = 1.0) -> Status:
        """Waits for a status newer than the one seen last."""
        self._take()
        seen = self._status_seq
        return self._wait_until(timeout, "a new status", lambda: self._status if self._status_seq != seen else None)

    def events(self) -> Iterator[Event]:
        """Every event received so far (oldest first), without waiting."""
        self._take()
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
        try:
            return self._transport.send(cmd)
        except NotDelivered as e:
            if self.daemon_alive():
                raise ClientError("the daemon's command queue for this client is full") from e
            raise NoDaemon("no daemon subscribed to the commands service") from e

    def wait_answer(self, request_id: int, timeout: float | None = None) -> Reply:
        """Waits for the answer to ``request_id``."""
        return self._transport.answer(request_id, self.timeout if timeout is None else timeout)

    def command(self, cmd: Command, timeout: float | None = None) -> Reply:
        """Sends a command and waits for its answer."""
        return self.wait_answer(self.send_command(cmd), timeout)

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
            s = self._status
            if (
                s is not None
                and (s.goal.client_id, s.goal.goal_id) == (me, goal_id)
                and GoalState(s.goal.state).terminal
            ):
                return Outcome(goal_id, GoalState(s.goal.state), ReasonCode(s.goal.reason))
            return None

        return self._wait_until(timeout, f"goal {goal_id}'s outcome", check)

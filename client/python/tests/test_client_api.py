"""The command API both clients share (``gaitd.api.ClientApi``), over an in-memory transport:
what each command puts on the wire, how answers, statuses and events are waited for, and which
received samples are refused."""

from __future__ import annotations

import math
import time
from collections.abc import Callable

import pytest

from gaitd import ipc
from gaitd.api import (
    ClientApi,
    ClientError,
    NoDaemon,
    NotDelivered,
    Outcome,
    Received,
    Reply,
    Timeout,
    Transport,
    answer_ok,
    event_ok,
    status_ok,
)
from gaitd.schema import (
    Answer,
    AnswerCode,
    Command,
    CommandKind,
    DaemonState,
    Event,
    EventKind,
    FingerPhase,
    GoalFrame,
    GoalState,
    LimitKind,
    LimitOrder,
    Phase,
    ReasonCode,
    Status,
    limit_bit,
)

ME = 0x1234_5679


class FakeTransport(Transport):
    """Answers every command at once (accepted unless its goal id is in ``refuse``); what "arrives"
    is queued in ``arrivals`` and taken one per :meth:`wait`."""

    def __init__(self) -> None:
        self.sent: list[Command] = []
        self.refuse: set[int] = set()
        self.undeliverable = False
        self.inbox = Received()
        self.arrivals: list[Received] = []
        self.waited = 0.0
        self.closed = False
        self.answer_timeouts: list[float] = []
        self._next_request = 100

    def send(self, cmd: Command) -> int:
        if self.undeliverable:
            raise NotDelivered("nobody took it")
        cmd.request_id = self._next_request
        self._next_request += 1
        self.sent.append(Command.from_buffer_copy(bytes(cmd)))  # as it went on the wire
        return int(cmd.request_id)

    def answer(self, request_id: int, timeout: float) -> Reply:
        self.answer_timeouts.append(timeout)
        cmd = next(c for c in self.sent if c.request_id == request_id)
        refused = cmd.goal_id in self.refuse
        a = Answer(
            client_id=cmd.client_id,
            request_id=request_id,
            goal_id=cmd.goal_id,
            command=cmd.kind,
            code=AnswerCode.Rejected if refused else AnswerCode.Accepted,
            reason=ReasonCode.DuplicateGoalId if refused else ReasonCode.None_,
            tick=42,
        )
        return Reply.of(a, request_id)

    def receive(self) -> Received:
        got, self.inbox = self.inbox, Received()
        return got

    def wait(self, seconds: float) -> None:
        self.waited += seconds
        if self.arrivals:
            self.inbox = self.arrivals.pop(0)
        else:
            time.sleep(seconds)

    def close(self) -> None:
        self.closed = True


def status(tick: int, goal_id: int = 0, state: GoalState = GoalState.None_, age_s: float = 0.0) -> Received:
    s = Status(tick=tick, daemon_state=DaemonState.Running, phase=Phase.Hold)
    for f in s.fingers:
        f.state = FingerPhase.Grasping
    s.goal.client_id, s.goal.goal_id, s.goal.state = ME, goal_id, state
    s.goal.reason = ReasonCode.Reached if state == GoalState.Succeeded else ReasonCode.None_
    return Received(s, ipc.monotonic_ns() - int(age_s * 1e9), [])


def event(seq: int, goal_id: int, state: GoalState, client_id: int = ME) -> Event:
    return Event(
        seq=seq,
        kind=EventKind.GoalTransition,
        finger=0xFFFF_FFFF,
        state=state,
        reason=ReasonCode.Reached if state == GoalState.Succeeded else ReasonCode.None_,
        goal_id=goal_id,
        client_id=client_id,
    )


def client(first_goal: int = 1) -> tuple[ClientApi, FakeTransport]:
    t = FakeTransport()
    return ClientApi(t, ME, timeout=0.5, max_status_age=1.0, first_goal=first_goal), t


# --------------------------------------------------------------------------- commands


def test_goal_puts_target_frame_ids_and_limits_on_the_wire() -> None:
    c, t = client(first_goal=7)
    limits = {(LimitKind.Object, LimitOrder.Velocity): 0.5, (LimitKind.Rolling, LimitOrder.Jerk): 3.0}
    r = c.goal((0.0, 1.0, 0.0, 0.0), GoalFrame.Relative, limits)
    assert r == Reply(True, ReasonCode.None_, 7, 42, 100)
    assert r.code == "Accepted"
    cmd = t.sent[0]
    assert (cmd.kind, cmd.frame, cmd.client_id, cmd.goal_id) == (CommandKind.Goal, GoalFrame.Relative, ME, 7)
    assert list(cmd.target) == [0.0, 1.0, 0.0, 0.0]
    assert cmd.limit_mask == limit_bit(LimitKind.Object, LimitOrder.Velocity) | limit_bit(
        LimitKind.Rolling, LimitOrder.Jerk
    )
    assert cmd.object_limits.velocity == 0.5 and cmd.object_limits.acceleration == 0.0
    assert cmd.rolling_limits.jerk == 3.0
    assert cmd.fingertip_limits.velocity == 0.0


def test_goal_ids_count_on_unless_given() -> None:
    c, t = client(first_goal=7)
    c.goal((1.0, 0.0, 0.0, 0.0))
    c.goal((1.0, 0.0, 0.0, 0.0), goal_id=99)
    c.goal((1.0, 0.0, 0.0, 0.0))
    assert [cmd.goal_id for cmd in t.sent] == [7, 99, 8]
    assert t.sent[0].frame == GoalFrame.Absolute and t.sent[0].limit_mask == 0


def test_a_refused_goal_says_why() -> None:
    c, t = client()
    t.refuse.add(5)
    r = c.goal((1.0, 0.0, 0.0, 0.0), goal_id=5)
    assert not r.accepted and r.code == "Rejected" and r.reason == ReasonCode.DuplicateGoalId


def test_turn_is_an_axis_angle_goal_about_the_unit_axis() -> None:
    c, t = client()
    c.turn((0.0, 0.0, 2.0), math.pi)
    cmd = t.sent[0]
    assert cmd.frame == GoalFrame.AxisAngle
    assert list(cmd.target) == [math.pi, 0.0, 0.0, 1.0]


def test_cancel_hold_reset() -> None:
    c, t = client()
    c.cancel()
    c.cancel(goal_id=3)
    c.hold()
    c.reset()
    kinds = [(cmd.kind, cmd.goal_id, cmd.client_id) for cmd in t.sent]
    assert kinds == [
        (CommandKind.Cancel, 0, ME),
        (CommandKind.Cancel, 3, ME),
        (CommandKind.Hold, 0, ME),
        (CommandKind.Reset, 0, ME),
    ]
    assert [cmd.request_id for cmd in t.sent] == [100, 101, 102, 103]


def test_answers_wait_the_clients_timeout_unless_told() -> None:
    c, t = client()
    c.hold()
    c.hold(timeout=3.0)
    assert t.answer_timeouts == [0.5, 3.0]


def test_a_command_nobody_takes() -> None:
    c, t = client()
    t.undeliverable = True
    with pytest.raises(NoDaemon, match="no daemon"):
        c.hold()
    t.inbox = status(1)  # the daemon is there: its queue for this client is full
    with pytest.raises(ClientError, match="queue for this client is full"):
        c.hold()


# --------------------------------------------------------------------------- status and events


def test_latest_and_fresh_status() -> None:
    c, t = client()
    assert c.latest_status() is None and not c.daemon_alive()
    t.inbox = status(5, age_s=2.0)  # older than max_status_age
    assert not c.daemon_alive()
    assert c.latest_status() is not None
    t.inbox = status(6)
    assert c.daemon_alive()
    s = c.latest_status()
    assert s is not None and s.tick == 6


def test_wait_status_waits_for_a_newer_one() -> None:
    c, t = client()
    t.inbox = status(1)
    t.arrivals = [Received(), status(2)]
    assert c.wait_status(timeout=5.0).tick == 2
    assert len(t.arrivals) == 0
    with pytest.raises(Timeout, match="a new status"):
        c.wait_status(timeout=0.05)


def test_wait_fresh_status_times_out() -> None:
    c, t = client()
    t.inbox = status(1, age_s=5.0)
    with pytest.raises(Timeout, match="a fresh status"):
        c._wait_fresh_status(0.05)
    t.arrivals = [status(2)]
    assert c._wait_fresh_status(5.0).tick == 2


def test_events_are_handed_out_once_oldest_first() -> None:
    c, t = client()
    t.inbox = Received(events=[event(1, 1, GoalState.Accepted), event(2, 1, GoalState.Executing)])
    assert [e.seq for e in c.events()] == [1, 2]
    assert list(c.events()) == []
    t.arrivals = [Received(events=[event(3, 1, GoalState.Succeeded)])]
    e = c.next_event(timeout=5.0)
    assert e is not None and e.seq == 3
    started = time.monotonic()
    assert c.next_event(timeout=0.05) is None
    assert time.monotonic() - started < 1.0


def test_wait_outcome_from_this_clients_terminal_event() -> None:
    c, t = client()
    t.arrivals = [
        Received(events=[event(1, 4, GoalState.Executing), event(2, 4, GoalState.Succeeded, client_id=ME + 2)]),
        Received(events=[event(3, 5, GoalState.Canceled), event(4, 4, GoalState.Aborted)]),
    ]
    assert c.wait_outcome(4, timeout=5.0) == Outcome(4, GoalState.Aborted, ReasonCode.None_)


def test_wait_outcome_from_the_status_without_an_event() -> None:
    c, t = client()
    t.arrivals = [status(1, goal_id=4, state=GoalState.Executing), status(2, goal_id=4, state=GoalState.Succeeded)]
    assert c.wait_outcome(4, timeout=5.0) == Outcome(4, GoalState.Succeeded, ReasonCode.Reached)
    with pytest.raises(Timeout, match="goal 9's outcome"):
        c.wait_outcome(9, timeout=0.05)


def test_close_and_context() -> None:
    c, t = client()
    with c as same:
        assert same is c
    assert t.closed
    t.bad_samples, t.reconnects = 3, 1
    assert (c.bad_samples, c.reconnects) == (3, 1)


# --------------------------------------------------------------------------- received samples


def good_status() -> Status:
    s = status(1).status
    assert s is not None
    return s


def test_a_good_status_passes() -> None:
    assert status_ok(good_status())


@pytest.mark.parametrize(
    "breaks",
    [
        lambda s: setattr(s, "phase", 99),
        lambda s: setattr(s, "daemon_state", 0),
        lambda s: setattr(s, "fault", 1000),
        lambda s: setattr(s, "grasp", 3),
        lambda s: setattr(s.goal, "state", 9),
        lambda s: setattr(s.goal, "reason", 1000),
        lambda s: setattr(s.fingers[2], "state", 0),
        lambda s: setattr(s.fingers[1], "measured_contact", 2),
        lambda s: setattr(s, "measured_mask", 32),
    ],
)
def test_status_codes_are_checked(breaks: Callable[[Status], object]) -> None:
    s = good_status()
    breaks(s)
    assert not status_ok(s)


def test_event_codes_and_finger_are_checked() -> None:
    e = event(1, 1, GoalState.Accepted)
    assert event_ok(e)
    e.finger = 2
    assert event_ok(e)
    e.finger = 3
    assert not event_ok(e)
    for field, value in (("kind", 0), ("state", 9), ("reason", 1000), ("fault", 1000)):
        e = event(1, 1, GoalState.Accepted)
        setattr(e, field, value)
        assert not event_ok(e), field


def test_answer_codes_are_checked() -> None:
    assert answer_ok(Answer(code=AnswerCode.Accepted, reason=ReasonCode.None_))
    assert not answer_ok(Answer(code=0, reason=ReasonCode.None_))
    assert not answer_ok(Answer(code=AnswerCode.Rejected, reason=1000))

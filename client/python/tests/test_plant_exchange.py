"""The plant protocol's bookkeeping (``gaitd.plant.Exchange``), without IPC: numbering, echoes,
stale and repeated commands, a restarted daemon, the lockstep target time, hold commands."""

from __future__ import annotations

from dataclasses import replace

import pytest

from gaitd import config, hand
from gaitd.plant import Exchange
from gaitd.schema import CommandFlags, PlantCommand
from gaitd.setpoint import BadCommand, Setpoint, encode_command

PERIOD_NS = 1_000_000
LOCKSTEP = int(CommandFlags.ENABLE | CommandFlags.LOCKSTEP)


def command(session: int, seq: int, answers: int, target_time_ns: int, flags: int = LOCKSTEP) -> PlantCommand:
    sp = hand.paper_start(config.Model(), grips=(1.0, 1.0, 1.0))
    return encode_command(
        replace(
            sp,
            flags=flags,
            session=session,
            seq=seq,
            answers=answers,
            target_time_ns=target_time_ns,
            period_ns=PERIOD_NS,
        )
    )


def answered(ex: Exchange, session: int, seq: int) -> PlantCommand:
    """The command answering the newest measurement, on time."""
    return command(session, seq, ex.seq, ex.time_ns + PERIOD_NS)


def test_measurements_are_numbered_from_one_and_strictly_later() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    assert ex.next_measurement(PERIOD_NS) == 1
    assert ex.next_measurement(2 * PERIOD_NS) == 2
    assert ex.time_ns == 2 * PERIOD_NS
    assert ex.next_measurement(2 * PERIOD_NS) == 3  # the same time stamp again: moved on by 1 ns
    assert ex.time_ns == 2 * PERIOD_NS + 1
    assert ex.next_measurement(5) == 4
    assert ex.time_ns == 2 * PERIOD_NS + 2


def test_a_new_command_is_taken_and_echoed_a_repeat_is_not() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)
    sp = ex.take(answered(ex, session=9, seq=1))
    assert sp is not None and len(sp.fingers) == 3
    assert (ex.session, ex.applied) == (9, 1)
    assert ex.take(answered(ex, session=9, seq=1)) is None  # repeated
    ex.next_measurement(2 * PERIOD_NS)
    assert ex.take(answered(ex, session=9, seq=1)) is None  # stale
    assert ex.take(answered(ex, session=9, seq=2)) is not None
    assert ex.applied == 2


def test_another_session_is_a_restarted_daemon_and_new() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)
    assert ex.take(answered(ex, session=9, seq=5)) is not None
    assert ex.take(answered(ex, session=10, seq=1)) is not None
    assert (ex.session, ex.applied) == (10, 1)


def test_lockstep_answer_must_target_the_next_period() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)
    with pytest.raises(BadCommand, match="target_time_ns"):
        ex.take(command(9, 1, answers=1, target_time_ns=3 * PERIOD_NS))
    assert (ex.session, ex.applied) == (0, 0)  # a refused command is not echoed
    # A command answering an older measurement is not held to the newest one's time.
    ex.next_measurement(2 * PERIOD_NS)
    assert ex.take(command(9, 1, answers=1, target_time_ns=2 * PERIOD_NS)) is not None


def test_a_command_answering_a_measurement_not_yet_sent_is_refused() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)
    with pytest.raises(BadCommand, match="answers measurement 2"):
        ex.take(command(9, 1, answers=2, target_time_ns=2 * PERIOD_NS))


def test_hold_and_disabled_commands_carry_no_setpoint() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)
    c = answered(ex, session=9, seq=1)
    c.flags = int(CommandFlags.LOCKSTEP | CommandFlags.ENABLE | CommandFlags.HOLD)
    c.fingers[0].grip_force = -1.0  # not checked: the hand holds what it has
    sp = ex.take(c)
    assert sp is not None and sp.fingers == () and sp.hold
    c = answered(ex, session=9, seq=2)
    c.flags = int(CommandFlags.LOCKSTEP)
    sp = ex.take(c)
    assert sp is not None and sp.fingers == () and not sp.enabled
    assert ex.applied == 2


def test_the_plants_own_check_refuses() -> None:
    ex = Exchange(PERIOD_NS, lockstep=True)
    ex.next_measurement(PERIOD_NS)

    def too_strong(sp: Setpoint) -> str | None:
        return "grip above 0.5 N" if any(f.grip_force > 0.5 for f in sp.fingers) else None

    with pytest.raises(BadCommand, match="grip above 0.5 N"):
        ex.take(answered(ex, session=9, seq=1), too_strong)
    assert ex.applied == 0


def test_realtime_takes_the_newest_without_a_target_time_check() -> None:
    ex = Exchange(PERIOD_NS, lockstep=False)
    ex.next_measurement(123)
    c = command(9, 1, answers=1, target_time_ns=10**12, flags=int(CommandFlags.ENABLE))
    assert ex.take(c) is not None

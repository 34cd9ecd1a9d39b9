"""AlarmHistory: raises and clears of the alarm word become occurrences with their times."""

from __future__ import annotations

import datetime as dt

from app.alarm_history import (
    ALARM_ADVICE,
    ALARM_MEANING,
    AlarmHistory,
    alarm_bits,
    blocks_motion,
)
from app.protocol.enums import ALARM_BITS, Alarm

T0 = dt.datetime(2026, 11, 24, 10, 0, 0)


def at(seconds: float) -> dt.datetime:
    return T0 + dt.timedelta(seconds=seconds)


def test_every_documented_bit_has_a_meaning_and_advice() -> None:
    assert set(ALARM_MEANING) == set(ALARM_BITS) == set(ALARM_ADVICE)


def test_bits_and_the_motion_hold() -> None:
    assert alarm_bits(0) == [] and alarm_bits(0b10011) == [1, 2, 16]
    assert blocks_motion(Alarm.ESTOP) and blocks_motion(Alarm.SERVO | Alarm.BRAKE)
    assert not blocks_motion(Alarm.BRAKE | Alarm.ENCODER) and not blocks_motion(None)


def test_raise_and_clear_record_their_times() -> None:
    history = AlarmHistory()
    assert history.update(0, at(0)) == []
    assert history.update(int(Alarm.ESTOP), at(1)) == [int(Alarm.ESTOP)]
    assert history.update(int(Alarm.ESTOP), at(2)) == []  # unchanged: nothing new
    history.update(int(Alarm.ESTOP | Alarm.SERVO), at(3))
    active = history.active()
    assert [(o.bit, o.raised) for o in active] == [(1, at(1)), (2, at(3))]
    assert history.update(int(Alarm.SERVO), at(5)) == [int(Alarm.ESTOP)]
    latest = history.latest(int(Alarm.ESTOP))
    assert latest is not None and latest.raised == at(1) and latest.cleared == at(5) and not latest.active
    history.update(0, at(6))
    history.update(int(Alarm.ESTOP), at(7))
    assert history.count(int(Alarm.ESTOP)) == 2
    assert history.latest(int(Alarm.ESTOP)).raised == at(7)  # type: ignore[union-attr]
    assert [o.bit for o in history.occurrences()] == [1, 2, 1]  # newest raise first
    assert history.latest(int(Alarm.BRAKE)) is None


def test_undocumented_bits_are_tracked_and_the_history_is_bounded() -> None:
    history = AlarmHistory(limit=3)
    for i in range(10):
        history.update(1 << 9, at(2 * i))
        history.update(0, at(2 * i + 1))
    assert history.count(1 << 9) == 3
    assert history.latest(1 << 9).cleared == at(19)  # type: ignore[union-attr]

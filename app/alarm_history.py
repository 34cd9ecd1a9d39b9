"""Alarm bits over time: what each GV281_L (register 562) bit means, what the operator does about
it, and when each bit was raised and cleared. Qt-free; the GUI's alarm list and banner read it.

:meth:`AlarmHistory.update` takes the alarm word of every status read (only changes matter) and
records one :class:`AlarmOccurrence` per raise; the clear closes it. Undocumented bits are
tracked by number like the documented ones.
"""

from __future__ import annotations

import datetime as dt
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass

from app.protocol.enums import ALARM_BITS, QT_TRANSLATE_NOOP, Alarm

__all__ = [
    "ALARM_ADVICE",
    "ALARM_MEANING",
    "BLOCKING_ALARMS",
    "TR_ALARMS",
    "AlarmHistory",
    "AlarmOccurrence",
    "alarm_bits",
    "blocks_motion",
]

TR_ALARMS = "Alarms"  # translation context of the texts below
HISTORY_LIMIT = 200  # occurrences kept (oldest dropped first)

# Motion controls are held while one of these is set (Stop stays): the controller will not move,
# and a jog or move sent now would start the moment the alarm is reset.
BLOCKING_ALARMS = int(Alarm.ESTOP | Alarm.SERVO)

ALARM_MEANING: dict[Alarm, str] = {
    Alarm.ESTOP: QT_TRANSLATE_NOOP("Alarms", "The emergency stop circuit is open: servo power is off."),
    Alarm.SERVO: QT_TRANSLATE_NOOP("Alarms", "A servo drive reported a fault."),
    Alarm.BRAKE: QT_TRANSLATE_NOOP("Alarms", "A holding brake did not release or engage as commanded."),
    Alarm.ALGORITHM: QT_TRANSLATE_NOOP(
        "Alarms", "The motion planner rejected a move (out of reach, singularity or limit)."
    ),
    Alarm.ENCODER: QT_TRANSLATE_NOOP("Alarms", "An axis encoder angle is implausible or was lost."),
}
ALARM_ADVICE: dict[Alarm, str] = {
    Alarm.ESTOP: QT_TRANSLATE_NOOP(
        "Alarms",
        "Make the cell safe, release the emergency stop button, then reset the alarm on the controller.",
    ),
    Alarm.SERVO: QT_TRANSLATE_NOOP(
        "Alarms", "Read the drive's fault code on the controller, remove the cause, then reset the alarm."
    ),
    Alarm.BRAKE: QT_TRANSLATE_NOOP(
        "Alarms", "Do not move the arm; check the brake wiring and power, then reset the alarm."
    ),
    Alarm.ALGORITHM: QT_TRANSLATE_NOOP(
        "Alarms", "Check the target point and speed, reset the alarm, then move to a reachable point."
    ),
    Alarm.ENCODER: QT_TRANSLATE_NOOP(
        "Alarms", "Check the encoder cable; the zero position may need recalibration before moving."
    ),
}
UNKNOWN_MEANING = QT_TRANSLATE_NOOP("Alarms", "A bit the protocol does not document.")
UNKNOWN_ADVICE = QT_TRANSLATE_NOOP("Alarms", "Read the alarm on the controller's own pendant.")


def alarm_bits(alarms: int) -> list[int]:
    """The set bits of an alarm word, as single-bit values, lowest first."""
    alarms = int(alarms) & 0xFFFF
    return [1 << b for b in range(16) if alarms & (1 << b)]


def blocks_motion(alarms: int | None) -> bool:
    """True while an alarm that holds the motion controls is set."""
    return bool((alarms or 0) & BLOCKING_ALARMS)


def is_documented(bit: int) -> bool:
    return any(int(a) == bit for a in ALARM_BITS)


@dataclass(frozen=True)
class AlarmOccurrence:
    """One raise of one bit; ``cleared`` is None while it is still set."""

    bit: int
    raised: dt.datetime
    cleared: dt.datetime | None = None

    @property
    def active(self) -> bool:
        return self.cleared is None


class AlarmHistory:
    """The alarm word's changes as occurrences (see the module docstring)."""

    def __init__(self, limit: int = HISTORY_LIMIT) -> None:
        self._alarms = 0
        self._open: dict[int, AlarmOccurrence] = {}
        self._closed: deque[AlarmOccurrence] = deque(maxlen=limit)

    @property
    def alarms(self) -> int:
        return self._alarms

    def update(self, alarms: int, when: dt.datetime | None = None) -> list[int]:
        """Take a new alarm word; returns the bits that changed (raised or cleared)."""
        alarms = int(alarms) & 0xFFFF
        changed = alarm_bits(alarms ^ self._alarms)
        if not changed:
            return []
        now = when or dt.datetime.now()
        for bit in changed:
            if alarms & bit:
                self._open[bit] = AlarmOccurrence(bit, now)
            else:
                opened = self._open.pop(bit, None)
                if opened is not None:
                    self._closed.append(AlarmOccurrence(bit, opened.raised, now))
        self._alarms = alarms
        return changed

    def active(self) -> list[AlarmOccurrence]:
        return [self._open[bit] for bit in sorted(self._open)]

    def occurrences(self) -> list[AlarmOccurrence]:
        """Every kept occurrence, the newest raise first (active and cleared)."""
        return sorted([*self._open.values(), *self._closed], key=lambda o: o.raised, reverse=True)

    def latest(self, bit: int) -> AlarmOccurrence | None:
        """The newest occurrence of ``bit`` (active or cleared), None if it was never raised."""
        if bit in self._open:
            return self._open[bit]
        for occurrence in reversed(self._closed):
            if occurrence.bit == bit:
                return occurrence
        return None

    def count(self, bit: int) -> int:
        return sum(1 for o in self._closed if o.bit == bit) + (1 if bit in self._open else 0)

    def __iter__(self) -> Iterator[AlarmOccurrence]:
        return iter(self.occurrences())

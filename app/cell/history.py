"""One controller's history in the cell view: state changes, alarms raised and cleared, program cycles.

Bounded (:data:`HISTORY_BOUND` events, the oldest dropped first and counted). Fed from the poller's
answers and silences; no Qt. Program cycles come from the program-state register (561) alone:

* *started*: stopped -> running;
* *finished*: running -> stopped with no alarm set (the program came to its end, or a stop nobody
  can tell from an end: the register has no "finished" value);
* *stopped*: running or paused -> stopped with an alarm set, or paused -> stopped.

Running <-> paused and the work mode (560) are state changes; the link's answering / not answering
is one too. Exported as CSV, UTF-8 with a BOM (a spreadsheet reads it), written atomically.
"""

from __future__ import annotations

import csv
import datetime as dt
import io
import os
from collections import deque
from dataclasses import dataclass

from app.models import ControllerStatus
from app.points.atomic import atomic_write_bytes
from app.protocol.enums import ALARM_BITS, ALARM_TEXT, Alarm, ProgramState

__all__ = ["HISTORY_BOUND", "CellEvent", "ControllerHistory", "alarm_order", "program_cycle"]

HISTORY_BOUND = 1000
CSV_HEADER = ("time", "controller", "kind", "detail")


@dataclass(frozen=True)
class CellEvent:
    """One event: ``kind`` is ``state``, ``alarm raised``, ``alarm cleared``, ``program started``,
    ``program finished``, ``program stopped``, ``link``; ``detail`` says what, in English."""

    wall_ms: int
    controller: str
    kind: str
    detail: str

    @property
    def time_text(self) -> str:
        moment = dt.datetime.fromtimestamp(self.wall_ms / 1000.0, tz=dt.UTC).astimezone()
        return moment.isoformat(timespec="milliseconds")


def _name(value: int, enum_type: type[ProgramState]) -> str:
    try:
        return enum_type(value).name.lower()
    except ValueError:
        return f"unknown ({value})"


def _mode_name(value: int) -> str:
    from app.protocol.enums import ControllerMode

    try:
        return ControllerMode(value).name.lower().replace("_", " ")
    except ValueError:
        return f"unknown ({value})"


def alarm_order(alarms: int, raised_at: dict[int, int]) -> list[Alarm]:
    """The set alarm bits, most severe first (emergency stop, servo, brake, algorithm, encoder),
    then the oldest first among equals (``raised_at``: bit -> ms it was first seen)."""
    bits = [bit for bit in ALARM_BITS if alarms & bit]
    return sorted(bits, key=lambda bit: (ALARM_BITS.index(bit), raised_at.get(int(bit), 0)))


def program_cycle(before: int, now: int, alarms: int) -> str | None:
    """What a change of the program-state register (561) from ``before`` to ``now`` is of a program
    cycle: ``"started"``, ``"finished"``, ``"stopped"`` (the module's rule), or None (none of them).
    The gateway's cycle counters count the same (:mod:`app.gateway.metrics`)."""
    stopped, running = int(ProgramState.STOPPED), int(ProgramState.RUNNING)
    if before == now:
        return None
    if before == stopped and now == running:
        return "started"
    if now == stopped and before == running and not alarms:
        return "finished"
    if now == stopped:
        return "stopped"
    return None


class ControllerHistory:
    """What happened to one controller, bounded; :meth:`observe` and :meth:`silent` feed it."""

    def __init__(self, controller: str, bound: int = HISTORY_BOUND) -> None:
        self.controller = controller
        self.events: deque[CellEvent] = deque(maxlen=bound)
        self.dropped = 0
        self.raised_at: dict[int, int] = {}  # alarm bit -> wall ms it was first seen set
        self._last: ControllerStatus | None = None
        self._answering: bool | None = None

    def _add(self, wall_ms: int, kind: str, detail: str) -> None:
        if len(self.events) == self.events.maxlen:
            self.dropped += 1
        self.events.append(CellEvent(wall_ms, self.controller, kind, detail))

    def observe(self, status: ControllerStatus, wall_ms: int) -> None:
        """An answered poll: record what changed since the last one."""
        if self._answering is not True:
            self._add(wall_ms, "link", "answering")
            self._answering = True
        last = self._last
        self._last = status
        self._alarms(0 if last is None else int(last.alarms), int(status.alarms), wall_ms)
        if last is None:
            self._add(wall_ms, "state", f"mode {_mode_name(int(status.mode))}")
            self._add(wall_ms, "state", f"program {_name(int(status.program_state), ProgramState)}")
            return
        if int(last.mode) != int(status.mode):
            self._add(
                wall_ms, "state", f"mode {_mode_name(int(last.mode))} -> {_mode_name(int(status.mode))}"
            )
        self._program(int(last.program_state), int(status.program_state), int(status.alarms), wall_ms)

    def silent(self, reason: str, wall_ms: int) -> None:
        """A failed poll: the link's change to not answering is recorded once."""
        if self._answering is not False:
            self._add(wall_ms, "link", f"not answering: {reason}")
            self._answering = False

    def _alarms(self, before: int, now: int, wall_ms: int) -> None:
        if before == now:  # the common case, 320 times a second in a cell of 16 at 20 Hz
            return
        for bit in ALARM_BITS:
            if now & bit and not before & bit:
                self.raised_at[int(bit)] = wall_ms
                self._add(wall_ms, "alarm raised", ALARM_TEXT[bit])
            elif before & bit and not now & bit:
                self.raised_at.pop(int(bit), None)
                self._add(wall_ms, "alarm cleared", ALARM_TEXT[bit])

    def _program(self, before: int, now: int, alarms: int, wall_ms: int) -> None:
        if before == now:
            return
        cycle = program_cycle(before, now, alarms)
        if cycle is not None:
            detail = (
                "" if cycle != "stopped" else "alarm" if alarms else f"from {_name(before, ProgramState)}"
            )
            self._add(wall_ms, f"program {cycle}", detail)
        else:
            detail = f"program {_name(before, ProgramState)} -> {_name(now, ProgramState)}"
            self._add(wall_ms, "state", detail)

    def csv_bytes(self) -> bytes:
        out = io.StringIO()
        writer = csv.writer(out, lineterminator="\r\n")
        writer.writerow(CSV_HEADER)
        for event in self.events:
            writer.writerow((event.time_text, event.controller, event.kind, event.detail))
        return out.getvalue().encode("utf-8-sig")

    def export_csv(self, path: str | os.PathLike[str]) -> None:
        """Write the history as CSV (UTF-8 with a BOM), atomically."""
        atomic_write_bytes(path, self.csv_bytes())

"""Another Modbus master on the same controller: what one client can see of it (issue 19).

The controller has one set of parameter GVs, one command block and one GV291 for every master,
and Modbus has no lock (PROTOCOL.md, "More than one master"). A host cannot prevent another
master's writes; it can notice them. Three signs are watched, here and in the supervisor:

* **GV291 results we did not cause** (:class:`ForeignMasterWatch`, fed by the client itself):
  GV291 changes to a non-initial value while none of our writes is pending -- a pending write is
  one made less than :data:`app.timing.FOREIGN_RESULT_WINDOW` ago, or the command it started is
  still running (GV291 *moving*). A change to 0 (initial) is not counted: a controller restart
  and a stop also show 0, and another master's command shows its result after it anyway.
* **Parameter registers changing without a write of ours**: GV200..GV205 and GV221..GV227
  (the motion parameters, the program and mode registers; see
  :data:`~app.link.register_client.SHARED_BLOCKS`) are read with a status read once a clock
  period (``watch_shared_every``: the GUI's polls, an upload's or a command's waits, the CLI's
  reads) and just before a move's trigger; a value
  other than the last read and our own answered writes since then left there is another
  master's (the controller only reads these registers: PROTOCOL.md, the host writes them).
* **The restart canary holding another host's token** (:mod:`app.link.supervisor`): a restart
  clears GV0..GV99, so the canary reads 0; any other value than ours was written by another
  master -- not a restart.

Each sighting is a :class:`ForeignSighting` (``what``: ``"gv291"``, ``"registers"`` or
``"canary"``, and the value seen: the GV291 code, the first changed register, the token); the
worker publishes it (screen and audit), the CLI prints a warning line.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from app import timing
from app.link.outcome import UNKNOWN_ADVICE
from app.protocol.enums import STATUS_INITIAL, STATUS_SENTINEL, MoveStatus
from app.safety.audit import AuditLog

__all__ = ["ForeignMasterWatch", "ForeignSighting", "audit_sighting", "overlapped_text"]

#: GV291 values that do not end a command of ours (the sentinel is ours, 0 shows before a result)
_NOT_FINAL = frozenset({STATUS_INITIAL, STATUS_SENTINEL, int(MoveStatus.MOVING)})


@dataclass(frozen=True)
class ForeignSighting:
    """One sign of another master: ``what`` (``"gv291"``, ``"registers"``, ``"canary"``) and the
    value seen."""

    what: str
    value: float
    at: float  # monotonic time it was seen

    @property
    def message(self) -> str:
        """English, for the log and the CLI."""
        if self.what == "registers":
            return (
                f"another Modbus master is on this controller: register {self.value:g} changed "
                f"without a write of ours"
            )
        if self.what == "canary":
            return (
                f"another Modbus master is on this controller: the restart canary holds another "
                f"host's token ({self.value:g})"
            )
        return (
            f"another Modbus master is on this controller: GV291 changed to {self.value:g} "
            f"without a command of ours"
        )


class ForeignMasterWatch:
    """GV291 and the shared registers watched across one client's writes and reads, and the
    sightings of every kind (any thread; one lock). A move is refused while one is recent
    (:meth:`seen_within`), a command's "done" after one is *outcome unknown* (the tracker)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._last_code: int | None = None
        self._last_write = -1e9
        self._ours_open = False  # a write of ours may still be answered in GV291
        # the shared registers as the last read and our writes since then left them (None: not read yet)
        self._expected: dict[int, int] | None = None
        self._sightings: list[ForeignSighting] = []
        self.last_seen: float | None = None  # monotonic time of the last sighting (any kind)
        self.last_sighting: ForeignSighting | None = None
        #: called with each sighting as it is made (the CLI's warning line); from the reading thread
        self.on_sighting: Callable[[ForeignSighting], None] | None = None

    def note_write(self, now: float) -> None:
        """A write of ours is about to go out: GV291 changes from now on may be its answer."""
        with self._lock:
            self._last_write = now
            self._ours_open = True

    def note_status(self, code: int, now: float) -> ForeignSighting | None:
        """GV291 as just read; a sighting when it changed without a write of ours pending."""
        with self._lock:
            last, self._last_code = self._last_code, code
            sighting = None
            if last is not None and code != last:
                if self._ours_open:
                    if code not in _NOT_FINAL:
                        self._ours_open = False  # our command's result: later changes are not ours
                elif code != STATUS_INITIAL:
                    sighting = ForeignSighting("gv291", float(code), now)
            if (
                self._ours_open
                and code != MoveStatus.MOVING
                and now - self._last_write > timing.FOREIGN_RESULT_WINDOW
            ):
                self._ours_open = False  # nothing of ours is running any more (a stop reads 0)
        if sighting is not None:
            self.add(sighting)
        return sighting

    @property
    def has_baseline(self) -> bool:
        """The shared registers were read once (what they should hold is known)."""
        return self._expected is not None

    def note_registers(self, address: int, values: Sequence[int], *, stored: bool) -> None:
        """A write of ours to ``address`` (``values``): what the shared registers hold now when the
        controller answered it (``stored``), else those registers are unknown until the next read."""
        with self._lock:
            expected = self._expected
            if expected is None:
                return
            for offset, value in enumerate(values):
                if address + offset in expected:
                    if stored:
                        expected[address + offset] = int(value) & 0xFFFF
                    else:
                        del expected[address + offset]

    def note_shared(self, watched: Sequence[tuple[int, int]], now: float) -> ForeignSighting | None:
        """The shared parameter / command registers as just read ((address, value) pairs); a
        sighting when one differs from what the last read and our writes since then left there."""
        with self._lock:
            expected, self._expected = self._expected, dict(watched)
            if expected is None:
                return None
            changed = [address for address, value in watched if expected.get(address, value) != value]
        if not changed:
            return None
        sighting = ForeignSighting("registers", float(changed[0]), now)
        self.add(sighting)
        return sighting

    def add(self, sighting: ForeignSighting) -> None:
        """Record a sighting (the supervisor adds the canary's) and tell ``on_sighting``."""
        with self._lock:
            self._sightings.append(sighting)
            self.last_seen = sighting.at
            self.last_sighting = sighting
        callback = self.on_sighting
        if callback is not None:
            callback(sighting)

    def take(self) -> list[ForeignSighting]:
        """The sightings not taken yet, oldest first."""
        with self._lock:
            taken, self._sightings = self._sightings, []
        return taken

    def seen_since(self, moment: float) -> bool:
        """True when another master was seen at or after ``moment`` (monotonic): a command sent
        then cannot tell its own end from the other master's."""
        seen = self.last_seen
        return seen is not None and seen >= moment

    def seen_within(self, now: float, window: float) -> bool:
        """True when another master was seen less than ``window`` seconds before ``now``."""
        seen = self.last_seen
        return seen is not None and now - seen < window


def overlapped_text(command: str) -> str:
    """What a command whose end came while another master was seen says (its outcome is unknown)."""
    return (
        f"{command}: another Modbus master was seen while it ran, so its result may be the other "
        f"master's: {UNKNOWN_ADVICE}"
    )


def audit_sighting(audit: AuditLog | None, sighting: ForeignSighting) -> None:
    """The audit trail's record of a sighting (GUI and CLI alike)."""
    if audit is not None:
        args = {"what": sighting.what, "value": sighting.value}
        audit.record("link", "another Modbus master seen", args=args, detail=sighting.message)

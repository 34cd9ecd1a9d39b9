"""An upload's report (what the controller created, refused, or was not asked), how it updates the
ledger, and the id lists of the CLI. The upload itself is the one upload driver's
(:mod:`app.link.upload_driver`): the GUI's worker (:mod:`app.link.upload`) and the CLI
(:func:`app.cli.points_upload.staged_upload`, which builds this report) send through it."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from app.errors import InvalidInput
from app.points.point import SyncState, TempPoint

if TYPE_CHECKING:
    from app.points.ledger import PointLedger


@dataclass(frozen=True)
class UploadOutcome:
    point_id: int
    ok: bool
    reason: str = ""
    sent: TempPoint | None = None  # the values the controller now holds (ok only)
    unconfirmed: bool = False  # ok, but the controller's status never changed (CommandResult.unconfirmed)


@dataclass(frozen=True)
class BootLost:
    """The restart canary changed during an upload (``teachpad-cli points upload``): the controller
    is not the boot the upload began on. ``value``: what the canary read (0: it restarted, a
    restart clears GV0..GV99; another value: another host wrote it -- another master, or a restart
    it armed again; either way nothing before it is proven). ``after``: the last point proven
    created before it (None: none). ``suspects``: the points created or tried since the last good
    read of the canary (one may have been created at a wiped, zero pose); ``repaired``: those of
    them created again at their poses on the new boot and proven there; ``repair_error``: why the
    rest were not (empty: all were)."""

    value: float
    after: int | None
    suspects: tuple[int, ...] = ()
    repaired: tuple[int, ...] = ()
    repair_error: str = ""

    @property
    def restarted(self) -> bool:
        return self.value == 0.0


@dataclass
class UploadReport:
    outcomes: list[UploadOutcome] = field(default_factory=list)
    aborted: str | None = None  # why the upload stopped early (link lost, stop requested)
    not_attempted: list[int] = field(default_factory=list)
    interrupted: bool = False  # ended by Ctrl-C
    #: ids created and proven held by the boot the upload began on (a read of the restart canary
    #: after their result still showed its token): what an upload record may keep
    confirmed: list[int] = field(default_factory=list)
    boot_lost: BootLost | None = None  # the controller restarted (or the canary changed) meanwhile

    @property
    def ok_count(self) -> int:
        return sum(1 for o in self.outcomes if o.ok)

    @property
    def failed(self) -> list[UploadOutcome]:
        return [o for o in self.outcomes if not o.ok]

    @property
    def all_ok(self) -> bool:
        return self.aborted is None and not self.failed


def apply_upload(ledger: PointLedger, report: UploadReport) -> list[int]:
    """Record an upload's outcome in the ledger; returns the rows that changed.

    A point edited on the host while it was being uploaded stays ``CHANGED``."""
    rows: list[int] = []
    for outcome in report.outcomes:
        current = ledger.get(outcome.point_id)
        if current is None:
            continue
        if outcome.ok:
            if outcome.sent is not None and not current.same_on_controller(outcome.sent):
                continue
            state = SyncState.UNCONFIRMED if outcome.unconfirmed else SyncState.ON_CONTROLLER
            rows.append(ledger.set_sync(outcome.point_id, state))
        else:
            rows.append(ledger.set_sync(outcome.point_id, SyncState.FAILED, outcome.reason))
    return rows


def parse_id_list(text: str) -> list[int]:
    """``"1,2,5-9"`` -> ``[1, 2, 5, 6, 7, 8, 9]`` (order kept, duplicates dropped)."""
    ids: list[int] = []
    seen: set[int] = set()
    for part in text.split(","):
        item = part.strip()
        if not item:
            continue
        lo_text, sep, hi_text = item.partition("-")
        try:
            if sep:
                lo, hi = int(lo_text), int(hi_text)
                if hi < lo:
                    raise InvalidInput(f"bad id range {item!r}: {hi} < {lo}")
                chunk = list(range(lo, hi + 1))
            else:
                chunk = [int(item)]
        except ValueError:
            raise InvalidInput(f"bad id list item {item!r} (use e.g. 1,2,5-9)") from None
        for i in chunk:
            if i not in seen:
                seen.add(i)
                ids.append(i)
    return ids

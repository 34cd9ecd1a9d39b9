"""The point sync controller's bookkeeping: the upload in flight and what the link's results
mean for it (why a result ended, the taught pose in a create-point result, why a batch ended
early).

:class:`~ui.controllers.point_sync.PointSyncController` owns one :class:`UploadTally` per upload
request; nothing here talks to the link or the model, or holds a Qt object.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from app.models import CommandResult, Pose
from app.points.point import TempPoint
from app.points.upload import UploadOutcome, UploadReport
from ui.messages import result_text

POSE_DETAIL_KEYS: tuple[str, ...] = ("x", "y", "z", "a", "b", "c")


def result_reason(result: CommandResult) -> str:
    """Why a result ended, one translated sentence (ui/messages.py)."""
    return result_text(result)


def pose_from_details(details: dict[str, float], fallback: Pose | None) -> Pose | None:
    """The pose the link added to a create-point result (``x``..``c``), else ``fallback``."""
    if all(k in details for k in POSE_DETAIL_KEYS):
        x, y, z, a, b, c = (float(details[k]) for k in POSE_DETAIL_KEYS)
        return Pose(x, y, z, a, b, c, ext=fallback.ext if fallback else (0.0,) * 5)
    return fallback


def batch_reason(message: str) -> str:
    """Why an upload ended early, from the link's "uploaded N of M points (reason)"."""
    _head, sep, tail = message.partition(" (")
    return tail[:-1] if sep and tail.endswith(")") else message


@dataclass
class UploadTally:
    """One upload request as the GUI follows it: what was sent, what the link reported so far."""

    points: dict[int, TempPoint]  # id -> the point as sent (ledger order)
    restore: bool
    report: UploadReport = field(default_factory=UploadReport)
    pending: list[UploadOutcome] = field(default_factory=list)  # reported, not yet in the ledger
    cancelled: bool = False
    link_lost: str | None = None  # the link went down: waiting for the worker's final result

    @property
    def total(self) -> int:
        return len(self.points)

    @property
    def attempted(self) -> int:
        return len(self.report.outcomes)

    def record(self, point_id: int, ok: bool, reason: str, unconfirmed: bool = False) -> None:
        """The link reported one point (ignored unless it is one of this request's)."""
        sent = self.points.get(point_id)
        if sent is None:
            return
        outcome = (
            UploadOutcome(point_id, True, sent=sent, unconfirmed=unconfirmed)
            if ok
            else UploadOutcome(point_id, False, reason)
        )
        self.report.outcomes.append(outcome)
        self.pending.append(outcome)

    def take_pending(self) -> list[UploadOutcome]:
        """The outcomes reported since the last call (to apply to the ledger at once)."""
        batch, self.pending = self.pending, []
        return batch

    def close(self, aborted: str | None) -> UploadReport:
        """The request's report; an aborted one lists the points never attempted."""
        if aborted is not None:
            done_ids = {o.point_id for o in self.report.outcomes}
            self.report.aborted = aborted
            self.report.not_attempted = [pid for pid in self.points if pid not in done_ids]
        return self.report

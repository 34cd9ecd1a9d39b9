"""The point guard of the GUI: a move's points re-created, its arrival checked.

Every move of the GUI to a stored point goes through it: each segment of a plan run
(:mod:`ui.controllers.plan_run_controller`) and the points table's *Move to point*
(:mod:`ui.controllers.point_sync`).

The GUI's side of :class:`app.points.guard.PointGuard` (the rule the CLI's ``run`` follows): a
temp point cannot be read back, the controller forgets them when it restarts and any other
Modbus client may overwrite one, so "uploaded earlier" proves nothing. For every segment,
:class:`RunPoints`

1. takes the segment's points from the ledger as it is now (:meth:`RunPoints.begin`; a point
   the project no longer has fails the segment before anything is sent),
2. gives the items of one ``UploadPoints`` request (the worker creates them from the
   host's values, stop and cancel between two points), which the run controller sends right
   before the segment's move; :meth:`RunPoints.on_point_uploaded` collects what the worker
   reports and :meth:`RunPoints.finish_upload` writes it into the ledger (sync state) and the
   project's upload history,
3. checks the arrival after the move (:meth:`RunPoints.check_arrival`): the pose polled with
   the move's completion against the ledger's end point, within
   :data:`app.points.guard.ARRIVAL_TOLERANCE_MM`. A mismatch marks the end point *unknown*
   and fails the run at that segment.

What it cannot do (as the CLI, see ``app/points/guard.py``): a tool that overwrites a point
between our create-point and our move command still moves the arm there once; the arrival
check then stops the run at that segment's end. An arc's middle point is not verified.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from app.errors import TeachPadError
from app.models import Pose
from app.points.guard import PointGuard, PointNotCreated
from app.points.point import SyncState, TempPoint
from app.points.upload import UploadOutcome, UploadReport
from ui.models.points_model import PointsModel

__all__ = ["ArrivalUnknown", "RunPoints", "SegmentPoints"]


class ArrivalUnknown(TeachPadError):
    """The move reported done, but no pose is known to check the arrival with."""

    code = "arrival_unknown"


@dataclass
class SegmentPoints:
    """One segment's points as sent (the ledger's copy when the segment began)."""

    end_id: int
    points: dict[int, TempPoint]
    outcomes: list[UploadOutcome] = field(default_factory=list)

    def items(self) -> list[tuple[int, Sequence[float], int]]:
        """:class:`~app.link.ops.UploadPoints` items: (id, X Y Z A B C, tool frame)."""
        return [(p.id, p.xyzabc, p.tool) for p in self.points.values()]

    @property
    def failed(self) -> list[UploadOutcome]:
        return [o for o in self.outcomes if not o.ok]

    @property
    def all_created(self) -> bool:
        done = {o.point_id for o in self.outcomes if o.ok}
        return done >= set(self.points)


class RunPoints:
    """The point guard of one run controller (see the module docstring)."""

    def __init__(self, points: PointsModel) -> None:
        self._model = points
        self.segment: SegmentPoints | None = None  # the segment whose points are being created

    @property
    def model(self) -> PointsModel:
        return self._model

    def begin(self, end_id: int, point_ids: Sequence[int]) -> SegmentPoints:
        """The points of a move to ``end_id`` (a segment's ``point_ids``, or the end point alone
        for the points table's *Move to point*) from the ledger now; :class:`PointNotCreated`
        (``point_missing``) when the project has no such point."""
        ledger = self._model.ledger
        points: dict[int, TempPoint] = {}
        for point_id in point_ids:
            point = ledger.get(point_id)
            if point is None:
                raise PointNotCreated(
                    f"the project has no point P{point_id}",
                    code="point_missing",
                    params={"point": f"P{point_id}"},
                )
            points[point_id] = point
        self.segment = SegmentPoints(end_id, points)
        return self.segment

    def on_point_uploaded(self, point_id: int, ok: bool, reason: str, unconfirmed: bool) -> None:
        """The worker's report of one point of the segment's upload (others are ignored)."""
        seg = self.segment
        if seg is None or point_id not in seg.points:
            return
        sent = seg.points[point_id]
        seg.outcomes.append(
            UploadOutcome(point_id, True, sent=sent, unconfirmed=unconfirmed)
            if ok
            else UploadOutcome(point_id, False, reason)
        )

    def finish_upload(self, endpoint: str) -> SegmentPoints | None:
        """The segment's upload ended: its outcomes go into the ledger and the created points
        into the project's upload history (history first, so the dirty check sees it)."""
        seg = self.segment
        if seg is None:
            return None
        created = [o.point_id for o in seg.outcomes if o.ok]
        if created:
            self._model.project.record_upload(created, endpoint or "controller")
        if seg.outcomes:
            self._model.apply_upload(UploadReport(outcomes=list(seg.outcomes)))
        return seg

    def not_created(self, seg: SegmentPoints) -> PointNotCreated:
        """The error for a segment whose points were not all created."""
        missing = [pid for pid in seg.points if pid not in {o.point_id for o in seg.outcomes if o.ok}]
        point = seg.points[missing[0]] if missing else next(iter(seg.points.values()))
        failed = {o.point_id: o.reason for o in seg.failed}
        cause = failed.get(point.id, "not created")
        return PointNotCreated(
            f"the controller did not create {point.label} before the move: {cause}",
            params={"point": point.label, "cause": cause},
        )

    def check_arrival(self, seg: SegmentPoints, pose: Pose | None) -> TeachPadError | None:
        """None when ``pose`` is at the segment's end point as sent; else the error that ends
        the run (the end point is then marked *unknown* in the ledger)."""
        point = seg.points[seg.end_id]
        if pose is None:
            return ArrivalUnknown(
                f"the arm's position after the move to {point.label} is not known",
                params={"point": point.label},
            )
        mismatch = PointGuard(seg.points, canary_gv=None).check_arrival(pose, seg.end_id)
        if mismatch is not None and self._model.ledger.get(point.id) is not None:
            self._model.set_sync(
                point.id,
                SyncState.UNKNOWN,
                "the arm did not arrive at this point: the controller's copy differs",
            )
        return mismatch

    def clear(self) -> None:
        self.segment = None

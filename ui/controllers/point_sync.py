"""PointSyncController: teach, upload / restore and move for the point ledger, through the link.

A ``QObject`` without widgets (GUI thread). It drives the robot link for the ledger: teach a
point from the current pose (function 2, "from the current pose"), upload points (function 2
from GVs, batched by tool frame), restore them all after a controller restart, move to a point
(function 3, line). It records the outcome in the :class:`~ui.models.points_model.PointsModel`
and says what happened through signals. The points panel and the planner share one.

The link is a :class:`~app.link.robot_link.LinkPort`. Each request's outcome comes back on its
own :class:`~app.link.robot_link.Pending` (``link.track(request_id)``), so nothing here matches
ids. Connection and pose are read from ``link.state`` (:class:`~app.link.state.RobotState`). An
upload is one request: its Pending's progress (:mod:`app.link.progress`, this request's only)
marks each point on the controller / failed as it goes (a ``PointUploaded``; applied to the
ledger at each ``UploadProgress`` and at the end, so a cancel or a lost link half way leaves
exact states), and the batch's result ends it. The points the controller
created go into the project's upload history as they are applied (``project.record_upload``
with the link's endpoint, like the CLI's ``points upload``): history only, never proof that
the controller still holds them. Teach reads the pose back from
the ``x``..``c`` details that the link adds to a successful create-point result (the pose
polled together with the completion); without them it uses the state's latest pose. The
bookkeeping of an upload in flight is :mod:`ui.controllers.point_sync_state`.

**Which controller the states refer to.** The sync states are true of one controller in one
boot: the :class:`~app.link.types.ControllerIdentity` the link publishes with each connection
(``link.state.connection.controller``). Whenever the link comes up with an identity that is not
provably the same boot as the one the states were made with (another endpoint or unit after
*Connect…*, a changed register profile, a restart seen by the canary, a reconnect whose canary
no longer holds our token), every point becomes *unknown* and "Restore all" is offered; a
reconnect to the same boot keeps them. A move that the controller answers with "bad end point
id" (it does not hold the point) makes that point *unknown* too.

**Move to point** goes through the point guard of the plan runs
(:class:`~ui.controllers.run_points.RunPoints`): the point is created again from the ledger
(one ``UploadPoints``), ``movePrepared(int)`` is emitted and the move goes out only when
the controller has created it; after the move the pose polled with its completion is compared
with the ledger's point (1 mm): an arm that stopped elsewhere is a failed move, said in words,
and the point becomes *unknown*.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal, Slot

from app.errors import InvalidInput
from app.link.link_port import LinkPort, Pending
from app.link.ops import CancelUpload, CreatePoint, MoveToPoint, Stop, UploadPoints
from app.link.progress import PointUploaded, Progress, UploadProgress
from app.link.types import ConnectionState, ControllerIdentity, WorkerError
from app.models import CommandResult, Pose
from app.points.point import SyncState
from app.points.upload import UploadReport
from app.protocol.enums import MoveStatus
from app.protocol.registers import TOOL_NONE
from ui.controllers.point_sync_state import UploadTally, batch_reason, pose_from_details, result_reason
from ui.controllers.run_points import RunPoints, SegmentPoints
from ui.messages import connection_text, error_text, refusal_text, result_text
from ui.models.points_model import PointsModel

if TYPE_CHECKING:
    from ui.controllers.new_point import NewPointPose

DEFAULT_MOVE_SPEED = 50.0  # mm/s for "move to point"
MAX_MOVE_SPEED = 1000.0

LEVEL_INFO = "info"
LEVEL_WARN = "warn"
LEVEL_ERROR = "error"


class PointSyncController(QObject):
    """Teach / upload / restore / move for the ledger through the link (GUI thread).

    Signals: ``busyChanged(bool)``, ``connectedChanged(bool)`` (``link.state.connected``, at each
    connection change of the state), ``statusMessage(str, str)``
    (text, level "info" / "warn" / "error"), ``pointTaught(int)`` (id), ``uploadProgress(int,
    int)`` (points done, total), ``uploadFinished(object)`` (:class:`UploadReport` of the whole
    request), ``restoreOffered(bool)`` (show / hide "Restore all"), ``movePrepared(int)`` (the
    point was created again from the ledger: its move goes out next), ``moveFinished(bool, str)``.
    """

    busyChanged = Signal(bool)
    connectedChanged = Signal(bool)
    statusMessage = Signal(str, str)
    pointTaught = Signal(int)
    uploadProgress = Signal(int, int)
    uploadFinished = Signal(object)
    restoreOffered = Signal(bool)
    movePrepared = Signal(int)
    moveFinished = Signal(bool, str)

    def __init__(
        self, model: PointsModel, link: LinkPort | None = None, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self._model = model
        self._link: LinkPort | None = None
        self._operation = ""  # "teach" | "upload" | "move" | ""
        self._teach_id: int | None = None
        self._teach_name = ""
        self._move_id: int | None = None
        self._move_speed = DEFAULT_MOVE_SPEED
        self._move_stops = 0  # link.state.stops_requested when the move began (a Stop since: no move)
        self._guard = RunPoints(model)  # a move's point re-created and its arrival checked
        self._prepared: SegmentPoints | None = None  # the point of the move under way, as created
        # the controller (and boot) the ledger's sync states are true of (None: none met yet)
        self._controller: ControllerIdentity | None = None
        self._live = False  # the link is up with self._controller (a new connection re-identifies)
        self._pending: Pending | None = None  # the outcome of the running teach / move / upload
        self._upload: UploadTally | None = None
        self._restore_offered = False
        self.teach_tool = TOOL_NONE
        if link is not None:
            self.set_link(link)

    # --- state
    @property
    def model(self) -> PointsModel:
        return self._model

    @property
    def link(self) -> LinkPort | None:
        return self._link

    @property
    def connected(self) -> bool:
        """The link's connection (``link.state``), never a copy."""
        return self._link is not None and self._link.state.connected

    @property
    def busy(self) -> bool:
        return bool(self._operation)

    @property
    def operation(self) -> str:
        return self._operation

    @property
    def last_pose(self) -> Pose | None:
        return self._link.state.pose if self._link is not None else None

    def new_point_pose(self, near_row: int | None = None) -> NewPointPose:
        """The pose for a point added by hand: the robot's while the link is fresh, else the
        point at ``near_row`` (default: the last one) or zeros (see :mod:`ui.controllers.new_point`)."""
        from ui.controllers.new_point import new_point_pose  # the first point added by hand

        state = self._link.state if self._link is not None else None
        return new_point_pose(
            state is not None and state.fresh,
            state.pose if state is not None else None,
            self._model.ledger,
            near_row,
            self.teach_tool,
        )

    @property
    def restore_offered(self) -> bool:
        return self._restore_offered

    def set_link(self, link: LinkPort) -> None:
        if self._link is not None:
            raise RuntimeError("the link is already set")
        self._link = link
        self._controller = link.state.connection.controller
        self._live = self._controller is not None
        # Reconnects and restarts reach the points through the connection's controller identity
        # (_on_connection): a restart seen by the canary is a new identity, published before
        # controllerRestarted; a reconnect to the same boot keeps the states.
        link.state.connectionChanged.connect(self._on_connection)

    # --- operations (return False, with a statusMessage, when they cannot start)
    def teach(self, name: str = "") -> int | None:
        """Create temp point N (:meth:`PointsModel.next_id`) on the controller from its current pose; the
        ledger gets it when the controller confirms. Returns N, or None if it cannot start."""
        link = self._ready(self.tr("Teach"))
        if link is None:
            return None
        try:
            point_id = self._model.next_id()
        except InvalidInput as exc:
            self._say(refusal_text(exc), LEVEL_ERROR)
            return None
        self._teach_id = point_id
        self._teach_name = name
        self._set_operation("teach")
        self._say(self.tr("Teaching P{id} at the current pose…").format(id=point_id), LEVEL_INFO)
        self._watch(link, link.submit(CreatePoint(point_id, None, self.teach_tool)))
        return point_id

    def upload(self, point_ids: Iterable[int], *, restore: bool = False) -> bool:
        """Create these points on the controller (one request; the link groups them by tool frame,
        keeping the ledger order within each)."""
        wanted = set(point_ids)
        points = [p for p in self._model.ledger if p.id in wanted]
        if not points:
            self._say(self.tr("No points to upload"), LEVEL_WARN)
            return False
        link = self._ready(self.tr("Upload"))
        if link is None:
            return False
        upload = UploadTally({p.id: p for p in points}, restore)
        self._upload = upload
        self._set_operation("upload")
        self.uploadProgress.emit(0, len(points))
        self._say(self.tr("Uploading {n} points…").format(n=len(points)), LEVEL_INFO)
        self._watch(link, link.submit(UploadPoints.of((p.id, p.xyzabc, p.tool) for p in points)))
        return True

    def upload_needed(self) -> bool:
        """Upload every point that is not known to be on the controller."""
        return self.upload([p.id for p in self._model.ledger.needing_upload()])

    def restore_all(self) -> bool:
        """Re-create every point of the ledger (after a controller restart)."""
        return self.upload(self._model.ledger.ids(), restore=True)

    def cancel_upload(self) -> None:
        """End the upload after the point being created (no controller stop); the points done
        so far are recorded."""
        upload = self._upload
        if upload is None:
            return
        if upload.link_lost is not None:  # nothing more will come from the worker for it
            self._finish_upload(aborted=upload.link_lost)
            return
        if upload.cancelled:
            return
        upload.cancelled = True
        if self._link is not None:
            self._link.submit(CancelUpload())
        self._say(self.tr("Cancelling the upload…"), LEVEL_WARN)

    def move_to(self, point_id: int, speed: float = DEFAULT_MOVE_SPEED) -> bool:
        """Line move to a point (function 3), guarded: the point is created again from the
        ledger first, the arrival is checked after (see the module docstring). The caller asks
        the operator first."""
        point = self._model.ledger.get(point_id)
        if point is None:
            self._say(self.tr("There is no point P{id}").format(id=point_id), LEVEL_ERROR)
            return False
        if not 0 < speed <= MAX_MOVE_SPEED:
            self._say(self.tr("Speed {v} mm/s is out of range").format(v=speed), LEVEL_ERROR)
            return False
        link = self._ready(self.tr("Move"))
        if link is None:
            return False
        prepared = self._guard.begin(point_id, (point_id,))
        self._move_id = point_id
        self._move_speed = float(speed)
        self._move_stops = link.state.stops_requested
        self._set_operation("move")
        self._say(
            self.tr("Moving to {point} at {v} mm/s…").format(point=point.label, v=f"{speed:g}"), LEVEL_INFO
        )
        self._watch(
            link, link.submit(UploadPoints.of(prepared.items()))
        )  # the move follows once it is created
        return True

    def _move_point_created(self, result: CommandResult) -> None:
        """The move's point was created again (or not): send the move, or fail it unsent."""
        link, guard = self._link, self._guard
        assert link is not None
        prepared = guard.finish_upload(link.state.connection.endpoint)
        guard.clear()
        assert prepared is not None
        stopped_since = link.state.stops_requested != self._move_stops  # a Stop after the create's answer
        if stopped_since or not (result.ok and prepared.all_created):
            if stopped_since or batch_reason(result.message) == "stopped":  # the operator's Stop
                self._move_id = None
                self._set_operation("")
                self._say(
                    self.tr("Move to P{id} stopped by the operator").format(id=prepared.end_id), LEVEL_INFO
                )
                self.moveFinished.emit(False, "stopped")
            else:
                self._fail_move(prepared.end_id, error_text(guard.not_created(prepared)))
            return
        point = prepared.points[prepared.end_id]
        self._prepared = prepared
        self.movePrepared.emit(point.id)
        self._watch(
            link,
            link.submit(
                MoveToPoint(
                    point.id,
                    None,
                    orientation_changes=True,
                    ignore_middle=False,
                    speed=self._move_speed,
                    tool=point.tool,
                )
            ),
        )

    def points_missing(self, point_ids: Iterable[int]) -> None:
        """The controller said it does not hold these points (e.g. "bad end point id"):
        they are not known to be on it any more, and "Restore all" is offered."""
        ledger = self._model.ledger
        for point_id in point_ids:
            point = ledger.get(point_id)
            if point is not None and point.sync is SyncState.ON_CONTROLLER:
                self._model.set_sync(point_id, SyncState.UNKNOWN)
        if len(ledger):
            self._offer_restore(True)
            self._say(
                self.tr(
                    "The controller does not hold the plan's points (did it restart?): "
                    "Restore all to re-create them."
                ),
                LEVEL_WARN,
            )

    def stop(self) -> None:
        """Stop whatever runs (a move, an upload)."""
        if self._upload is not None:
            self.cancel_upload()
        elif self._link is not None:
            self._link.submit(Stop())

    # --- internals
    def _watch(self, link: LinkPort, request_id: int) -> None:
        """Hear the progress and outcome of this request (and of no other)."""
        pending = link.track(request_id)
        self._pending = pending
        pending.progressed.connect(lambda progress: self._on_progress(pending, progress))
        pending.finished.connect(lambda result: self._on_result(pending, result))
        pending.failed.connect(lambda error: self._on_error(pending, error))

    def _ready(self, what: str) -> LinkPort | None:
        if self._link is None or not self.connected:
            self._say(self.tr("{what}: not connected to a controller").format(what=what), LEVEL_ERROR)
            return None
        if self._operation:
            self._say(self.tr("{what}: wait until the current operation ends").format(what=what), LEVEL_WARN)
            return None
        return self._link

    def _say(self, text: str, level: str) -> None:
        self.statusMessage.emit(text, level)

    def _set_operation(self, operation: str) -> None:
        was = bool(self._operation)
        self._operation = operation
        if not operation:
            self._pending = None  # a late outcome of what ended here is not ours any more
        if was != bool(operation):
            self.busyChanged.emit(bool(operation))

    def _offer_restore(self, offered: bool) -> None:
        if offered != self._restore_offered:
            self._restore_offered = offered
            self.restoreOffered.emit(offered)

    @Slot(ConnectionState)
    def _on_connection(self, state: ConnectionState) -> None:
        connected = state.connected
        controller = state.controller  # set while the link is up (connected or not answering)
        if controller is None:
            self._live = False  # down, connecting, disconnected: the next identity is a new connection
        elif not (self._live and controller == self._controller):  # not a blip of the same connection
            self._live = True
            self._identify(controller)  # the states first: views of connectedChanged read them
        self.connectedChanged.emit(connected)
        if not connected and self._operation:
            reason = connection_text(state) or self.tr("link lost")
            if self._upload is not None:
                # The worker still reports the points it finished, then ends the batch: wait for it.
                self._upload.link_lost = reason
            else:
                self._abort(reason)

    def _identify(self, controller: ControllerIdentity) -> None:
        """The link is up to ``controller``: unless it is provably the controller and boot the
        sync states were made with, nothing is known to be on it any more."""
        previous, self._controller = self._controller, controller
        if controller.same_boot(previous):
            return
        self._flush_upload()  # what the controller confirmed before it changed
        changed = self._model.mark_all_unknown()
        n = len(self._model.ledger)
        if not n or (previous is None and not changed):
            return  # the first controller these points meet, and none was believed on one
        self._offer_restore(True)
        if previous is not None and not controller.same_place(previous):
            text = self.tr(
                "Connected to another controller ({endpoint}): {n} points are not known to be on it. "
                "Restore all to create them there."
            ).format(endpoint=controller.endpoint, n=n)
        else:
            text = self.tr(
                "The controller restarted, or it is not the one the points were uploaded to: {n} "
                "points may be gone from it. Restore all to re-create them."
            ).format(n=n)
        self._say(text, LEVEL_WARN)

    def _on_error(self, pending: Pending, error: WorkerError) -> None:
        if pending is self._pending:
            self._pending = None
            self._abort(error_text(error))

    def _on_result(self, pending: Pending, result: CommandResult) -> None:
        if pending is not self._pending:
            return  # an operation that was already given up (link lost)
        self._pending = None
        if self._operation == "teach":
            self._finish_teach(result)
        elif self._operation == "move" and self._guard.segment is not None:
            self._move_point_created(result)
        elif self._operation == "move":
            self._finish_move(result)
        elif self._operation == "upload":
            self._upload_done(result)

    def _abort(self, reason: str) -> None:
        operation = self._operation
        if operation == "teach":
            self._teach_id = None
            self._set_operation("")
            self._say(self.tr("Teach failed: {reason}").format(reason=reason), LEVEL_ERROR)
        elif operation == "move":
            if self._guard.segment is not None:  # while its point was being created
                self._guard.finish_upload(self._link.state.connection.endpoint if self._link else "")
                self._guard.clear()
            self._move_id = None
            self._prepared = None
            self._set_operation("")
            self.moveFinished.emit(False, reason)
            self._say(self.tr("Move failed: {reason}").format(reason=reason), LEVEL_ERROR)
        elif operation == "upload":
            self._finish_upload(aborted=reason)

    # teach
    def _finish_teach(self, result: CommandResult) -> None:
        point_id, self._teach_id = self._teach_id, None
        self._set_operation("")
        assert point_id is not None
        if not result.ok:
            reason = result_reason(result)
            self._say(self.tr("Teach P{id} failed: {reason}").format(id=point_id, reason=reason), LEVEL_ERROR)
            return
        pose = pose_from_details(result.details, self.last_pose)
        if pose is None:
            self._say(
                self.tr("P{id} was created on the controller, but its pose is not known yet").format(
                    id=point_id
                ),
                LEVEL_ERROR,
            )
            return
        if self._model.ledger.get(point_id) is not None:
            # Someone added P{id} on the host meanwhile: the controller's copy is the taught pose.
            self._model.set_sync(point_id, SyncState.CHANGED)
            text = self.tr(
                "P{id} was added on the host while teaching; the controller now holds the "
                "taught pose: upload it to keep the host's values"
            ).format(id=point_id)
            self._say(text, LEVEL_WARN)
            return
        try:
            self._model.add_taught_point(point_id, pose, name=self._teach_name, tool=self.teach_tool)
        except InvalidInput as exc:
            why = refusal_text(exc)
            self._say(self.tr("Teach P{id}: {reason}").format(id=point_id, reason=why), LEVEL_ERROR)
            return
        if result.unconfirmed:  # created without an error, but not proven: not "on controller"
            self._model.set_sync(point_id, SyncState.UNCONFIRMED)
        self._say(
            self.tr("Taught P{id} at X {x:.3f}  Y {y:.3f}  Z {z:.3f}").format(
                id=point_id, x=pose.x, y=pose.y, z=pose.z
            ),
            LEVEL_INFO,
        )
        self.pointTaught.emit(point_id)

    # move
    def _finish_move(self, result: CommandResult) -> None:
        point_id, self._move_id = self._move_id, None
        prepared, self._prepared = self._prepared, None
        if result.ok and prepared is not None:
            # the pose that came with the result, else the link's latest (the poll that completed
            # the move publishes its pose before the result): the 1 mm rule of the plan runs
            error = self._guard.check_arrival(prepared, pose_from_details(result.details, self.last_pose))
            if error is not None:
                self._fail_move(point_id, error_text(error))
                return
        self._set_operation("")
        if result.ok:
            self._say(self.tr("Reached P{id}").format(id=point_id), LEVEL_INFO)
            self.moveFinished.emit(True, "")
        elif result.stopped_by_operator:
            reason = result_reason(result)
            self._say(self.tr("Move to P{id} stopped by the operator").format(id=point_id), LEVEL_INFO)
            self.moveFinished.emit(False, reason)
        else:
            reason = result_reason(result)
            missing = result.status is not None and result.status.code == MoveStatus.BAD_END_POINT
            if missing and point_id is not None:
                self._point_gone(point_id)
            self._say(
                self.tr("Move to P{id} failed: {reason}").format(id=point_id, reason=reason), LEVEL_ERROR
            )
            self.moveFinished.emit(False, reason)

    def _fail_move(self, point_id: int | None, reason: str) -> None:
        """The guarded move failed for ``reason`` (its point not created, or the arm elsewhere)."""
        self._move_id = None
        self._prepared = None
        self._set_operation("")
        self._say(self.tr("Move to P{id} failed: {reason}").format(id=point_id, reason=reason), LEVEL_ERROR)
        self.moveFinished.emit(False, reason)

    def _point_gone(self, point_id: int) -> None:
        """The controller does not hold ``point_id`` ("bad end point id"): not known to be on it."""
        if self._model.ledger.get(point_id) is not None:
            self._model.set_sync(
                point_id, SyncState.UNKNOWN, "the controller answered that it does not hold this point"
            )
            self._offer_restore(True)

    # upload
    def _on_progress(self, pending: Pending, progress: Progress) -> None:
        """The progress of the request under way (an upload's, or the upload of a move's point)."""
        if pending is not self._pending:
            return  # an operation that was already given up
        if isinstance(progress, PointUploaded):
            self._on_point_uploaded(progress)
        elif isinstance(progress, UploadProgress):
            self._on_upload_progress(progress)

    def _on_point_uploaded(self, point: PointUploaded) -> None:
        if self._upload is not None:
            self._upload.record(point.point_id, point.ok, point.reason, point.unconfirmed)
        elif self._operation == "move":  # the move's own point
            self._guard.on_point_uploaded(point.point_id, point.ok, point.reason, point.unconfirmed)

    def _flush_upload(self) -> None:
        """Apply the outcomes reported since the last flush to the ledger (one model update)."""
        upload = self._upload
        if upload is not None and upload.pending:
            batch = upload.take_pending()
            created = [o.point_id for o in batch if o.ok]
            if created:  # before the sync states: the project's dirty check follows syncChanged
                endpoint = self._link.state.connection.endpoint if self._link is not None else ""
                self._model.project.record_upload(created, endpoint or "controller")
            self._model.apply_upload(UploadReport(outcomes=batch))

    def _on_upload_progress(self, progress: UploadProgress) -> None:
        upload = self._upload
        if upload is not None and self._operation == "upload":
            self._flush_upload()
            self.uploadProgress.emit(min(progress.done, upload.total), upload.total)

    def _upload_done(self, result: CommandResult) -> None:
        upload = self._upload
        assert upload is not None
        self._flush_upload()
        attempted = upload.attempted
        self.uploadProgress.emit(attempted, upload.total)
        if attempted >= upload.total:
            self._finish_upload(aborted=None)
        elif upload.cancelled:
            self._finish_upload(aborted=self.tr("cancelled"))
        else:
            batch = result_text(result) if result.reason else batch_reason(result.message)
            reason = upload.link_lost or batch or self.tr("stopped")
            self._finish_upload(aborted=reason)

    def _finish_upload(self, aborted: str | None) -> None:
        self._flush_upload()
        upload, self._upload = self._upload, None
        self._set_operation("")
        if upload is None:
            return
        report = upload.close(aborted)
        ok, failed = report.ok_count, len(report.failed)
        if report.all_ok:
            self._say(self.tr("Uploaded {n} points").format(n=ok), LEVEL_INFO)
            if upload.restore:
                self._offer_restore(False)
        elif aborted is not None:
            self._say(
                self.tr("Upload stopped after {ok} of {total} points: {reason}").format(
                    ok=ok, total=upload.total, reason=aborted
                ),
                LEVEL_WARN,
            )
        else:
            first = report.failed[0]
            text = self.tr("Uploaded {ok} of {total} points; {failed} failed (P{id}: {reason})").format(
                ok=ok, total=upload.total, failed=failed, id=first.point_id, reason=first.reason
            )
            self._say(text, LEVEL_ERROR)
        self.uploadFinished.emit(report)

"""The temp point panel: the ledger table, teach, upload / restore, move to a point.

Two classes:

* :class:`PointSyncController` (a ``QObject``, no widgets) drives the robot link for the
  ledger: teach a point from the current pose (function 2, "from the current pose"), upload
  points (function 2 from GVs, batched by tool frame), restore them all after a controller
  restart, move to a point (function 3, line). It records the outcome in the
  :class:`~ui.models.points_model.PointsModel` and says what happened through signals.
* :class:`PointsPanel` (the widget): toolbar, reconnect banner, upload progress, the table
  (filter by id / name, E1..E5 hideable) and a status line.

The link is anything that fits :class:`PointLink` (``app.link.worker.RobotLink`` does); the tests
use a small fake.

Completion of the link's commands is matched by request id: every link command returns one
and the ``commandFinished`` / ``errorOccurred`` that ends it carries it. An upload is one
request: ``pointUploaded`` marks each point on the controller / failed as it goes (applied to
the ledger at each ``uploadProgress`` and at the end, so a cancel or a lost link half way
leaves exact states), and the batch's ``commandFinished`` ends it. Teach reads the pose back
from the ``x``..``c`` details that ``RobotLink`` adds to a successful create-point result (the
pose polled together with the completion); without them it uses the latest ``poseChanged``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from PySide6.QtCore import QEvent, QModelIndex, QObject, QPoint, Qt, Signal, SignalInstance, Slot
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDoubleSpinBox,
    QFrame,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QMenu,
    QMessageBox,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QTableView,
    QToolBar,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.errors import InvalidInput
from app.models import CommandResult, Pose
from app.points.ledger import SyncState, TempPoint, UploadOutcome, UploadReport
from app.protocol.registers import TOOL_NONE
from ui.models.point_columns import COL_ID, COL_NAME, COL_SYNC, COLUMNS, EXT_COLUMNS, sync_text
from ui.models.points_model import PointFilterProxy, PointsModel
from ui.widgets_common import COLOR_ERROR, COLOR_OK, COLOR_WARN, COLOR_WARN_BG, command_status_text

DEFAULT_MOVE_SPEED = 50.0  # mm/s for "move to point"
MAX_MOVE_SPEED = 1000.0
POSE_DETAIL_KEYS: tuple[str, ...] = ("x", "y", "z", "a", "b", "c")

LEVEL_INFO = "info"
LEVEL_WARN = "warn"
LEVEL_ERROR = "error"


class PointLink(Protocol):
    """What the point panel needs from the robot link (``app.link.worker.RobotLink`` fits)."""

    poseChanged: SignalInstance  # (Pose)
    commandFinished: SignalInstance  # (CommandResult, .request_id)
    errorOccurred: SignalInstance  # (WorkerError: .operation, .message, .request_id)
    connectionChanged: SignalInstance  # (ConnectionState: .connected, .message)
    controllerReconnected: SignalInstance  # ()
    uploadProgress: SignalInstance  # (done, total) of the running upload
    pointUploaded: SignalInstance  # (point id, ok, reason)
    # optional: controllerRestarted (), the restart canary; handled like controllerReconnected

    @property
    def state(self) -> Any: ...  # ConnectionState

    def create_point(self, point_id: int, pose: Sequence[float] | None = None, tool: int = ...) -> int: ...

    def upload_points(self, points: Iterable[tuple[int, Sequence[float], int]]) -> int: ...

    def cancel_upload(self) -> int: ...

    def move_to_point(self, end_id: int, via_id: int | None = None, *, orientation_changes: bool = ...,
                      ignore_middle: bool = ..., speed: float = ..., tool: int = ...) -> int: ...

    def stop(self) -> int: ...


def result_reason(result: CommandResult) -> str:
    """The decoded reason of a failed result (GV291 meaning and the worker's message)."""
    status = command_status_text(result) if result.status is not None else ""
    if result.message and status and status not in result.message:
        return f"{status} — {result.message}"
    return result.message or status or "failed"


def _pose_from_details(details: dict[str, float], fallback: Pose | None) -> Pose | None:
    if all(k in details for k in POSE_DETAIL_KEYS):
        x, y, z, a, b, c = (float(details[k]) for k in POSE_DETAIL_KEYS)
        return Pose(x, y, z, a, b, c, ext=fallback.ext if fallback else (0.0,) * 5)
    return fallback


@dataclass
class _Upload:
    points: dict[int, TempPoint]  # id -> the point as sent (ledger order)
    restore: bool
    request_id: int = 0
    report: UploadReport = field(default_factory=UploadReport)
    pending: list[UploadOutcome] = field(default_factory=list)  # reported, not yet in the ledger
    cancelled: bool = False
    link_lost: str | None = None  # the link went down: waiting for the worker's final result

    @property
    def total(self) -> int:
        return len(self.points)


class PointSyncController(QObject):
    """Teach / upload / restore / move for the ledger through the link (GUI thread).

    Signals: ``busyChanged(bool)``, ``connectedChanged(bool)``, ``statusMessage(str, str)``
    (text, level "info" / "warn" / "error"), ``pointTaught(int)`` (id), ``uploadProgress(int,
    int)`` (points done, total), ``uploadFinished(object)`` (:class:`UploadReport` of the whole
    request), ``restoreOffered(bool)`` (show / hide "Restore all"), ``moveFinished(bool, str)``.
    """

    busyChanged = Signal(bool)
    connectedChanged = Signal(bool)
    statusMessage = Signal(str, str)
    pointTaught = Signal(int)
    uploadProgress = Signal(int, int)
    uploadFinished = Signal(object)
    restoreOffered = Signal(bool)
    moveFinished = Signal(bool, str)

    def __init__(self, model: PointsModel, link: PointLink | None = None,
                 parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._model = model
        self._link: PointLink | None = None
        self._connected = False
        self._operation = ""  # "teach" | "upload" | "move" | ""
        self._teach_id: int | None = None
        self._teach_name = ""
        self._move_id: int | None = None
        self._request = 0  # request id of the running teach / move
        self._upload: _Upload | None = None
        self._last_pose: Pose | None = None
        self._restore_offered = False
        self.teach_tool = TOOL_NONE
        if link is not None:
            self.set_link(link)

    # --- state
    @property
    def model(self) -> PointsModel:
        return self._model

    @property
    def link(self) -> PointLink | None:
        return self._link

    @property
    def connected(self) -> bool:
        return self._connected

    @property
    def busy(self) -> bool:
        return bool(self._operation)

    @property
    def operation(self) -> str:
        return self._operation

    @property
    def last_pose(self) -> Pose | None:
        return self._last_pose

    @property
    def restore_offered(self) -> bool:
        return self._restore_offered

    def set_link(self, link: PointLink) -> None:
        if self._link is not None:
            raise RuntimeError("the link is already set")
        self._link = link
        link.poseChanged.connect(self._on_pose)
        link.commandFinished.connect(self._on_result)
        link.errorOccurred.connect(self._on_error)
        link.connectionChanged.connect(self._on_connection)
        link.controllerReconnected.connect(self._on_reconnected)
        restarted = getattr(link, "controllerRestarted", None)  # the restart canary (RobotLink)
        if restarted is not None:
            restarted.connect(self._on_reconnected)  # the same path: the points may be gone
        link.uploadProgress.connect(self._on_upload_progress)
        link.pointUploaded.connect(self._on_point_uploaded)
        state = getattr(link, "state", None)
        self._set_connected(bool(getattr(state, "connected", False)))

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
            self._say(str(exc), LEVEL_ERROR)
            return None
        self._teach_id = point_id
        self._teach_name = name
        self._set_operation("teach")
        self._say(self.tr("Teaching P{id} at the current pose…").format(id=point_id), LEVEL_INFO)
        self._request = link.create_point(point_id, None, self.teach_tool)
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
        upload = _Upload({p.id: p for p in points}, restore)
        self._upload = upload
        self._set_operation("upload")
        self.uploadProgress.emit(0, len(points))
        self._say(self.tr("Uploading {n} points…").format(n=len(points)), LEVEL_INFO)
        upload.request_id = link.upload_points([(p.id, p.xyzabc, p.tool) for p in points])
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
            self._link.cancel_upload()
        self._say(self.tr("Cancelling the upload…"), LEVEL_WARN)

    def move_to(self, point_id: int, speed: float = DEFAULT_MOVE_SPEED) -> bool:
        """Line move to a point (function 3). The caller asks the operator first."""
        point = self._model.ledger.get(point_id)
        if point is None:
            self._say(self.tr("There is no point P{id}").format(id=point_id), LEVEL_ERROR)
            return False
        if point.needs_upload:
            self._say(self.tr("{point} is not on the controller ({state}): upload it first").format(
                point=point.label, state=sync_text(point.sync)), LEVEL_ERROR)
            return False
        if not 0 < speed <= MAX_MOVE_SPEED:
            self._say(self.tr("Speed {v} mm/s is out of range").format(v=speed), LEVEL_ERROR)
            return False
        link = self._ready(self.tr("Move"))
        if link is None:
            return False
        self._move_id = point_id
        self._set_operation("move")
        self._say(self.tr("Moving to {point} at {v} mm/s…").format(point=point.label, v=f"{speed:g}"),
                  LEVEL_INFO)
        self._request = link.move_to_point(point_id, None, orientation_changes=True, ignore_middle=False,
                                           speed=float(speed), tool=point.tool)
        return True

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
            self._say(self.tr("The controller does not hold the plan's points (did it restart?): "
                              "Restore all to re-create them."), LEVEL_WARN)

    def stop(self) -> None:
        """Stop whatever runs (a move, an upload)."""
        if self._upload is not None:
            self.cancel_upload()
        elif self._link is not None:
            self._link.stop()

    # --- internals
    def _ready(self, what: str) -> PointLink | None:
        if self._link is None or not self._connected:
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
        if was != bool(operation):
            self.busyChanged.emit(bool(operation))

    def _set_connected(self, connected: bool) -> None:
        if connected != self._connected:
            self._connected = connected
            self.connectedChanged.emit(connected)

    def _offer_restore(self, offered: bool) -> None:
        if offered != self._restore_offered:
            self._restore_offered = offered
            self.restoreOffered.emit(offered)

    @Slot(object)
    def _on_pose(self, pose: Pose) -> None:
        self._last_pose = pose

    @Slot(object)
    def _on_connection(self, state: Any) -> None:
        connected = bool(getattr(state, "connected", False))
        self._set_connected(connected)
        if not connected and self._operation:
            reason = getattr(state, "message", "") or self.tr("link lost")
            if self._upload is not None:
                # The worker still reports the points it finished, then ends the batch: wait for it.
                self._upload.link_lost = reason
            else:
                self._abort(reason)

    @Slot()
    def _on_reconnected(self) -> None:
        """The controller restarted (canary) or the link came back: its points may be gone."""
        self._flush_upload()
        self._model.mark_all_unknown()
        if len(self._model.ledger):
            self._offer_restore(True)
            self._say(self.tr("The controller restarted or reconnected: {n} points may be gone from it. "
                              "Restore all to re-create them.").format(n=len(self._model.ledger)), LEVEL_WARN)

    def _current_request(self) -> int | None:
        if self._upload is not None:
            return self._upload.request_id
        return self._request if self._operation in ("teach", "move") else None

    @Slot(object)
    def _on_error(self, error: Any) -> None:
        request_id = getattr(error, "request_id", None)
        if request_id is not None and request_id == self._current_request():
            self._abort(str(getattr(error, "message", error)))

    @Slot(object)
    def _on_result(self, result: CommandResult) -> None:
        if result.request_id is None or result.request_id != self._current_request():
            return
        if self._operation == "teach":
            self._finish_teach(result)
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
            self._move_id = None
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
        pose = _pose_from_details(result.details, self._last_pose)
        if pose is None:
            self._say(self.tr("P{id} was created on the controller, but its pose is not known yet").format(
                id=point_id), LEVEL_ERROR)
            return
        if self._model.ledger.get(point_id) is not None:
            # Someone added P{id} on the host meanwhile: the controller's copy is the taught pose.
            self._model.set_sync(point_id, SyncState.CHANGED)
            text = self.tr("P{id} was added on the host while teaching; the controller now holds the "
                           "taught pose: upload it to keep the host's values").format(id=point_id)
            self._say(text, LEVEL_WARN)
            return
        try:
            self._model.add_taught_point(point_id, pose, name=self._teach_name, tool=self.teach_tool)
        except InvalidInput as exc:
            self._say(self.tr("Teach P{id}: {reason}").format(id=point_id, reason=str(exc)), LEVEL_ERROR)
            return
        self._say(self.tr("Taught P{id} at X {x:.3f}  Y {y:.3f}  Z {z:.3f}").format(
            id=point_id, x=pose.x, y=pose.y, z=pose.z), LEVEL_INFO)
        self.pointTaught.emit(point_id)

    # move
    def _finish_move(self, result: CommandResult) -> None:
        point_id, self._move_id = self._move_id, None
        self._set_operation("")
        if result.ok:
            self._say(self.tr("Reached P{id}").format(id=point_id), LEVEL_INFO)
            self.moveFinished.emit(True, "")
        else:
            reason = result_reason(result)
            self._say(self.tr("Move to P{id} failed: {reason}").format(id=point_id, reason=reason),
                      LEVEL_ERROR)
            self.moveFinished.emit(False, reason)

    # upload
    @Slot(int, bool, str)
    def _on_point_uploaded(self, point_id: int, ok: bool, reason: str) -> None:
        upload = self._upload
        if upload is None or point_id not in upload.points:
            return
        sent = upload.points[point_id]
        outcome = UploadOutcome(point_id, True, sent=sent) if ok else UploadOutcome(point_id, False, reason)
        upload.report.outcomes.append(outcome)
        upload.pending.append(outcome)

    def _flush_upload(self) -> None:
        """Apply the outcomes reported since the last flush to the ledger (one model update)."""
        upload = self._upload
        if upload is not None and upload.pending:
            batch, upload.pending = upload.pending, []
            self._model.apply_upload(UploadReport(outcomes=batch))

    @Slot(int, int)
    def _on_upload_progress(self, done: int, total: int) -> None:
        upload = self._upload
        if upload is not None and self._operation == "upload":
            self._flush_upload()
            self.uploadProgress.emit(min(done, upload.total), upload.total)

    def _upload_done(self, result: CommandResult) -> None:
        upload = self._upload
        assert upload is not None
        self._flush_upload()
        attempted = len(upload.report.outcomes)
        self.uploadProgress.emit(attempted, upload.total)
        if attempted >= upload.total:
            self._finish_upload(aborted=None)
        elif upload.cancelled:
            self._finish_upload(aborted=self.tr("cancelled"))
        else:
            reason = upload.link_lost or _batch_reason(result.message) or self.tr("stopped")
            self._finish_upload(aborted=reason)

    def _finish_upload(self, aborted: str | None) -> None:
        self._flush_upload()
        upload, self._upload = self._upload, None
        self._set_operation("")
        if upload is None:
            return
        report = upload.report
        done_ids = {o.point_id for o in report.outcomes}
        if aborted is not None:
            report.aborted = aborted
            report.not_attempted = [pid for pid in upload.points if pid not in done_ids]
        ok, failed = report.ok_count, len(report.failed)
        if report.all_ok:
            self._say(self.tr("Uploaded {n} points").format(n=ok), LEVEL_INFO)
            if upload.restore:
                self._offer_restore(False)
        elif aborted is not None:
            self._say(self.tr("Upload stopped after {ok} of {total} points: {reason}").format(
                ok=ok, total=upload.total, reason=aborted), LEVEL_WARN)
        else:
            first = report.failed[0]
            text = self.tr("Uploaded {ok} of {total} points; {failed} failed (P{id}: {reason})").format(
                ok=ok, total=upload.total, failed=failed, id=first.point_id, reason=first.reason)
            self._say(text, LEVEL_ERROR)
        self.uploadFinished.emit(report)


def _batch_reason(message: str) -> str:
    """Why an upload ended early, from the link's "uploaded N of M points (reason)"."""
    _head, sep, tail = message.partition(" (")
    return tail[:-1] if sep and tail.endswith(")") else message


# --------------------------------------------------------------------------------------------
# The widget
# --------------------------------------------------------------------------------------------

ConfirmCallable = Callable[[str, str], bool]  # (title, question) -> go ahead?


class PointsPanel(QWidget):
    """Point ledger panel; see the module docstring.

    Public: the ``action_*`` QActions (teach Ctrl+T, add, duplicate, delete, move up/down,
    upload selected / all / needed, restore all, cancel upload, move to point, show E1..E5,
    find Ctrl+F), ``selected_rows()`` / ``select_rows()``, ``set_run_active(bool)`` (disables
    motion while a plan runs), signal ``statusMessage(str)``.
    """

    statusMessage = Signal(str)

    def __init__(self, model: PointsModel, controller: PointSyncController | None = None,
                 parent: QWidget | None = None, *, confirm: ConfirmCallable | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("PointsPanel")
        self._model = model
        self._controller = controller or PointSyncController(model, parent=self)
        self._confirm = confirm or self._ask
        self._run_active = False

        self.proxy = PointFilterProxy(self)
        self.proxy.setSourceModel(model)

        self._make_actions()
        self._build()
        self.retranslate()

        model.editRejected.connect(self._on_rejected)
        model.modelReset.connect(self._update_actions)
        model.rowsInserted.connect(self._update_actions)
        model.rowsRemoved.connect(self._update_actions)
        model.rowsMoved.connect(self._update_actions)
        c = self._controller
        c.statusMessage.connect(self.show_message)
        c.busyChanged.connect(self._update_actions)
        c.connectedChanged.connect(self._update_actions)
        c.restoreOffered.connect(self._on_restore_offered)
        c.uploadProgress.connect(self._on_upload_progress)
        c.uploadFinished.connect(self._on_upload_finished)
        c.pointTaught.connect(self._on_taught)
        self.table.selectionModel().selectionChanged.connect(self._update_actions)
        self._on_restore_offered(c.restore_offered)
        self._update_actions()

    # --- construction
    def _make_actions(self) -> None:
        def act(shortcut: QKeySequence | QKeySequence.StandardKey | str | None = None,
                slot: Callable[[], Any] | None = None,
                checkable: bool = False) -> QAction:
            action = QAction(self)
            if shortcut is not None:
                action.setShortcut(QKeySequence(shortcut))
                action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.setCheckable(checkable)
            if slot is not None:
                action.triggered.connect(slot)
            self.addAction(action)
            return action

        self.action_teach = act("Ctrl+T", self.teach)
        self.action_teach.setShortcutContext(Qt.ShortcutContext.WindowShortcut)
        self.action_add = act("Ctrl+Shift+N", self.add_point)
        self.action_duplicate = act("Ctrl+D", self.duplicate_selected)
        self.action_delete = act(QKeySequence.StandardKey.Delete, self.delete_selected)
        self.action_move_up = act("Alt+Up", lambda: self.move_selected(-1))
        self.action_move_down = act("Alt+Down", lambda: self.move_selected(1))
        self.action_upload_selected = act(None, self.upload_selected)
        self.action_upload_all = act(None, self.upload_all)
        self.action_upload_needed = act(None, self._controller.upload_needed)
        self.action_restore_all = act(None, self._controller.restore_all)
        self.action_cancel_upload = act(None, self._controller.cancel_upload)
        self.action_move_to = act("Ctrl+M", self.move_to_selected)
        self.action_show_ext = act(None, None, checkable=True)
        self.action_show_ext.toggled.connect(self._show_ext)
        self.action_find = act(QKeySequence.StandardKey.Find, self._focus_find)

    def _build(self) -> None:
        bar = QToolBar(self)
        bar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        bar.addAction(self.action_teach)
        teach_button = bar.widgetForAction(self.action_teach)
        font = teach_button.font()
        font.setBold(True)
        teach_button.setFont(font)
        bar.addSeparator()
        for action in (self.action_add, self.action_duplicate, self.action_delete, self.action_move_up,
                       self.action_move_down):
            bar.addAction(action)
        bar.addSeparator()
        self.upload_button = QToolButton(self)
        self.upload_button.setDefaultAction(self.action_upload_selected)
        self.upload_button.setPopupMode(QToolButton.ToolButtonPopupMode.MenuButtonPopup)
        upload_menu = QMenu(self.upload_button)
        upload_menu.addAction(self.action_upload_selected)
        upload_menu.addAction(self.action_upload_needed)
        upload_menu.addAction(self.action_upload_all)
        upload_menu.addAction(self.action_restore_all)
        self.upload_button.setMenu(upload_menu)
        bar.addWidget(self.upload_button)
        bar.addSeparator()
        bar.addAction(self.action_move_to)
        self.speed = QDoubleSpinBox(self)
        self.speed.setRange(0.1, MAX_MOVE_SPEED)
        self.speed.setDecimals(1)
        self.speed.setValue(DEFAULT_MOVE_SPEED)
        self.speed.setSuffix(" mm/s")
        self.speed.setKeyboardTracking(False)
        bar.addWidget(self.speed)
        self.toolbar = bar

        self.find_edit = QLineEdit(self)
        self.find_edit.setClearButtonEnabled(True)
        self.find_edit.setMaximumWidth(220)
        self.find_edit.textChanged.connect(self.proxy.set_filter_text)
        self.ext_button = QToolButton(self)
        self.ext_button.setDefaultAction(self.action_show_ext)
        self.ext_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)

        top = QHBoxLayout()
        top.setContentsMargins(0, 0, 0, 0)
        top.addWidget(bar, 1)
        self.find_label = QLabel(self)
        top.addWidget(self.find_label)
        top.addWidget(self.find_edit)
        top.addWidget(self.ext_button)

        # banner: the controller may have lost its points
        self.banner = QFrame(self)
        self.banner.setObjectName("restoreBanner")
        self.banner.setStyleSheet(f"#restoreBanner {{ background: {COLOR_WARN_BG}; "
                                  f"border: 1px solid {COLOR_WARN}; border-radius: 4px; }}")
        banner_row = QHBoxLayout(self.banner)
        banner_row.setContentsMargins(8, 4, 8, 4)
        self.banner_label = QLabel(self.banner)
        self.banner_label.setWordWrap(True)
        self.restore_button = QPushButton(self.banner)
        self.restore_button.clicked.connect(self._controller.restore_all)
        font = self.restore_button.font()
        font.setBold(True)
        self.restore_button.setFont(font)
        banner_row.addWidget(self.banner_label, 1)
        banner_row.addWidget(self.restore_button)

        # upload progress
        self.progress_row = QWidget(self)
        progress = QHBoxLayout(self.progress_row)
        progress.setContentsMargins(0, 0, 0, 0)
        self.progress_label = QLabel(self.progress_row)
        self.progress = QProgressBar(self.progress_row)
        self.progress.setTextVisible(True)
        self.cancel_button = QPushButton(self.progress_row)
        self.cancel_button.clicked.connect(self._controller.cancel_upload)
        progress.addWidget(self.progress_label)
        progress.addWidget(self.progress, 1)
        progress.addWidget(self.cancel_button)
        self.progress_row.hide()

        table = QTableView(self)
        table.setModel(self.proxy)
        table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        table.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        table.setEditTriggers(QAbstractItemView.EditTrigger.DoubleClicked
                              | QAbstractItemView.EditTrigger.EditKeyPressed
                              | QAbstractItemView.EditTrigger.AnyKeyPressed)
        table.setAlternatingRowColors(True)
        table.setWordWrap(False)
        table.verticalHeader().setVisible(False)
        table.verticalHeader().setDefaultSectionSize(24)
        header = table.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        header.setStretchLastSection(True)
        widths = {COL_ID: 56, COL_NAME: 150, COL_SYNC: 130, COLUMNS.index("tool"): 70}
        widths.update(dict.fromkeys(EXT_COLUMNS, 62))  # usually zero: narrower than the pose
        for column in range(len(COLUMNS)):
            table.setColumnWidth(column, widths.get(column, 80))
        table.setContextMenuPolicy(Qt.ContextMenuPolicy.CustomContextMenu)
        table.customContextMenuRequested.connect(self._context_menu)
        self.table = table
        self._show_ext(False)

        self.status = QLabel(self)
        self.status.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.status.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.setSpacing(4)
        layout.addLayout(top)
        layout.addWidget(self.banner)
        layout.addWidget(self.progress_row)
        layout.addWidget(table, 1)
        layout.addWidget(self.status)

    def retranslate(self) -> None:
        texts = {
            self.action_teach: (self.tr("Teach"), self.tr("Create the next temp point on the controller from "
                                                          "the robot's current pose (Ctrl+T)")),
            self.action_add: (self.tr("Add"), self.tr("Add a point on the host (not on the controller yet)")),
            self.action_duplicate: (self.tr("Duplicate"), self.tr("Copy the selected points under new ids")),
            self.action_delete: (self.tr("Delete"),
                                 self.tr("Delete the selected points from the host's list")),
            self.action_move_up: ("▲", self.tr("Move the selected points up (Alt+Up)")),
            self.action_move_down: ("▼", self.tr("Move the selected points down (Alt+Down)")),
            self.action_upload_selected: (self.tr("Upload selected"),
                                          self.tr("Create the selected points on the controller")),
            self.action_upload_needed: (self.tr("Upload changed"),
                                        self.tr("Upload every point not known to be on the controller")),
            self.action_upload_all: (self.tr("Upload all"), self.tr("Create every point on the controller")),
            self.action_restore_all: (self.tr("Restore all"),
                                      self.tr("Re-create all points after a controller restart")),
            self.action_cancel_upload: (self.tr("Cancel upload"), ""),
            self.action_move_to: (self.tr("Move to point"),
                                  self.tr("Move the robot in a line to the selected point (asks first)")),
            self.action_show_ext: (self.tr("E1–E5"), self.tr("Show the external axes columns")),
            self.action_find: (self.tr("Find"), ""),
        }
        for action, (text, tip) in texts.items():
            action.setText(text)
            action.setToolTip(tip or text)
        self.speed.setToolTip(self.tr("Speed of Move to point"))
        self.find_label.setText(self.tr("Find:"))
        self.find_edit.setPlaceholderText(self.tr("id or name"))
        self.banner_label.setText(self.tr("The controller restarted or the link was re-established: its temp "
                                          "points may be gone. Re-create them before running a plan."))
        self.restore_button.setText(self.tr("Restore all"))
        self.cancel_button.setText(self.tr("Cancel"))
        self.progress_label.setText(self.tr("Uploading"))
        self._model.retranslate()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public
    @property
    def model(self) -> PointsModel:
        return self._model

    @property
    def controller(self) -> PointSyncController:
        return self._controller

    def selected_rows(self) -> list[int]:
        """Selected rows of the model (not of the filtered view), ascending."""
        rows = {self.proxy.mapToSource(index).row() for index in self.table.selectionModel().selectedRows()}
        return sorted(r for r in rows if r >= 0)

    def select_rows(self, rows: Iterable[int]) -> None:
        selection = self.table.selectionModel()
        selection.clearSelection()
        first: QModelIndex | None = None
        for row in rows:
            index = self.proxy.mapFromSource(self._model.index(row, 0))
            if not index.isValid():
                continue
            selection.select(index, selection.SelectionFlag.Select | selection.SelectionFlag.Rows)
            first = first or index
        if first is not None:
            selection.setCurrentIndex(first, selection.SelectionFlag.NoUpdate)
            self.table.scrollTo(first)

    def set_confirm(self, confirm: ConfirmCallable) -> None:
        """Replace the operator's yes/no question (tests answer without a dialog)."""
        self._confirm = confirm

    @Slot(bool)
    def set_run_active(self, active: bool) -> None:
        """A plan is running: no teach / upload / move from here."""
        self._run_active = active
        self._update_actions()

    @Slot(str, str)
    def show_message(self, text: str, level: str = LEVEL_INFO) -> None:
        colour = {LEVEL_ERROR: COLOR_ERROR, LEVEL_WARN: "#8a5300", LEVEL_INFO: COLOR_OK}.get(level, "")
        self.status.setStyleSheet(f"color: {colour};" if colour else "")
        self.status.setText(text)
        self.status.setToolTip(text)
        self.statusMessage.emit(text)

    # --- slots of the actions
    @Slot()
    def teach(self) -> None:
        self._controller.teach()

    @Slot()
    def add_point(self) -> None:
        rows = self.selected_rows()
        at = rows[-1] + 1 if rows else None
        try:
            row = self._model.add_point(at)
        except InvalidInput as exc:
            self.show_message(str(exc), LEVEL_ERROR)
            return
        self._clear_filter_for(row)
        self.select_rows([row])

    @Slot()
    def duplicate_selected(self) -> None:
        try:
            rows = self._model.duplicate_rows(self.selected_rows())
        except InvalidInput as exc:
            self.show_message(str(exc), LEVEL_ERROR)
            return
        self.select_rows(rows)

    @Slot()
    def delete_selected(self) -> None:
        rows = self.selected_rows()
        if not rows:
            return
        used = [(p.label, ref) for r in rows for p in [self._model.point_at(r)]
                for ref in self._model.project.references(p.id)]
        n = self._model.remove_rows(rows)
        text = self.tr("Deleted {n} points (Ctrl+Z to undo)").format(n=n)
        if used:
            label, (plan, segment) = used[0]
            text += " — " + self.tr("{point} is used by plan '{plan}' segment {k}").format(
                point=label, plan=plan, k=segment + 1)
            self.show_message(text, LEVEL_WARN)
        else:
            self.show_message(text, LEVEL_INFO)

    def move_selected(self, delta: int) -> None:
        rows = self._model.move_rows(self.selected_rows(), delta)
        self.select_rows(rows)

    @Slot()
    def upload_selected(self) -> None:
        ids = [self._model.point_at(r).id for r in self.selected_rows()]
        self._controller.upload(ids)

    @Slot()
    def upload_all(self) -> None:
        self._controller.upload(self._model.ledger.ids())

    @Slot()
    def move_to_selected(self) -> None:
        rows = self.selected_rows()
        if len(rows) != 1:
            self.show_message(self.tr("Select one point to move to"), LEVEL_WARN)
            return
        point = self._model.point_at(rows[0])
        speed = self.speed.value()
        question = self.tr("Move the robot in a straight line to {point}?\n\n"
                           "X {x:.3f}  Y {y:.3f}  Z {z:.3f}\nA {a:.3f}  B {b:.3f}  C {c:.3f}\n"
                           "Speed {v} mm/s").format(point=point.label, x=point.x, y=point.y, z=point.z,
                                                    a=point.a, b=point.b, c=point.c, v=f"{speed:g}")
        if point.needs_upload:
            self._controller.move_to(point.id, speed)  # refuses with the reason
            return
        if self._confirm(self.tr("Move to point"), question):
            self._controller.move_to(point.id, speed)

    # --- internals
    def _ask(self, title: str, question: str) -> bool:
        answer = QMessageBox.question(self, title, question,
                                      QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Cancel,
                                      QMessageBox.StandardButton.Cancel)
        return answer == QMessageBox.StandardButton.Yes

    def _clear_filter_for(self, row: int) -> None:
        if not self.proxy.mapFromSource(self._model.index(row, 0)).isValid():
            self.find_edit.clear()

    def _focus_find(self) -> None:
        self.find_edit.setFocus()
        self.find_edit.selectAll()

    @Slot(bool)
    def _show_ext(self, shown: bool) -> None:
        for column in EXT_COLUMNS:
            self.table.setColumnHidden(column, not shown)

    @Slot(str)
    def _on_rejected(self, text: str) -> None:
        self.show_message(text, LEVEL_ERROR)

    @Slot(bool)
    def _on_restore_offered(self, offered: bool) -> None:
        self.banner.setVisible(offered)

    @Slot(int, int)
    def _on_upload_progress(self, done: int, total: int) -> None:
        self.progress_row.show()
        self.progress.setRange(0, max(total, 1))
        self.progress.setValue(done)
        self.progress.setFormat(self.tr("%v of %m points"))

    @Slot(object)
    def _on_upload_finished(self, report: UploadReport) -> None:
        self.progress_row.hide()

    @Slot(int)
    def _on_taught(self, point_id: int) -> None:
        row = self._model.row_of(point_id)
        if row is not None:
            self._clear_filter_for(row)
            self.select_rows([row])

    def _context_menu(self, pos: QPoint) -> None:
        index = self.table.indexAt(pos)
        if index.isValid() and not self.table.selectionModel().isRowSelected(index.row(), QModelIndex()):
            self.table.selectRow(index.row())
        menu = QMenu(self)
        for action in (self.action_move_to, self.action_upload_selected, None, self.action_teach,
                       self.action_add, self.action_duplicate, self.action_delete):
            if action is None:
                menu.addSeparator()
            else:
                menu.addAction(action)
        menu.popup(self.table.viewport().mapToGlobal(pos))

    @Slot()
    def _update_actions(self, *_args: Any) -> None:
        rows = self.selected_rows()
        c = self._controller
        link_ok = c.link is not None and c.connected and not c.busy and not self._run_active
        has_points = len(self._model.ledger) > 0
        self.action_teach.setEnabled(link_ok)
        self.action_duplicate.setEnabled(bool(rows))
        self.action_delete.setEnabled(bool(rows))
        self.action_move_up.setEnabled(self._model.can_move(rows, -1))
        self.action_move_down.setEnabled(self._model.can_move(rows, 1))
        self.action_upload_selected.setEnabled(link_ok and bool(rows))
        self.action_upload_all.setEnabled(link_ok and has_points)
        self.action_upload_needed.setEnabled(link_ok and has_points)
        self.action_restore_all.setEnabled(link_ok and has_points)
        self.restore_button.setEnabled(link_ok and has_points)
        self.action_cancel_upload.setEnabled(c.operation == "upload")
        self.cancel_button.setEnabled(c.operation == "upload")
        self.action_move_to.setEnabled(link_ok and len(rows) == 1)
        self.upload_button.setEnabled(link_ok and has_points)

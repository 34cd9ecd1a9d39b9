"""Runs a plan on the controller from the GUI thread, one segment at a time, via the link.

:class:`PlanRunController` wraps :class:`app.plan.runner.PlanRunner` (the sequencing, resume
points and messages live there) around the non-blocking robot link: it sends segment k with
``link.submit(MoveToPoint(...))`` and sends segment k+1 only after the link's ``commandFinished``
for segment k. Pause / resume / stop are forwarded to the link. A failed segment, a refused
command, a lost link or a controller that is not answering (each said as such, through
:mod:`ui.messages`) ends the run in ``FAILED`` at that segment; :meth:`resume_run`
continues from it ("Resume from k").

Each segment's outcome comes back on its own :class:`~app.link.robot_link.Pending`
(``link.track(link.submit(MoveToPoint(...)))``: the link matches request ids, including "cancelled by
Stop" and refusals); everything else (acknowledgements, other panels' commands) never reaches
the run. A failed stop request of ours ends a run that is stopping. Connection and pose come
from ``link.state`` (:class:`~app.link.state.RobotState`), never a copy kept here.

**The point guard** (every run; the :class:`~ui.models.points_model.PointsModel` given as
``points=`` is mandatory): the controller's temp points are never assumed
(:mod:`ui.controllers.run_points`). Before each segment's move its
points are created again from the ledger, in the worker thread (one ``UploadPoints``
request; the move goes out when it has succeeded, or on Resume when the operator paused
meanwhile), and after the move the pose polled with its completion is compared with the
ledger's end point. A point that is not created, or an arrival off by more than 1 mm (the point
was overwritten by another tool), ends the run in ``FAILED`` at that segment with a sentence
from :mod:`ui.messages`; nothing further moves. ``segmentPrepared(int, object)`` (index, point
ids) is emitted right before each move is sent. There is no unguarded run.

**Another master** (issue 19 section 2, app/link/foreign.py): at the link's ``foreignMaster``
sign the run pauses itself as the operator's Pause would (442, the arm held, resumable) and says
why (``pausedByForeign``: "Paused: another master wrote to the controller (...)"; the planner
puts it in the run box, the window in the event log; audited when ``audit`` is given). Nothing
further is sent while it is paused so: no move, and not even the next segment's points (a create
overlapping the other master's writes would be *unknown*). :meth:`resume` checks again: refused
while the link's move hold (:data:`app.timing.FOREIGN_MOVE_HOLD`) lasts after the last sign
(``resumeRefused(str)``).
The segment that was under way at the sign ends *outcome unknown* (its "done" cannot be told from
the other master's): the run tells it by arrival instead -- the arm stands at the ledger's end
point (the point guard's check): done; elsewhere: the run fails at that segment (the arm stopped
if our pause holds it), "Resume from k" sends it again.

**A Pause is over only when the controller answered it** (issue 19, item 1; app/link/halt.py):
:meth:`pause` holds the next segment at once, but the run counts as *paused* only once the Pause's
own request ends well (``pause_state``: :class:`PauseState`, ``pauseStateChanged``). Until then
it is *pausing*; refused or unanswered, the worker sends it again at every poll and the link's
``haltChanged`` says so (*pausing -- the controller has not confirmed*); a Pause that failed
(refused for good, the link) leaves the run *not paused* (its next segment still held: Resume or
Pause again), and a Pause the worker replaced by a Stop ends the run as stopped.

How an ended run reads ("Failed at segment 2: ...") and what a link change means for it are
:mod:`ui.controllers.plan_run_reasons`.
"""

from __future__ import annotations

import dataclasses
import enum
import time
from collections import deque
from collections.abc import Sequence
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal, Slot

from app import timing
from app.errors import LinkError, TeachPadError
from app.link.link_port import LinkPort, Pending
from app.link.ops import MoveToPoint, Pause, Resume, Stop, UploadPoints
from app.link.progress import PointUploaded, Progress
from app.link.types import ConnectionState, HaltKind, LinkState, UnconfirmedHalt, WorkerError
from app.models import CommandResult, Pose
from app.plan.segments import Plan, Segment
from app.protocol.enums import MoveStatus
from ui.controllers.plan_run_reasons import (
    connection_error,
    foreign_resume_refused_text,
    outcome_text,
    stopped_by_operator,
)
from ui.controllers.point_sync_state import pose_from_details
from ui.controllers.run_points import RunPoints, SegmentPoints
from ui.messages import error_text, result_text
from ui.models.points_model import PointsModel

if TYPE_CHECKING:  # app.plan.runner is imported where a run starts, after the first paint
    from app.plan.runner import PlanRunner, RunOutcome, RunProgress, SegmentCommand
    from app.safety.audit import AuditLog


class PauseState(enum.Enum):
    """Where the run's Pause is (the run box says it)."""

    NONE = "none"  # not paused
    PAUSING = "pausing"  # sent, not answered yet
    UNCONFIRMED = "unconfirmed"  # refused or unanswered: sent again at every poll
    STOPPING = "stopping"  # not confirmed in time: a Stop is sent instead
    PAUSED = "paused"  # the controller confirmed it
    REFUSED = "refused"  # it failed: the arm was not paused (the next segment is held)


#: How many of the segments sent a run remembers (``sent_segments``): a run with endless loops
#: sends segments for as long as it runs.
SENT_KEPT = 1000


class PlanRunController(QObject):
    """GUI-thread driver of a plan run (see the module docstring).

    Signals: ``runningChanged(bool)``, ``pausedChanged(bool)``, ``progressChanged(object)``
    (:class:`RunProgress`, every segment start / end), ``segmentStarted(int, int)`` (0-based
    index, 1-based loop), ``runFinished(object)`` (:class:`RunOutcome`), ``connectedChanged(bool)``
    (``link.state.connected``, at each connection change of the state),
    ``pointsMissing(object)``
    (list of point ids: the controller answered "bad end point id", so it does not hold the
    segment's points — e.g. it restarted without the link noticing), ``segmentPrepared(int,
    object)`` (index, list of point ids re-created: the guarded move goes out next),
    ``pointMismatch(int)`` (end point id: the arm did not arrive at the ledger's copy),
    ``pausedByForeign(str, float)`` (the run paused itself at a sign of another master: what and
    the value, as ``link.foreignMaster``; :func:`~ui.controllers.plan_run_reasons.foreign_pause_text`
    says it), ``resumeRefused(str)`` (Resume did nothing: why, translated),
    ``pauseStateChanged(object)`` (:class:`PauseState`; ``pause_refusal`` says why a Pause failed).
    """

    runningChanged = Signal(bool)
    pausedChanged = Signal(bool)
    progressChanged = Signal(object)
    segmentStarted = Signal(int, int)
    runFinished = Signal(object)
    connectedChanged = Signal(bool)
    pointsMissing = Signal(object)
    segmentPrepared = Signal(int, object)
    pointMismatch = Signal(int)
    pausedByForeign = Signal(str, float)
    resumeRefused = Signal(str)
    pauseStateChanged = Signal(object)

    def __init__(
        self, link: LinkPort | None = None, parent: QObject | None = None, *, points: PointsModel
    ) -> None:
        super().__init__(parent)
        self._link: LinkPort | None = None
        self._runner: PlanRunner | None = None
        self._plan: Plan | None = None
        self._paused = False  # the run holds its next segment (the operator or the run paused)
        self._pause_state = PauseState.NONE
        self._pause: Pending | None = None  # the Pause under way, until the controller answers it
        self.pause_refusal = ""  # why the last Pause failed, translated
        self._guard = RunPoints(points)  # every run is guarded: there is no other path
        self._upload: Pending | None = None  # the re-creation of the running segment's points
        self._prepared: SegmentPoints | None = None  # the running segment's points, as sent
        self._held: SegmentCommand | None = None  # created while paused: the move waits for Resume
        self._outcome: RunOutcome | None = None
        self.end_reason = ""  # why the last run stopped or failed, translated (outcome_text)
        self._by_operator = False  # the last run ended by an operator's Stop (said in its own words)
        self._progress: RunProgress | None = None
        # segment indices sent, in order (for tests and the log): the last SENT_KEPT (endless loops)
        self._sent: deque[int] = deque(maxlen=SENT_KEPT)
        self._move: Pending | None = None  # the outcome of the segment under way
        self._stop: Pending | None = None  # the outcome of our last stop
        self._stops = 0  # link.state.stops_requested when the run began or resumed
        self.audit: AuditLog | None = None  # the trail a pause of the run's own is recorded in
        self._foreign_at: float | None = None  # monotonic time of the last sign of another master
        self._foreign_paused = False  # paused by the run itself at such a sign (not the operator)
        self._deferred = False  # the next segment waits for Resume (paused at a sign between segments)
        self._redo: SegmentCommand | None = None  # its points are created again on Resume
        if link is not None:
            self.set_link(link)

    def set_link(self, link: LinkPort) -> None:
        if self._link is not None:
            raise RuntimeError("the link is already set")
        self._link = link
        link.state.connectionChanged.connect(self._on_connection)
        link.foreignMaster.connect(self._on_foreign_master)
        link.state.haltChanged.connect(self._on_halt)

    @property
    def points(self) -> PointsModel:
        """The ledger every run's points are created from (the point guard's)."""
        return self._guard.model

    # --- state
    @property
    def link(self) -> LinkPort | None:
        return self._link

    @property
    def connected(self) -> bool:
        """The link's connection (``link.state``), never a copy."""
        return self._link is not None and self._link.state.connected

    @property
    def running(self) -> bool:
        runner = self._runner
        return runner is not None and not runner.state.is_over

    @property
    def paused(self) -> bool:
        """The run holds its next segment (paused by the operator or itself); whether the
        controller confirmed the Pause is :attr:`pause_state`."""
        return self._paused

    @property
    def pause_state(self) -> PauseState:
        return self._pause_state

    @property
    def can_pause(self) -> bool:
        """Pause does something for the run: it runs and is not paused, or its last Pause failed."""
        return self.running and (not self._paused or self._pause_state is PauseState.REFUSED)

    @property
    def plan(self) -> Plan | None:
        return self._plan

    @property
    def runner(self) -> PlanRunner | None:
        return self._runner

    @property
    def outcome(self) -> RunOutcome | None:
        """How the last run ended (None while running or before the first run)."""
        return self._outcome

    @property
    def progress(self) -> RunProgress | None:
        return self._progress

    @property
    def last_pose(self) -> Pose | None:
        return self._link.state.pose if self._link is not None else None

    @property
    def can_resume(self) -> bool:
        """A stopped or failed run can continue from :attr:`resume_from`."""
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        return (
            runner is not None
            and runner.state in (RunState.STOPPED, RunState.FAILED)
            and runner.resume_from is not None
        )

    @property
    def resume_from(self) -> int | None:
        return self._runner.resume_from if self._runner is not None else None

    @property
    def resume_loop(self) -> int | None:
        return self._runner.resume_loop if self._runner is not None else None

    @property
    def sent_segments(self) -> list[int]:
        return list(self._sent)

    # --- commands
    def start(
        self,
        plan: Plan | Sequence[Segment],
        *,
        start: int = 0,
        start_loop: int = 1,
        single: bool = False,
        loops: int | None = None,
    ) -> None:
        """Run ``plan`` from segment ``start`` (``single``: that segment only). Raises
        :class:`~app.errors.InvalidInput` for a bad start and :class:`LinkError` without a link."""
        from app.plan.runner import PlanRunner  # lazy: not before the first paint

        if self.running:
            raise RuntimeError("a run is already under way")
        link = self._require_link()
        self._runner = PlanRunner(
            plan, loops=loops, start=start, start_loop=start_loop, single=single, progress=self._on_progress
        )
        self._plan = plan if isinstance(plan, Plan) else None
        self._stops = link.state.stops_requested  # a Stop asked after this (any button): no further move
        self._outcome = None
        self.end_reason = ""
        self._by_operator = False
        self._sent.clear()
        self._set_paused(False)
        self.runningChanged.emit(True)
        self._send_next(link)

    def run(self, plan: Plan) -> None:
        self.start(plan)

    def run_from(self, plan: Plan, index: int, loop: int = 1) -> None:
        self.start(plan, start=index, start_loop=loop)

    def step(self, plan: Plan, index: int, loop: int = 1) -> None:
        self.start(plan, start=index, start_loop=loop, single=True)

    def resume_run(self) -> None:
        """Continue a stopped or failed run from the segment it ended at."""
        runner = self._runner
        if runner is None or not self.can_resume:
            raise RuntimeError("there is no stopped or failed run to resume")
        link = self._require_link()
        runner.resume()
        self._stops = link.state.stops_requested
        self._outcome = None
        self.end_reason = ""
        self._by_operator = False
        self._set_paused(False)
        self.runningChanged.emit(True)
        self._send_next(link)

    def pause(self) -> None:
        """Hold the next segment and pause the controller; *paused* once it answered (see the
        module docstring)."""
        link = self._link
        if not self.can_pause or link is None:
            return
        pause = link.track(link.submit(Pause()))
        self._pause = pause
        pause.finished.connect(lambda result: self._on_pause_result(pause, result))
        pause.failed.connect(lambda error: self._on_pause_failed(pause, error))
        self._set_paused(True)
        if not pause.done:
            self._set_pause_state(PauseState.PAUSING)

    def _on_pause_result(self, pause: Pending, result: CommandResult) -> None:
        """The Pause's outcome: answered (paused), or stopped instead / not carried out."""
        if pause is not self._pause or not self._paused:
            return
        self._pause = None
        if result.ok:
            self._set_pause_state(PauseState.PAUSED)
        elif result.reason is not None and result.reason.code == "pause_stopped":
            self._set_pause_state(PauseState.STOPPING)  # the move ends as stopped: so does the run
        else:
            self._pause_failed(result_text(result))

    def _on_pause_failed(self, pause: Pending, error: WorkerError) -> None:
        if pause is self._pause and self._paused:
            self._pause = None
            self._pause_failed(error_text(error))

    def _pause_failed(self, why: str) -> None:
        self.pause_refusal = why
        self._set_pause_state(PauseState.REFUSED)

    @Slot(object)
    def _on_halt(self, halt: UnconfirmedHalt | None) -> None:
        """The link's word on a Pause it has not confirmed (sent again at every poll)."""
        if self._pause is None or halt is None or halt.kind is not HaltKind.PAUSE:
            return
        self._set_pause_state(PauseState.STOPPING if halt.escalated else PauseState.UNCONFIRMED)

    def _set_pause_state(self, state: PauseState) -> None:
        if state is not self._pause_state:
            self._pause_state = state
            self.pauseStateChanged.emit(state)

    def resume(self) -> None:
        """Resume a paused move (not to be confused with :meth:`resume_run`); a move held
        because the operator paused while its points were being created goes out now, and what a
        pause at a sign of another master held back (the next segment, its points). Refused
        (``resumeRefused``) while another master was seen less than the move hold ago."""
        link = self._link
        if not (self.running and self._paused and link is not None) or self._foreign_hold_lasts():
            return
        link.submit(Resume())
        self._set_paused(False)
        held, self._held = self._held, None
        redo, self._redo = self._redo, None
        deferred, self._deferred = self._deferred, False
        if (held or redo or deferred) and self._stop_asked_since_start():
            self._end_stopped()
        elif held is not None:
            self._send_move(link, held)
        elif redo is not None:
            self._prepare(link, self._guard, redo)
        elif deferred:
            self._send_next(link)

    def _foreign_hold_lasts(self) -> bool:
        """Another master was seen less than ``timing.FOREIGN_MOVE_HOLD`` ago: said, and True."""
        seen, hold = self._foreign_at, timing.FOREIGN_MOVE_HOLD
        left = hold - (time.monotonic() - seen) if seen is not None else 0.0
        if left <= 0:
            return False
        text = foreign_resume_refused_text(hold, left)
        if self.audit is not None:
            self.audit.record_refused(
                "resume the plan run",
                f"another master wrote to the controller less than {hold:g} s ago",
                {"hold": hold},
            )
        self.resumeRefused.emit(text)
        return True

    @Slot(str, float)
    def _on_foreign_master(self, what: str, value: float) -> None:
        """A sign of another master (app/link/foreign.py): a run under way pauses itself and says
        why (once per pause); the sign's time starts the hold :meth:`resume` checks."""
        self._foreign_at = time.monotonic()
        runner = self._runner
        if not self.running or runner is None or runner.stop_requested or self._foreign_paused:
            return
        if not self._paused:
            self.pause()
        self._foreign_paused = True
        if self.audit is not None:
            current = runner.current
            args: dict[str, object] = {"what": what, "value": value}
            if current is not None:
                args["segment"] = current.index + 1
            self.audit.record(
                "action",
                "plan run paused",
                args=args,
                detail="Paused: another master wrote to the controller",
            )
        self.pausedByForeign.emit(what, value)

    def outcome_text(self, outcome: RunOutcome) -> str:
        """How a stopped or failed run ended, in the operator's language (one sentence)."""
        return outcome_text(outcome, self.end_reason, by_operator=self._by_operator)

    def _mark_operator_stop(self) -> None:
        self.end_reason = stopped_by_operator()
        self._by_operator = True

    def stop(self) -> None:
        """Stop the robot and the run. The run ends when the link reports the stopped move
        (at once when no move is out, or when the link is down)."""
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        link = self._link
        if link is not None:
            stop = link.track(link.submit(Stop()))
            self._stop = stop
            stop.failed.connect(lambda error: self._on_stop_failed(stop, error))
        if runner is None or runner.state.is_over:
            return
        runner.request_stop()
        self._mark_operator_stop()
        self._set_paused(False)
        if (
            runner.state is not RunState.RUNNING
            or not self.connected
            or (self._move is None and self._upload is None)
        ):
            # nothing out that could report the stop (e.g. a move held by a pause)
            self._clear_segment()
            runner.on_stopped()
            self._finish()

    # --- internals
    def link_refusal(self) -> LinkError | None:
        """Why a run cannot start on the link now (None: it can): not connected, or connected but
        the controller not answering (the last poll went unanswered) -- not "no connection"."""
        if self._link is not None and self._link.state.connection.state is LinkState.NOT_ANSWERING:
            return LinkError(
                "the controller is not answering: the plan was not started", code="run_not_answering_start"
            )
        if self._link is None or not self.connected:
            return LinkError("not connected to a controller", code="not_connected")
        return None

    def _require_link(self) -> LinkPort:
        refusal = self.link_refusal()
        if refusal is not None or self._link is None:
            raise refusal or LinkError("not connected to a controller", code="not_connected")
        return self._link

    def _set_paused(self, paused: bool) -> None:
        if not paused:
            self._foreign_paused = False
            self._pause = None  # a Pause still under way no longer speaks for the run
            self._set_pause_state(PauseState.NONE)
        if paused != self._paused:
            self._paused = paused
            self.pausedChanged.emit(paused)

    def _on_progress(self, progress: RunProgress) -> None:
        from app.plan.runner import RunEvent  # lazy: not before the first paint

        self._progress = progress
        if progress.event is RunEvent.SEGMENT_STARTED:
            self.segmentStarted.emit(progress.index, progress.loop)
        self.progressChanged.emit(progress)

    def _stop_asked_since_start(self) -> bool:
        """A Stop was asked of the link (any button: the window's STOP too) since the run began
        or resumed: nothing more is sent for this run."""
        return self._link is not None and self._link.state.stops_requested != self._stops

    def _end_stopped(self) -> None:
        """End the run as stopped by the operator before its next move went out."""
        runner = self._runner
        assert runner is not None
        if not runner.stop_requested:
            runner.request_stop()
            self._mark_operator_stop()
        self._clear_segment()
        runner.on_stopped(self.end_reason or "stopped by the operator")
        self._finish()

    def _send_next(self, link: LinkPort) -> None:
        runner = self._runner
        assert runner is not None
        if self._stop_asked_since_start() and not runner.stop_requested:
            runner.request_stop()  # the runner ends the run before this segment
            self._mark_operator_stop()
        command = runner.next_command()
        if command is None:
            self._finish()
            return
        self._prepare(link, self._guard, command)

    def _prepare(self, link: LinkPort, guard: RunPoints, command: SegmentCommand) -> None:
        """Create the segment's points from the ledger (worker thread); the move follows."""
        try:
            prepared = guard.begin(command.segment.end_id, command.segment.point_ids)
        except TeachPadError as exc:
            self._fail_segment(exc)
            return
        self._prepared = prepared
        upload = link.track(link.submit(UploadPoints.of(prepared.items())))
        self._upload = upload
        upload.progressed.connect(lambda progress: self._on_upload_progress(upload, progress))
        upload.finished.connect(lambda result: self._on_upload(upload, result))
        upload.failed.connect(lambda error: self._on_upload_error(upload, error))

    def _on_upload(self, upload: Pending, result: CommandResult) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner, guard, link = self._runner, self._guard, self._link
        if (
            upload is not self._upload
            or runner is None
            or runner.state is not RunState.RUNNING
            or link is None
        ):
            return
        self._upload = None
        prepared = guard.finish_upload(link.state.connection.endpoint)
        guard.clear()
        command = runner.current
        assert command is not None and prepared is not None
        if runner.stop_requested or self._stop_asked_since_start():
            self._end_stopped()
        elif not (result.ok and prepared.all_created) and self._foreign_paused:
            self._redo = command  # another master wrote meanwhile: created again on Resume
        elif not (result.ok and prepared.all_created):
            self._fail_segment(guard.not_created(prepared))
        elif self._paused:
            self._held = command  # Resume sends it
        else:
            self._send_move(link, command)

    def _on_upload_error(self, upload: Pending, error: WorkerError) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        if upload is not self._upload or runner is None or runner.state is not RunState.RUNNING:
            return
        self._upload = None
        self._guard.finish_upload(self._link.state.connection.endpoint if self._link else "")
        self._guard.clear()
        self.end_reason = error_text(error)
        self._clear_segment()
        runner.on_error(TeachPadError(self.end_reason))
        self._after_report()

    def _fail_segment(self, error: TeachPadError) -> None:
        """End the run at the running segment with ``error`` (its sentence is the end reason)."""
        runner = self._runner
        assert runner is not None
        self.end_reason = error_text(error)
        self._clear_segment()
        runner.on_error(error)
        self._after_report()

    def _clear_segment(self) -> None:
        self._upload = None
        self._prepared = None
        self._held = None
        self._redo = None
        self._deferred = False
        self._guard.clear()

    def _on_upload_progress(self, upload: Pending, progress: Progress) -> None:
        """One point of the segment's upload (its own request's: ``upload``'s progress)."""
        if upload is self._upload and isinstance(progress, PointUploaded):
            point = progress
            self._guard.on_point_uploaded(point.point_id, point.ok, point.reason, point.unconfirmed)

    def _send_move(self, link: LinkPort, command: SegmentCommand) -> None:
        seg = command.segment
        assert self._prepared is not None  # created by _prepare, or the move is not sent
        self.segmentPrepared.emit(command.index, list(self._prepared.points))
        self._sent.append(command.index)
        move = link.track(
            link.submit(
                MoveToPoint(
                    seg.end_id,
                    seg.via_id,
                    orientation_changes=seg.orientation_changes,
                    ignore_middle=seg.ignore_middle,
                    speed=seg.speed,
                    tool=seg.tool,
                )
            )
        )
        self._move = move
        move.finished.connect(lambda result: self._on_result(move, result))
        move.failed.connect(lambda error: self._on_error(move, error))

    def _finish(self) -> None:
        runner = self._runner
        assert runner is not None
        self._set_paused(False)
        self._outcome = runner.outcome()
        self.runningChanged.emit(False)
        self.runFinished.emit(self._outcome)

    def _after_report(self) -> None:
        runner = self._runner
        assert runner is not None
        if runner.state.is_over:
            self._finish()
        elif self._foreign_paused:
            self._deferred = True  # paused at a sign of another master: Resume sends it
        elif self._link is not None:
            self._send_next(self._link)

    def _on_result(self, move: Pending, result: CommandResult) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        if move is not self._move or runner is None or runner.state is not RunState.RUNNING:
            return
        self._move = None
        prepared, self._prepared = self._prepared, None
        if _overlapped(result) and prepared is not None:
            result = self._told_by_arrival(result, prepared)
        if result.ok and prepared is not None:
            # the pose that came with the result, else the link's latest (the poll that
            # completed the move publishes its pose before the result)
            error = self._guard.check_arrival(prepared, pose_from_details(result.details, self.last_pose))
            if error is not None:
                self.pointMismatch.emit(prepared.end_id)
                self._fail_segment(error)
                return
        current = runner.current
        missing = (
            not result.ok
            and result.status is not None
            and result.status.code == MoveStatus.BAD_END_POINT
            and current is not None
        )
        if not result.ok and (result.stopped_by_operator or self._stop_asked_since_start()):
            self._stopped_by_operator(runner)  # a Stop (any button) ended it: not a failure
        elif not result.ok:
            # the runner keeps the reason as text: give it the operator's language
            self.end_reason = result_text(result)
            result = dataclasses.replace(result, message=self.end_reason)
        runner.on_result(result)
        if missing and current is not None:
            self.pointsMissing.emit(list(current.segment.point_ids))
        self._after_report()

    def _told_by_arrival(self, result: CommandResult, prepared: SegmentPoints) -> CommandResult:
        """A segment whose end came while another master was seen: done when the arm stands at
        the ledger's end point (what the segment was for; the other master's command would have
        left it elsewhere), else it stays *unknown* and the arm held by our pause is stopped (the
        run fails at it; "Resume from k" sends it again)."""
        pose = pose_from_details(result.details, self.last_pose)
        if self._guard.check_arrival(prepared, pose) is None:
            message = "arrived at the end point (its result could not be told from another master's)"
            return dataclasses.replace(result, ok=True, message=message, reason=None)
        if self._paused and self._link is not None:
            self._link.submit(Stop())
        return result

    def _on_error(self, move: Pending, error: WorkerError) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        if move is not self._move or runner is None or runner.state is not RunState.RUNNING:
            return
        self._move = None
        self._prepared = None
        if error.reason is not None and error.reason.code == "stopped_by_operator":
            self._stopped_by_operator(runner)
            runner.on_stopped(self.end_reason)
        else:
            self.end_reason = error_text(error)
            runner.on_error(TeachPadError(self.end_reason))
        self._after_report()

    def _stopped_by_operator(self, runner: PlanRunner) -> None:
        """The segment under way ended by a Stop (ours, the window's STOP, the keyboard's): the
        run ends *stopped by the operator* at it, never as a failure."""
        if not runner.stop_requested:
            runner.request_stop()
        if self._pause_state is PauseState.STOPPING:  # the Pause, not confirmed in time, became a Stop
            self.end_reason = self.tr(
                "the controller did not confirm the Pause in time: Stop was sent instead"
            )
            self._by_operator = False
            return
        self._mark_operator_stop()

    def _on_stop_failed(self, stop: Pending, error: WorkerError) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        runner = self._runner
        if (
            stop is self._stop
            and runner is not None
            and runner.state is RunState.RUNNING
            and runner.stop_requested
        ):
            self._clear_segment()
            self.end_reason = error_text(error)
            self._by_operator = False
            runner.on_stopped(self.end_reason)
            self._finish()

    @Slot(ConnectionState)
    def _on_connection(self, state: ConnectionState) -> None:
        from app.plan.runner import RunState  # lazy: not before the first paint

        self.connectedChanged.emit(state.connected)
        runner = self._runner
        if not state.connected and runner is not None and runner.state is RunState.RUNNING:
            self._move = None
            if self._upload is not None:
                self._guard.finish_upload(state.endpoint)  # what the worker reported so far
            self._clear_segment()
            error = connection_error(state)
            self.end_reason = error_text(error)
            runner.on_error(error)
            self._finish()


def _overlapped(result: CommandResult) -> bool:
    """The command's end came while another master was seen (app/link/foreign.py): unknown."""
    reason = result.reason
    return (
        not result.ok
        and reason is not None
        and reason.code == "outcome_unknown"
        and bool(reason.args.get("foreign"))
    )

"""Run a plan on the controller, one segment (function 3 move) at a time.

:class:`PlanRunner` is a small state machine, usable two ways:

* **Step by step** (the GUI worker, never blocking): ``cmd = runner.next_command()`` gives the
  next :class:`SegmentCommand` (None when the run is over); the worker starts the move
  however it likes (e.g. ``client.begin_command`` + ``CommandTracker``) and reports back with
  exactly one of ``runner.on_result(result)``, ``runner.on_error(exc)`` or
  ``runner.on_stopped()``. Then it asks for the next command.
* **Blocking** (the CLI): ``runner.run(client, guard)`` does that loop itself with
  ``client.move_to_point(..., wait=True)``; the optional :class:`SegmentGuard`
  (``app.points.guard.PointGuard``) re-creates each segment's points from the host's copy
  right before its move and verifies the arrival pose after it.

Every segment waits for its own completion before the next is sent. A failed segment (error,
refusal, lost link) ends the run in ``FAILED`` with ``resume_from`` = that segment and
``resume_loop`` = its loop; a stop ends it in ``STOPPED`` the same way (the interrupted
segment is run again on resume; a stop requested between segments resumes at the next one).
``resume()`` continues from there, or a new runner can be made with ``start=resume_from,
start_loop=resume_loop`` (run-from-here). ``single=True`` runs one segment (step).

Stopping: :meth:`PlanRunner.request_stop` is thread-safe and means "send no further segment".
Halting the robot mid-segment is the controller's stop command, sent by whoever owns the
client (the worker: ``client.stop()``, then ``runner.on_stopped()``). ``run()`` sends it
itself on Ctrl-C, on a command timeout and on an unexpected exception. Pause and resume of a
move are plain controller commands too; the runner needs no notice (the move just lasts
longer).

The client is duck-typed (:class:`MoveClient`): ``app.link.client.RobotClient`` fits.
"""

from __future__ import annotations

import enum
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from app.errors import CommandStopped, CommandTimeout, InvalidInput, TeachPadError
from app.models import CommandResult
from app.plan.segments import Plan, Segment
from app.protocol.enums import QT_TRANSLATE_NOOP


class MoveClient(Protocol):
    """The part of ``RobotClient`` the runner uses."""

    def move_to_point(
        self,
        end_id: int,
        *,
        via_id: int | None = ...,
        orientation_changes: bool = ...,
        ignore_middle: bool = ...,
        speed: float = ...,
        tool: int = ...,
        wait: bool = ...,
        timeout: float | None = ...,
    ) -> CommandResult: ...

    def stop(self) -> None: ...


class SegmentGuard(Protocol):
    """Checks around each move of a blocking run (``app.points.guard.PointGuard`` fits):
    ``before_segment`` may re-create the segment's points, ``after_segment`` may verify the
    arrival; either raising a ``TeachPadError`` ends the run in FAILED at that segment."""

    def before_segment(self, client: Any, point_ids: Sequence[int]) -> None: ...

    def after_segment(self, client: Any, end_id: int) -> None: ...


class RunState(enum.Enum):
    READY = "ready"  # the next command can be taken
    RUNNING = "running"  # a segment was handed out; waiting for its result
    FINISHED = "finished"
    STOPPED = "stopped"
    FAILED = "failed"

    @property
    def text(self) -> str:
        return RUN_STATE_TEXT[self]

    @property
    def is_over(self) -> bool:
        return self in (RunState.FINISHED, RunState.STOPPED, RunState.FAILED)


RUN_STATE_TEXT: dict[RunState, str] = {
    RunState.READY: QT_TRANSLATE_NOOP("Runner", "ready"),
    RunState.RUNNING: QT_TRANSLATE_NOOP("Runner", "running"),
    RunState.FINISHED: QT_TRANSLATE_NOOP("Runner", "finished"),
    RunState.STOPPED: QT_TRANSLATE_NOOP("Runner", "stopped"),
    RunState.FAILED: QT_TRANSLATE_NOOP("Runner", "failed"),
}


class RunEvent(enum.Enum):
    SEGMENT_STARTED = "segment-started"
    SEGMENT_DONE = "segment-done"
    FINISHED = "finished"
    STOPPED = "stopped"
    FAILED = "failed"


@dataclass(frozen=True)
class SegmentCommand:
    """The next move to send: segment ``index`` (0-based) of ``count``, loop ``loop`` (1-based)
    of ``loops`` (0 = endless)."""

    index: int
    count: int
    loop: int
    loops: int
    segment: Segment
    timeout: float | None = None

    def move_kwargs(self) -> dict[str, object]:
        """Keyword arguments of ``RobotClient.move_to_point`` (besides ``end_id``)."""
        seg = self.segment
        return {
            "via_id": seg.via_id,
            "orientation_changes": seg.orientation_changes,
            "ignore_middle": seg.ignore_middle,
            "speed": seg.speed,
            "tool": seg.tool,
            "timeout": self.timeout,
        }

    def send(self, client: MoveClient, *, wait: bool = True) -> CommandResult:
        seg = self.segment
        return client.move_to_point(
            seg.end_id,
            via_id=seg.via_id,
            orientation_changes=seg.orientation_changes,
            ignore_middle=seg.ignore_middle,
            speed=seg.speed,
            tool=seg.tool,
            wait=wait,
            timeout=self.timeout,
        )


def _loop_text(loop: int, loops: int) -> str:
    return f"loop {loop}" if loops == 0 else f"loop {loop}/{loops}"


@dataclass(frozen=True)
class RunProgress:
    """One progress report. ``index`` is 0-based; texts count from 1."""

    event: RunEvent
    index: int
    count: int
    loop: int
    loops: int
    message: str = ""

    @property
    def text(self) -> str:
        return f"{_loop_text(self.loop, self.loops)}, segment {self.index + 1}/{self.count}"


@dataclass(frozen=True)
class RunOutcome:
    state: RunState
    message: str
    resume_from: int | None  # 0-based segment to resume at (STOPPED / FAILED), else None
    resume_loop: int | None
    segments_done: int
    error: BaseException | None = None
    next_position: tuple[int, int] | None = None  # (index, loop) a further step would run
    interrupted: bool = False  # ended by Ctrl-C in run()
    loops: int = 1  # the run's number of loops (0 = endless): "loop 2 of 20"

    @property
    def ok(self) -> bool:
        return self.state is RunState.FINISHED


ProgressCallback = Callable[[RunProgress], None]


class PlanRunner:
    """Sequences one run of a plan; see the module docstring."""

    def __init__(
        self,
        plan: Plan | Sequence[Segment],
        *,
        loops: int | None = None,
        start: int = 0,
        start_loop: int = 1,
        single: bool = False,
        timeouts: Sequence[float | None] | None = None,
        progress: ProgressCallback | None = None,
    ) -> None:
        self._segments: tuple[Segment, ...] = tuple(plan.segments if isinstance(plan, Plan) else plan)
        self._loops = (plan.loops if isinstance(plan, Plan) else 1) if loops is None else loops
        n = len(self._segments)
        if n == 0:
            raise InvalidInput("the plan has no segments")
        if self._loops < 0:
            raise InvalidInput(f"loops must be >= 0 (0 = endless), got {self._loops}")
        if not 0 <= start < n:
            raise InvalidInput(f"cannot start at segment {start + 1}: the plan has {n} segments")
        if start_loop < 1 or (self._loops and start_loop > self._loops):
            raise InvalidInput(f"cannot start at loop {start_loop} of {self._loops}")
        if timeouts is not None and len(timeouts) != n:
            raise InvalidInput(f"{len(timeouts)} timeouts for {n} segments")
        self._timeouts = tuple(timeouts) if timeouts is not None else (None,) * n
        self._single = single
        self._progress = progress
        self._stop = threading.Event()
        self._state = RunState.READY
        self._position: tuple[int, int] | None = (start, start_loop)
        self._current: SegmentCommand | None = None
        self._resume: tuple[int, int] | None = None
        self._message = ""
        self._error: BaseException | None = None
        self._done = 0
        self._interrupted = False

    # --- read-only view
    @property
    def state(self) -> RunState:
        return self._state

    @property
    def count(self) -> int:
        return len(self._segments)

    @property
    def loops(self) -> int:
        return self._loops

    @property
    def current(self) -> SegmentCommand | None:
        """The segment handed out and not yet reported on."""
        return self._current

    @property
    def position(self) -> tuple[int, int] | None:
        """``(index, loop)`` of the next segment to hand out; None when nothing is left."""
        return self._position

    @property
    def resume_from(self) -> int | None:
        return None if self._resume is None else self._resume[0]

    @property
    def resume_loop(self) -> int | None:
        return None if self._resume is None else self._resume[1]

    @property
    def message(self) -> str:
        return self._message

    @property
    def error(self) -> BaseException | None:
        return self._error

    @property
    def segments_done(self) -> int:
        return self._done

    @property
    def stop_requested(self) -> bool:
        return self._stop.is_set()

    def outcome(self) -> RunOutcome:
        return RunOutcome(
            self._state,
            self._message,
            self.resume_from,
            self.resume_loop,
            self._done,
            self._error,
            self._position,
            self._interrupted,
            self._loops,
        )

    # --- driving
    def request_stop(self) -> None:
        """Send no further segment (thread-safe). The running one finishes unless the owner of
        the client stops the controller too."""
        self._stop.set()

    def next_command(self) -> SegmentCommand | None:
        """The next segment to send (state becomes RUNNING), or None when the run is over."""
        if self._state is RunState.RUNNING:
            assert self._current is not None
            raise RuntimeError(f"segment {self._current.index + 1} is still running: report its result first")
        if self._state.is_over:
            return None
        if self._position is None:
            self._end(RunState.FINISHED, "finished", None)
            return None
        index, loop = self._position
        if self._stop.is_set():
            self._end(RunState.STOPPED, f"stopped on request before segment {index + 1}", self._position)
            return None
        segment = self._segments[index]
        cmd = SegmentCommand(index, self.count, loop, self._loops, segment, self._timeouts[index])
        self._current = cmd
        self._state = RunState.RUNNING
        self._emit(RunEvent.SEGMENT_STARTED, index, loop, self._segments[index].text)
        return cmd

    def on_result(self, result: CommandResult) -> None:
        """Report how the segment handed out last ended."""
        cmd = self._take_current()
        if not result.ok:
            reason = result.message or (result.status.text if result.status is not None else "failed")
            if self._stop.is_set():
                self._end(RunState.STOPPED, self._where(cmd, f"stopped ({reason})"), (cmd.index, cmd.loop))
            else:
                self._end(RunState.FAILED, self._where(cmd, reason), (cmd.index, cmd.loop))
            return
        self._done += 1
        self._position = self._after(cmd.index, cmd.loop)
        self._state = RunState.READY
        self._emit(RunEvent.SEGMENT_DONE, cmd.index, cmd.loop, "")
        if self._single or self._position is None:
            self._end(RunState.FINISHED, "finished", None, at=cmd)
        elif self._stop.is_set():
            nxt = self._position
            self._end(RunState.STOPPED, f"stopped on request before segment {nxt[0] + 1}", nxt)

    def on_error(self, error: BaseException) -> None:
        """Report that the segment handed out last raised ``error`` (a lost link, a refusal...)."""
        cmd = self._take_current()
        self._error = error
        reason = str(error) or type(error).__name__
        state = RunState.STOPPED if isinstance(error, CommandStopped) else RunState.FAILED
        self._end(state, self._where(cmd, reason), (cmd.index, cmd.loop))

    def on_stopped(self, reason: str = "stopped by the operator") -> None:
        """Report a stop the owner of the client sent; the run ends in STOPPED."""
        self._stop.set()
        if self._state is RunState.RUNNING:
            cmd = self._take_current()
            self._end(RunState.STOPPED, self._where(cmd, reason), (cmd.index, cmd.loop))
        elif not self._state.is_over:
            self._end(RunState.STOPPED, reason, self._position)

    def resume(self) -> None:
        """Continue a STOPPED or FAILED run from where it ended."""
        if self._state not in (RunState.STOPPED, RunState.FAILED) or self._resume is None:
            raise RuntimeError(f"cannot resume a run that is {self._state.value}")
        self._position = self._resume
        self._resume = None
        self._error = None
        self._message = ""
        self._interrupted = False
        self._stop.clear()
        self._state = RunState.READY

    def run(self, client: MoveClient, guard: SegmentGuard | None = None) -> RunOutcome:
        """Blocking: send every segment with ``move_to_point(wait=True)`` until the run is over.

        With a ``guard``, each segment's points are passed to ``guard.before_segment`` right
        before its move, and its end point to ``guard.after_segment`` after a successful one.
        """
        while (cmd := self.next_command()) is not None:
            try:
                if guard is not None:
                    guard.before_segment(client, cmd.segment.point_ids)
                result = cmd.send(client, wait=True)
                if guard is not None and result.ok:
                    guard.after_segment(client, cmd.segment.end_id)
            except CommandTimeout as exc:
                # The robot may still be moving: halt it before reporting.
                note = self._halt(client)
                self.on_error(CommandTimeout(f"{exc}{note}") if note else exc)
            except TeachPadError as exc:
                self.on_error(exc)
            except KeyboardInterrupt:
                note = self._halt(client)
                self._interrupted = True
                self.on_stopped(f"interrupted (Ctrl-C){note}")
            except BaseException as exc:
                self._halt(client)
                self.on_error(exc)
                raise
            else:
                self.on_result(result)
        return self.outcome()

    # --- internals
    def _after(self, index: int, loop: int) -> tuple[int, int] | None:
        if index + 1 < self.count:
            return index + 1, loop
        if self._loops and loop >= self._loops:
            return None
        return 0, loop + 1

    def _take_current(self) -> SegmentCommand:
        if self._state is not RunState.RUNNING or self._current is None:
            raise RuntimeError("no segment is running")
        cmd, self._current = self._current, None
        return cmd

    def _where(self, cmd: SegmentCommand, reason: str) -> str:
        return f"segment {cmd.index + 1}/{cmd.count} ({_loop_text(cmd.loop, cmd.loops)}): {reason}"

    def _end(
        self, state: RunState, message: str, resume: tuple[int, int] | None, at: SegmentCommand | None = None
    ) -> None:
        self._state = state
        self._message = message
        self._resume = resume if state is not RunState.FINISHED else None
        event = {
            RunState.FINISHED: RunEvent.FINISHED,
            RunState.STOPPED: RunEvent.STOPPED,
            RunState.FAILED: RunEvent.FAILED,
        }[state]
        index, loop = (at.index, at.loop) if at else (resume or self._position or (self.count - 1, 1))
        self._emit(event, index, loop, message)

    def _emit(self, event: RunEvent, index: int, loop: int, message: str) -> None:
        if self._progress is not None:
            self._progress(RunProgress(event, index, self.count, loop, self._loops, message))

    @staticmethod
    def _halt(client: MoveClient) -> str:
        """Best-effort controller stop; returns a note when it failed (the link may be gone)."""
        try:
            client.stop()
        except TeachPadError as exc:
            return f"; the stop command failed too: {exc}"
        return ""

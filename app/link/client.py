"""RobotClient: one method per controller operation, typed results, typed errors.

The commands, over :class:`~app.link.command_client.CommandClient` (440 and the completion
rule) and :class:`~app.link.register_client.RegisterClient` (the link, the write guard, raw
register access and the pose/status reads), which RobotClient inherits: ``connect``,
``read_pose``, ``read_status``, ``write_gv``, ``stats``, ``begin_command``, ``wait`` ... Not
thread-safe: one thread owns it (the GUI worker, or the CLI).

Decisions on the open questions of PROTOCOL.md section 7 that live here:

* **Work mode**: before a step, move, create-point or teach command the client reads the status
  (it needs it as the tracker's "before" anyway) and writes 444 <- auto only when the mode reads
  manual (or an unknown value), as the vendor's recipe of the four functions says; Modbus-teach
  (2) counts as auto. Go to zero and run program are not in those recipes: in manual mode they
  are refused (:class:`~app.errors.ManualModeRefused`, audited, nothing written) unless the
  caller passes ``switch_to_auto=True`` -- the operator confirmed the switch (the GUI names it in
  its confirmation, the CLI needs ``--auto``); 444 <- auto then goes out as its own write (its
  own audit record) before the command.
* **Reduced-speed caps** (``caps``, :class:`~app.safety.caps.MotionCaps`, None: not reduced):
  every speed this client writes is capped here -- the jog ratio, the program speed ratio, the
  GV225 of steps and moves -- whoever asked for it; go to zero, which has no speed to cap, is
  refused (:class:`~app.errors.ReducedSpeedRefused`).
* **Cached parameters**: GV245 (tool), GV241 (user frame) and the external-axis offsets
  GV236-240 are written only when they differ from what this client last wrote; the cache is
  dropped whenever the connection is (re)made or fails, and by :meth:`invalidate_cache`.
* **Completion rule**: see :mod:`app.link.command_client` (CommandClient, the layer between
  the registers and these operations: it writes 440 and follows the command to its end).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from collections.abc import Callable, Iterable, Sequence

from app import timing
from app.connection import ConnectionSettings
from app.errors import (
    ControllerBusy,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ManualModeRefused,
    ModbusExceptionError,
    OutcomeUnknown,
    ReducedSpeedRefused,
    ResponseTimeout,
    TeachPadError,
)
from app.link.busy import BusyBackoff, is_busy, retry_busy
from app.link.checks import check_enum, check_float, check_floats, check_int, check_tool
from app.link.command_client import CommandClient
from app.link.line_retry import LINE_ERRORS, LineRetry, retry_line
from app.link.tracker import CommandTracker, command_text
from app.link.types import StepFrame
from app.link.watch import MotionWatch
from app.models import CommandResult, ControllerStatus, Pose
from app.protocol import registers
from app.protocol.enums import (
    JOINT_AXIS_NAMES,
    CommandKind,
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    RunCommand,
    TeachFrame,
    WorkMode,
    program_state_text,
)
from app.safety.caps import MotionCaps

__all__ = [
    "RobotClient",
]

_GENERAL_POSE_LAST_START = registers.GV_GENERAL_LAST - 5  # six GVs must fit in GV0..GV99


ProgressCallback = Callable[[int, int], bool]


class _PoseStaging:
    """The staging of an upload's poses (:meth:`RobotClient.upload_points`): they alternate
    between two blocks of GVs, and while the controller works on one point the next point's pose
    goes into the other block (``spare`` None: one block, each pose written before its point)."""

    def __init__(
        self,
        items: Sequence[tuple[int, Sequence[float]]],
        gv_start: int,
        spare: int | None,
        write: Callable[[int, Sequence[float]], None],
        halted: Callable[[], bool] | None,
    ) -> None:
        self._items = items
        self._gv_start = gv_start
        self.spare = spare
        self._write = write
        self._halted = halted
        self.staged = -1  # the index of the item whose pose is already in its block

    def block_of(self, index: int) -> int:
        return self.spare if self.spare is not None and index % 2 else self._gv_start

    def meanwhile(self, index: int) -> Callable[[], None] | None:
        """What to do while point ``index`` is in flight: stage the next pose (None: nothing)."""
        return (
            functools.partial(self.stage, index + 1)
            if self.spare is not None and index + 1 < len(self._items)
            else None
        )

    def stage(self, nxt: int) -> None:
        """Write item ``nxt``'s pose into its block, unless it is there already or a stop or
        cancel is pending."""
        if self.staged == nxt or (self._halted is not None and self._halted()):
            return  # staged already (a busy retry); a stop or cancel is pending
        try:
            self._write(self.block_of(nxt), self._items[nxt][1])
        except LINE_ERRORS:
            return  # not known to be there: written again before its point is created
        except ModbusExceptionError as exc:
            # busy: staged after the result instead. Refused: the point in flight goes on,
            # and the next poses go into the first block, each after the previous result
            # (the unstaged way)
            if not is_busy(exc):
                self.spare = None
        else:
            self.staged = nxt


def _failed_point(point_id: int, exc: TeachPadError) -> CommandResult:
    """The result of a point whose writes or reads failed (it ends the batch)."""
    return CommandResult(
        RunCommand.CREATE_POINT,
        CommandKind.CREATE_POINT,
        None,
        False,
        str(exc),
        {"point_id": float(point_id)},
        reason=exc.as_reason(),
    )


def _point_result(point_id: int, result: CommandResult) -> CommandResult:
    """A point's result, naming the point."""
    details = dict(result.details, point_id=float(point_id))
    return dataclasses.replace(result, message=f"point {point_id}: {result.message}", details=details)


class RobotClient(CommandClient):
    """One method per controller operation. Blocking; owned by one thread."""

    def __init__(self, settings: ConnectionSettings) -> None:
        self._tool_cache: int | None = None  # before the link exists: it drops these caches
        self._user_frame_cache: int | None = None
        self._ext_cache: tuple[float, ...] | None = None
        super().__init__(settings)
        self._teach_frame: TeachFrame | None = None
        self.last_watch: MotionWatch | None = None  # the last go to zero / run program (stop ends it)
        # X Y Z of the points this client created from given poses (a move whose GV291 never
        # changed may be confirmed by arriving there, see CommandTracker's ``target``)
        self._sent_points: dict[int, tuple[float, float, float]] = {}
        #: reduced-speed mode's caps, applied to every speed written (None: not reduced)
        self.caps: MotionCaps | None = None

    def invalidate_cache(self) -> None:
        """Forget which tool / user frame / external offsets were written last."""
        self._tool_cache = None
        self._user_frame_cache = None
        self._ext_cache = None

    # -- plain commands (no GV291) -------------------------------------------------------
    def set_work_mode(self, mode: WorkMode) -> None:
        mode = check_enum(mode, WorkMode, "work mode")
        self._write_control(registers.REG_WORK_MODE, int(mode))

    def stop(self) -> None:
        self._write_control(registers.REG_STOP, 1)
        for command in (self.last_tracker, self.last_watch):
            if command is not None and not command.finished:
                command.stopped(time.monotonic())

    def pause(self) -> None:
        self._write_control(registers.REG_PAUSE, 1)

    def resume(self) -> None:
        self._write_control(registers.REG_RESUME, 1)

    def go_zero(
        self, axis: int | None, *, before: Pose | None = None, switch_to_auto: bool = False
    ) -> MotionWatch:
        """Send one axis (0..10 = J1..J11) or all axes (None) to zero; returns the watch that tells
        how it ends (by motion: go to zero has no GV291 result; :meth:`follow` it, or feed it).
        ``before``: the pose just read (the GUI's last poll), else it is read here. In manual mode:
        refused, unless ``switch_to_auto`` (444 <- auto first); in reduced-speed mode: refused."""
        last_axis = registers.NUM_AXES_TOTAL - 1
        value = registers.GO_ZERO_ALL if axis is None else check_int(axis, 0, last_axis, "axis")
        which = "all axes" if axis is None else JOINT_AXIS_NAMES[axis]
        self._require_writable("go to zero")
        self.watch_shared_baseline()
        if self.caps is not None:
            self._refuse("go to zero", ReducedSpeedRefused("go to zero"))
        status = self.read_status()
        self._refuse_while_busy("go to zero", f"go to zero ({which})", status)
        self._auto_for("go to zero", status, switch_to_auto)
        before = before or self.read_pose()
        self.check_no_foreign_master("go to zero")
        sent = time.monotonic()  # a sign of another master from here on overlaps it
        axes = tuple(range(registers.NUM_AXES_TOTAL)) if axis is None else (value,)
        watch = MotionWatch(
            None, f"go to zero ({which})", before, sent, operation="go to zero", zero_axes=axes
        )
        return self._watching(watch, registers.REG_GO_ZERO, value)

    def run_program(
        self,
        program_id: int,
        mode: ProgramMotionMode = ProgramMotionMode.SINGLE_RUN,
        cycles: int = 1,
        speed_ratio: int = 100,
        *,
        before: Pose | None = None,
        switch_to_auto: bool = False,
    ) -> MotionWatch:
        """446..449 in one 0x10, then 440 <- 0x01; returns the watch that tells how it ends
        (``before``: as for :meth:`go_zero`). In manual mode: refused, unless ``switch_to_auto``
        (444 <- auto first); the speed ratio is capped in reduced-speed mode."""
        program_id = check_int(program_id, 0, 0xFFFF, "program id")
        motion = check_enum(mode, ProgramMotionMode, "program motion mode")
        cycles = check_int(cycles, 0, 0xFFFF, "cycle count")
        speed_ratio = check_int(speed_ratio, 1, 100, "program speed ratio")
        if self.caps is not None:
            speed_ratio = self.caps.program_ratio(speed_ratio)
        self._require_writable("run program")
        self.watch_shared_baseline()
        status = self.read_status()
        self._refuse_while_busy("run program", f"run program {program_id}", status)
        self._auto_for("run program", status, switch_to_auto)
        before = before or self.read_pose()
        self._write(registers.REG_PROGRAM_ID, [program_id, int(motion), cycles, speed_ratio])
        self.check_no_foreign_master("run program")
        sent = time.monotonic()  # a sign of another master from here on overlaps it
        watch = MotionWatch(
            RunCommand.RUN_PROGRAM,
            f"run program {program_id}",
            before,
            sent,
            operation="run program",
            program=program_id,
        )
        return self._watching(watch, registers.REG_RUN_COMMAND, int(RunCommand.RUN_PROGRAM))

    def _refuse_while_busy(self, operation: str, what: str, status: ControllerStatus) -> None:
        """Run program and go to zero are told by motion: not while a program or motion runs
        (nothing would tell this command's start from what is under way). Audited, not sent."""
        if status.program_state not in (ProgramState.RUNNING, ProgramState.PAUSED):
            return
        state = program_state_text(int(status.program_state))
        text = (
            f"{what} not sent: the controller is busy (program state {state}); wait for it to end, or stop it"
        )
        if self.audit is not None:
            self.audit.record_refused(what, text, {"program_state": int(status.program_state)})
        raise ControllerBusy(text, params={"operation": operation})

    def _watching(self, watch: MotionWatch, register: int, value: int) -> MotionWatch:
        """Send the trigger ``register`` <- ``value`` of the command ``watch`` tells the end of
        (a sign of another master before its end makes it unknown: ``watch.foreign``)."""
        watch.foreign = self.foreign
        self.send_trigger(register, value, watch)
        self.last_watch = watch
        return watch

    # -- helpers of the four functions ---------------------------------------------------
    def _ensure_auto(self, status: ControllerStatus) -> None:
        """444 <- auto unless the (fresh) status already says auto or Modbus teach."""
        if status.mode not in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH):
            self.set_work_mode(WorkMode.AUTO)

    def _auto_for(self, operation: str, status: ControllerStatus, switch: bool) -> None:
        """Auto (or Modbus teach) already: nothing; manual or unknown: 444 <- auto when the caller
        may ``switch``, else refused (audited) before anything is written."""
        if status.mode in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH):
            return
        if not switch:
            self._refuse(operation, ManualModeRefused(operation, int(status.mode)))
        self.set_work_mode(WorkMode.AUTO)

    def _refuse(self, operation: str, error: TeachPadError) -> None:
        """Record ``error`` as a refused action in the audit trail and raise it (nothing sent)."""
        if self.audit is not None:
            self.audit.record_refused(operation, str(error), dict(error.params))
        raise error

    def ensure_auto(self) -> None:
        self._require_writable("set work mode")
        self._ensure_auto(self.read_status())

    def _prepare(self, command: RunCommand, *, auto: bool = True) -> tuple[ControllerStatus, Pose | None]:
        self._require_writable(command_text(command))
        self.watch_shared_baseline()  # another master's writes from here on are told from ours
        before = self.read_status()
        before_pose = self.read_pose() if CommandKind.of(command) is CommandKind.MOVE else None
        if auto:
            self._ensure_auto(before)
        return before, before_pose

    def _write_tool(self, tool: int) -> None:
        if self._tool_cache != tool:  # a value register: written again on a noisy line (read back first)
            self._write_floats(registers.GV_TOOL_FRAME, [float(tool)], repeatable=True)
            self._tool_cache = tool

    def _write_user_frame(self, user: int) -> None:
        if self._user_frame_cache != user:
            self._write_floats(registers.GV_USER_FRAME, [float(user)])
            self._user_frame_cache = user

    def _check_point_id(self, point_id: int, name: str = "point id") -> int:
        return check_int(point_id, self.settings.point_id_min, self.settings.point_id_max, name)

    # -- function 1: incremental move ----------------------------------------------------
    def step(
        self,
        frame: StepFrame,
        offsets: Sequence[float],
        ext_offsets: Sequence[float] = (0.0,) * registers.NUM_EXTERNAL_AXES,
        speed: float = 10.0,
        *,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        """Incremental move: GV200-205 (one 0x10), GV236-240 when needed, GV225, 440 <- 0x40/0x41.

        ``offsets`` are J1..J6 (degrees, joint frame) or X Y Z A B C (mm, degrees, base
        frame); ``ext_offsets`` are J7..J11. ``speed`` is rpm (joint) or mm/s (base).
        """
        if not isinstance(frame, StepFrame):
            raise InvalidInput(f"step frame must be joint or base, got {frame!r}")
        offs = check_floats(offsets, registers.NUM_ROBOT_AXES, "offsets")
        ext = tuple(check_floats(ext_offsets, registers.NUM_EXTERNAL_AXES, "external offsets"))
        speed = check_float(speed, "speed", 0.0, lo_open=True)
        if timeout is not None:
            timeout = check_float(timeout, "timeout", 0.0, lo_open=True)
        if not any(offs) and not any(ext):
            raise InvalidInput("step: every offset is zero, nothing to move")
        if self.caps is not None:
            speed = (
                self.caps.joint_speed(speed, offs)
                if frame is StepFrame.JOINT
                else self.caps.linear_speed(speed)
            )
        if timeout is None:
            timeout = self._step_timeout(frame, offs, ext, speed)
        command = frame.command
        before, before_pose = self._prepare(command)
        self._write_floats(registers.GV_PARAM0, offs)
        if self._ext_cache != ext:
            self._write_floats(registers.GV_EXT_OFFSET0, ext)
            self._ext_cache = ext
        self._write_floats(registers.GV_EXPECTED_SPEED, [speed])
        tracker = self.begin_command(command, before, before_pose, timeout=timeout)
        if before_pose is not None and frame is StepFrame.BASE:
            x, y, z = before_pose.xyzabc[:3]
            tracker.target = (x + offs[0], y + offs[1], z + offs[2])
        elif before_pose is not None and frame is StepFrame.JOINT and before_pose.joints:
            tracker.target_joints = tuple(q + d for q, d in zip(before_pose.joints, offs, strict=False))
        if before_pose is not None and any(ext) and (tracker.target or tracker.target_joints):
            # the external axes are reported too (GV212..216): they must have arrived as well
            tracker.target_ext = tuple(e + d for e, d in zip(before_pose.ext, ext, strict=False))
        return self._finish(tracker, wait)

    @staticmethod
    def _step_timeout(
        frame: StepFrame, offs: Sequence[float], ext: Sequence[float], speed: float
    ) -> float | None:
        """max(MOVE_TIMEOUT_MIN, 3 x the estimated duration) when that exceeds the minimum."""
        if frame is StepFrame.JOINT:
            duration = max(abs(v) for v in (*offs, *ext)) / (speed * 6.0)  # rpm -> deg/s
        else:
            duration = math.dist((0.0, 0.0, 0.0), offs[:3]) / speed
        estimate = 3.0 * duration
        return estimate if estimate > timing.MOVE_TIMEOUT_MIN else None

    # -- function 2: create temp point ---------------------------------------------------
    def create_point(
        self,
        point_id: int,
        *,
        pose: Sequence[float] | None = None,
        gv_start: int = 0,
        tool: int = registers.TOOL_NONE,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        """Create (or overwrite) a temp point from the current pose, or from ``pose`` via GVs."""
        point_id = self._check_point_id(point_id)
        tool = check_tool(tool)
        values = None if pose is None else check_floats(pose, 6, "pose")
        gv_start = check_int(gv_start, registers.GV_GENERAL_FIRST, _GENERAL_POSE_LAST_START, "first pose GV")
        if timeout is not None:
            timeout = check_float(timeout, "timeout", 0.0, lo_open=True)
        before, _ = self._prepare(RunCommand.CREATE_POINT)
        if values is None:
            self._write_floats(registers.GV_PARAM0, [float(point_id), 0.0])
        else:
            self._write_floats(gv_start, values)
            self._write_floats(registers.GV_PARAM0, [float(point_id), 1.0, float(gv_start)])
        self._sent_points.pop(point_id, None)  # from the current pose: not known here
        if values is not None:
            self._sent_points[point_id] = (values[0], values[1], values[2])
        self._write_tool(tool)
        tracker = self.begin_command(RunCommand.CREATE_POINT, before, None, timeout=timeout)
        return self._finish(tracker, wait)

    def upload_points(
        self,
        points: Iterable[tuple[int, Sequence[float]]],
        tool: int = registers.TOOL_NONE,
        progress: ProgressCallback | None = None,
        *,
        gv_start: int = 0,
        stage: bool = True,
        stage_gv: int | None = None,
        halted: Callable[[], bool] | None = None,
        between: Callable[[], None] | None = None,
        results: list[CommandResult] | None = None,
    ) -> list[CommandResult]:
        """Batched case 2.2: per point the pose GVs (one 0x10), GV200-202 (one 0x10), 440 <- 0xE0, polls.

        Every point is validated before the first write. Returns one result per point tried,
        in order (``details["point_id"]``); a point whose command the controller refuses (a
        failed status) does not stop the others. A link error, a timeout, a malformed answer or a
        Modbus exception ends the batch after a failed result for that point (``status`` None,
        ``reason`` the error's); :attr:`CommandResult.link_failed` tells the first three (the link
        is not to be trusted) from the exception (the controller refused a write or read of that
        point: the link is fine, and a caller goes on with the next point in a fresh call, which
        writes its pose anew). ``progress`` (done, total) returning False cancels after the
        current point.

        **Staging** (``stage``; ``stage_gv``: six more general-purpose GVs, by default the six
        after ``gv_start``, or before it at the top of GV0..GV99): the poses alternate
        between the two blocks, and while the controller works on point n (after the read that
        shows it taken) point n+1's pose goes into the other block. The command in flight
        reads only its own block and GV200-202, which are written after its result, so the
        write only fills the controller's latency. A staged pose the upload then does not use
        (cancelled, link lost) stays in its GVs, unused.

        ``halted`` (any thread may make it True; read on this one): once True -- a stop or a
        cancel is on its way -- no further write of the batch starts: no staging write, no next
        point (the point whose writes went out is waited for). ``between``: run between two status
        reads of a point in flight (:meth:`CommandClient.wait`): the worker's urgent jobs; a stop
        written there ends that point as stopped at once (never "created": its result was not
        seen), and ``progress`` then ends the batch. ``results``: the list the results
        are appended to as they come (returned), so a caller interrupted mid-batch (Ctrl-C) keeps
        what was done.
        """
        items = [
            (self._check_point_id(pid), check_floats(pose, 6, f"pose of point {pid}")) for pid, pose in points
        ]
        tool = check_tool(tool)
        gv_start = check_int(gv_start, registers.GV_GENERAL_FIRST, _GENERAL_POSE_LAST_START, "first pose GV")
        spare = self._stage_block(gv_start, stage_gv) if stage else None
        if results is None:
            results = []
        if not items or (halted is not None and halted()):
            return results
        status = self._begin_upload(tool, halted, between)
        staging = _PoseStaging(
            items,
            gv_start,
            spare,
            lambda gv, values: self._write_floats(gv, values, repeatable=True, halted=halted),
            halted,
        )
        total = len(items)
        for index, (point_id, values) in enumerate(items):
            if halted is not None and halted():
                break  # nothing of this point has gone out: it is not attempted
            block = staging.block_of(index)
            meanwhile = staging.meanwhile(index)
            try:
                result, status = self._create_one(
                    point_id,
                    values,
                    block,
                    status,
                    write_pose=staging.staged != index,
                    meanwhile=meanwhile,
                    between=between,
                    backoff=BusyBackoff(halted, between),
                    line=LineRetry(
                        self.settings,
                        timing.LINE_POINT_RETRIES,
                        halted,
                        timeouts=timing.LINE_POINT_TIMEOUT_RETRIES,
                    ),
                )
            except (
                LinkError,
                ResponseTimeout,
                MalformedResponse,
                ModbusExceptionError,
                OutcomeUnknown,
            ) as exc:
                results.append(_failed_point(point_id, exc))
                break
            results.append(_point_result(point_id, result))
            if progress is not None and progress(index + 1, total) is False:
                break
        return results

    def _begin_upload(
        self, tool: int, halted: Callable[[], bool] | None, between: Callable[[], None] | None
    ) -> ControllerStatus:
        """Before an upload's first point: the status read (444 <- auto when manual) and GV245;
        the status read."""
        backoff = BusyBackoff(halted, between)  # busy before the first point: the status read, GV245
        # a damaged frame there: prepared again (its status read tells whether a 444 <- auto took)
        line = LineRetry(
            self.settings, timing.LINE_POINT_RETRIES, halted, timeouts=timing.LINE_POINT_TIMEOUT_RETRIES
        )
        status, _ = retry_busy(
            lambda: retry_line(lambda: self._prepare(RunCommand.CREATE_POINT), line), backoff
        )
        retry_busy(lambda: self._write_tool(tool), backoff)
        return status

    def _create_one(
        self,
        point_id: int,
        values: Sequence[float],
        block: int,
        status: ControllerStatus,
        *,
        write_pose: bool,
        meanwhile: Callable[[], None] | None,
        between: Callable[[], None] | None,
        backoff: BusyBackoff,
        line: LineRetry,
    ) -> tuple[CommandResult, ControllerStatus]:
        """One point of :meth:`upload_points`: its pose (unless staged), GV200-202, 440 and the status
        reads to its result; the result and the last status read. A *busy* answer to any of them
        (Modbus exception 6) sends the whole point again after ``backoff``'s pause, within its
        budget (the same point at the same pose: idempotent); so does a frame damaged on a serial
        line (:mod:`app.link.line_retry`), at once, within ``line``'s budget, after a fresh status
        read (the "before" of its new command); any other error is raised. Its value registers
        (the pose, GV200-202) are read back after a damaged answer before they are written again."""
        fresh = False  # a status read before the command: the point is sent again after a damaged frame
        while True:
            tracker: CommandTracker | None = None
            try:
                if fresh:
                    status = self.read_status()
                if write_pose:
                    self._write_floats(block, values, repeatable=True, halted=line.halted)
                self._write_floats(
                    registers.GV_PARAM0,
                    [float(point_id), 1.0, float(block)],
                    repeatable=True,
                    halted=line.halted,
                )
                self._sent_points[point_id] = (values[0], values[1], values[2])
                tracker = self.begin_command(RunCommand.CREATE_POINT, status, None)
                result = self.wait(tracker, raise_errors=False, meanwhile=meanwhile, between=between)
                return result, tracker.last_status or status
            except (LinkError, ResponseTimeout, MalformedResponse, ModbusExceptionError) as exc:
                if tracker is not None:  # its command was answered: what it did is not known
                    tracker.unknown(time.monotonic(), exc)
                if line.may_retry(exc):  # the same point at the same pose, at once: idempotent
                    write_pose = fresh = True
                    continue
                if not backoff.may_retry(exc):
                    raise
                busy = exc
            if not backoff.pause():  # a stop or cancel came meanwhile: no retry
                raise busy
            write_pose = True  # the pose again too: the point is sent whole

    @staticmethod
    def _stage_block(gv_start: int, stage_gv: int | None) -> int:
        """The second pose block of an upload (see :meth:`upload_points`), checked."""
        if stage_gv is None:
            after = gv_start + 6
            return after if after <= _GENERAL_POSE_LAST_START else gv_start - 6
        gv = check_int(stage_gv, registers.GV_GENERAL_FIRST, _GENERAL_POSE_LAST_START, "staging pose GV")
        if abs(gv - gv_start) < 6:
            raise InvalidInput(f"the staging pose GVs GV{gv}.. overlap the pose GVs GV{gv_start}..")
        return gv

    # -- function 3: move to temp point --------------------------------------------------
    def move_to_point(
        self,
        end_id: int,
        *,
        via_id: int | None = None,
        orientation_changes: bool = True,
        ignore_middle: bool = False,
        speed: float = 50.0,
        tool: int = registers.TOOL_NONE,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        """Line (``via_id`` None) or arc through ``via_id``: GV200-203 one 0x10, GV225, GV245, 0x42."""
        end_id = self._check_point_id(end_id, "end point id")
        motion = -1.0
        if via_id is not None:
            via_id = self._check_point_id(via_id, "middle point id")
            if via_id == end_id:
                raise InvalidInput("the arc's middle point must differ from its end point")
            motion = float(via_id)
        speed = check_float(speed, "speed", 0.0, lo_open=True)
        if self.caps is not None:
            speed = self.caps.linear_speed(speed)
        tool = check_tool(tool)
        if timeout is not None:
            timeout = check_float(timeout, "timeout", 0.0, lo_open=True)
        before, before_pose = self._prepare(RunCommand.MOVE_TO_POINT)
        self._write_floats(
            registers.GV_PARAM0,
            [motion, float(end_id), 1.0 if orientation_changes else 0.0, 1.0 if ignore_middle else 0.0],
        )
        self._write_floats(registers.GV_EXPECTED_SPEED, [speed])
        self._write_tool(tool)
        tracker = self.begin_command(RunCommand.MOVE_TO_POINT, before, before_pose, timeout=timeout)
        tracker.target = self._sent_points.get(end_id)
        return self._finish(tracker, wait)

    # -- function 4: teach (jog) ---------------------------------------------------------
    def _check_axis(self, frame: TeachFrame | None, axis: int) -> int:
        joint = frame in (TeachFrame.JOINT, None)
        top = (registers.NUM_AXES_TOTAL if joint else registers.NUM_ROBOT_AXES) - 1
        return check_int(axis, 0, top, "axis")

    @staticmethod
    def _check_direction(direction: int) -> int:
        return check_int(direction, 0, 1, "direction (0 negative, 1 positive)")

    def teach_enable(
        self,
        frame: TeachFrame,
        axis: int,
        direction: int,
        *,
        user_frame: int = 0,
        tool_frame: int = 0,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        """GV200-203 = (frame, axis, direction, 0) in one 0x10, GV241/GV245 if needed, 440 <- 0x80."""
        frame = check_enum(frame, TeachFrame, "teach frame")
        axis = self._check_axis(frame, axis)
        direction = self._check_direction(direction)
        user_frame = check_int(user_frame, 0, 0xFFFF, "user frame")
        tool_frame = check_tool(tool_frame)
        before, _ = self._prepare(RunCommand.TEACH_ENABLE)
        self._write_floats(registers.GV_PARAM0, [float(frame), float(axis), float(direction), 0.0])
        if frame is TeachFrame.USER:
            self._write_user_frame(user_frame)
        elif frame is TeachFrame.TOOL:
            self._write_tool(tool_frame)
        tracker = self.begin_command(RunCommand.TEACH_ENABLE, before, None, timeout=timeout)
        self._teach_frame = frame
        return self._finish(tracker, wait)

    def teach_set_ratio(self, ratio: float, *, timeout: float | None = None) -> None:
        """GV203 <- ratio: > 0 moves, 0 stops the jog (teach stays enabled). ``timeout``: s per attempt."""
        ratio = check_float(ratio, "speed ratio", 0.0, 100.0)
        if self.caps is not None:
            ratio = self.caps.jog_ratio(ratio)
        self._write_floats(registers.GV_PARAM3, [ratio], timeout)

    def teach_set_axis(self, axis: int, direction: int) -> None:
        """Ratio 0 first, then GV201-202 (same frame); start again with :meth:`teach_set_ratio`."""
        axis = self._check_axis(self._teach_frame, axis)
        direction = self._check_direction(direction)
        self._write_floats(registers.GV_PARAM3, [0.0])
        self._write_floats(registers.GV_PARAM1, [float(axis), float(direction)])

    def teach_disable(self, *, wait: bool = True, timeout: float | None = None) -> CommandResult:
        """GV203 <- 0 (the controller refuses to disable while the ratio is not 0), 440 <- 0x81."""
        before, _ = self._prepare(RunCommand.TEACH_DISABLE, auto=False)
        self._write_floats(registers.GV_PARAM3, [0.0])
        tracker = self.begin_command(RunCommand.TEACH_DISABLE, before, None, timeout=timeout)
        self._teach_frame = None
        return self._finish(tracker, wait)

"""teachpad-cli's controller commands: monitor, move, jog, teach points, programs, raw GVs.

``status``, ``watch``, ``mode``, ``step``, ``jog``, ``point create``, ``move``, ``zero``,
``program run``, ``stop`` / ``pause`` / ``resume``, ``read``, ``write``: each a handler
``cmd_*(ctx) -> ExitCode`` (see :mod:`app.cli.context`), added to the main parser by
:func:`register`. Errors are raised (typed) and turned into a one-line message and an exit code
once, by ``app/cli/main.py``.
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from app.cli import point_move
from app.cli.context import CliContext, sigint_deferred, stop_after_ctrl_c, wait_motion
from app.cli.exit_codes import ExitCode
from app.cli.format import (
    JOG_SECONDS_MAX,
    format_number,
    format_status,
    parse_axis,
    parse_direction,
    parse_jog_seconds,
    parse_positive_float,
    parse_step_offsets,
    parse_zero_axis,
    status_to_dict,
)
from app.cli.watching import add_watch_parser
from app.errors import AlarmRaised, InvalidInput, OutcomeUnknown, Reason, TeachPadError
from app.link.client import RobotClient
from app.link.halt import HaltWatch, HaltWrite, confirm_halt
from app.link.outcome import UNKNOWN_ADVICE, outcome_note
from app.link.types import HaltKind, StepFrame
from app.link.watch import MotionWatch, StateCheck
from app.models import CommandResult, ControllerStatus, Pose
from app.plan.segments import Segment
from app.points.guard import PointGuard
from app.points.ledger import PointLedger
from app.protocol import registers
from app.protocol.codec import decode_floats, encode_floats
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    ControllerMode,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    WorkMode,
    alarm_names,
    controller_mode_text,
    program_state_text,
)
from app.protocol.word_order_check import judge_pose, warning_text
from app.safety.jog_guard import GuardTiming, JogMotion

__all__ = ["JOG_SECONDS_DEFAULT", "register"]

JOG_POLL_INTERVAL = 0.05  # s between status checks while a jog runs (keeps a watchdog fed)
JOG_SECONDS_DEFAULT = 2.0  # s a jog runs when --seconds is not given
# What the link accepts (RobotClient checks settings.point_id_min..max, the register profile's;
# PROTOCOL.md: 0 <= id <= 10000 by default).
_POINT_ID_RANGE = (
    f"{registers.TEMP_POINT_ID_MIN}..{registers.TEMP_POINT_ID_MAX} "
    "(the register profile's point_id_min..point_id_max)"
)


# --------------------------------------------------------------------------------------------
# Handlers
# --------------------------------------------------------------------------------------------


def cmd_status(ctx: CliContext) -> ExitCode:
    # Monitoring reads use the poll timeout: a silent controller is reported at once. A read
    # that fails raises, so nothing is printed that was not read cleanly.
    client = ctx.client
    timeout = ctx.settings.effective_poll_timeout
    status = client.read_status(with_clock=True, timeout=timeout)
    pose = client.read_pose(timeout=timeout)
    # the word order probably wrong (app/protocol/word_order_check.py): said on stderr, and in the
    # JSON as "word_order_warning" (null when the pose reads right)
    verdict = judge_pose(pose, ctx.settings.word_order)
    warning = warning_text(verdict) if verdict.swapped else None
    if warning is not None:
        ctx.warn(warning)
    if ctx.args.json:
        said = None if warning is None else {"suggested": verdict.suggested.value, "message": warning}
        data = {**status_to_dict(pose, status), "link": client.stats.as_dict(), "word_order_warning": said}
        ctx.print(json.dumps(data))
    else:
        ctx.print(format_status(pose, status))
    return ExitCode.OK


def cmd_mode(ctx: CliContext) -> ExitCode:
    mode = WorkMode.AUTO if ctx.args.mode == "auto" else WorkMode.MANUAL
    client = ctx.client
    wanted = _MODES_READ[mode]
    check = StateCheck(f"work mode {ctx.args.mode}", lambda s: s.mode in wanted, _mode_words, 0.0)
    return _judged(ctx, check, lambda: client.set_work_mode(mode))


# What the controller's mode (560) reads once a work mode (444) is taken: Modbus teach is an auto mode.
_MODES_READ = {
    WorkMode.AUTO: (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH),
    WorkMode.MANUAL: (ControllerMode.MANUAL,),
}


def cmd_step(ctx: CliContext) -> ExitCode:
    frame = StepFrame(ctx.args.frame)
    offsets, ext = parse_step_offsets(frame, ctx.args.offsets)
    client = ctx.client
    if ctx.safety is not None:  # the envelope, from the pose now (refused: nothing is sent)
        joint = frame is StepFrame.JOINT
        ctx.safety.check_step(client.read_pose(), offsets, joint=joint, speed=ctx.args.speed)
    result = wait_motion(
        ctx, lambda: client.step(frame, offsets, ext, speed=ctx.args.speed, wait=not ctx.args.no_wait)
    )
    ctx.print(result.message)
    if not ctx.args.no_wait:
        ctx.print(_pose_line(client.read_pose()))
    return ExitCode.OK


def _pose_line(pose: Pose) -> str:
    pairs = zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True)
    return "pose " + " ".join(f"{n}={format_number(v)}" for n, v in pairs)


def cmd_jog(ctx: CliContext) -> ExitCode:
    """A bounded jog in the envelope: its ratio capped, refused when it would have to stop at
    once, stopped before a boundary by the GUI's jog guard watching the pose (app/cli/guard.py)."""
    args = ctx.args
    frame = TeachFrame[args.frame.upper()]
    axis = parse_axis(args.axis, frame is TeachFrame.JOINT)
    direction = parse_direction(args.dir)
    ratio = float(args.ratio)
    if not 0 < ratio <= 100:
        raise InvalidInput(f"jog ratio must be in (0, 100], got {args.ratio}")
    client = ctx.client
    watch = _JogWatch.start(ctx, JogMotion(frame, axis, direction, ratio))
    writes_before = client.write_count
    halt: HaltWatch | None = None
    stopped: TeachPadError | None = None
    try:
        result = client.teach_enable(frame, axis, direction, user_frame=args.user, tool_frame=args.tool)
        ctx.print(result.message)
        client.teach_set_ratio(watch.motion.ratio)
        deadline = time.monotonic() + args.duration
        while (remaining := deadline - time.monotonic()) > 0:
            status = client.read_status()
            if status.alarms:
                names = ", ".join(alarm_names(int(status.alarms)))
                raise AlarmRaised(int(status.alarms), f"jog: alarm while jogging: {names}")
            stopped = watch.poll(client)
            if stopped is not None:
                break
            time.sleep(min(remaining, JOG_POLL_INTERVAL))
    except KeyboardInterrupt:
        client.close()  # a request may have been cut in half: clean up on a fresh link
        raise
    finally:
        # Always leave the arm still and teach mode off, also after Ctrl-C or an error
        # (but not when nothing was written, e.g. monitor-only or no link at all).
        if client.write_count != writes_before:
            with sigint_deferred():
                halt = _jog_cleanup(ctx, client)
    if halt is not None and not halt.over:
        raise TeachPadError(_halt_failed("jog", halt), code="halt_unconfirmed")
    ctx.print(_pose_line(client.read_pose()))
    if stopped is not None:
        raise stopped
    return ExitCode.OK


class _JogWatch:
    """The envelope around a CLI jog: the GUI's jog guard deciding on every poll's pose, with
    the look-ahead timed as the worker times it (:class:`GuardTiming`)."""

    def __init__(self, ctx: CliContext, motion: JogMotion) -> None:
        self.safety = ctx.safety
        self.motion = motion
        self.guard = None if ctx.safety is None else ctx.safety.session.jog_guard(JOG_POLL_INTERVAL)
        self.timing = GuardTiming()

    @classmethod
    def start(cls, ctx: CliContext, motion: JogMotion) -> _JogWatch:
        """The ratio capped (said when it is), and the jog refused (nothing sent) when it would
        have to stop at once."""
        safety = ctx.safety
        if safety is None:
            return cls(ctx, motion)
        capped = safety.jog_ratio(motion.ratio)
        if capped < motion.ratio:
            mode = " in reduced-speed mode" if safety.session.reduced else ""
            ctx.warn(f"jog: ratio {motion.ratio:g} % capped at {capped:g} %, the envelope's limit{mode}")
            motion = dataclasses.replace(motion, ratio=capped)
        safety.check_jog_start(ctx.client.read_pose(), motion, JOG_POLL_INTERVAL)
        return cls(ctx, motion)

    def poll(self, client: RobotClient) -> TeachPadError | None:
        """Read the pose and decide; the error the jog ends with when the guard stops it."""
        if self.guard is None or self.safety is None:
            return None
        read_at = time.perf_counter()
        pose = client.read_pose()
        now = time.perf_counter()
        self.timing.note_read(read_at, now)
        self.timing.note_decision(now, jogging=True)
        horizon = self.timing.horizon(self.guard, now, read_at)
        self.timing.note_horizon(now, horizon)
        decision = self.guard.decide(pose, self.motion, horizon)
        if decision.allow or decision.violation is None:
            return None
        return self.safety.guard_stopped(decision.violation, self.motion)


def _jog_cleanup(ctx: CliContext, client: RobotClient) -> HaltWatch:
    """The jog is over only when the controller has answered speed 0 (or a Stop) and the pose is
    seen still: speed 0 again every ``JOG_POLL_INTERVAL``, a Stop too after
    ``timing.HALT_ESCALATE_AFTER``, for ``timing.HALT_CONFIRM_BUDGET`` at most (app/link/halt.py).
    Then teach mode off. What went wrong is said in a warning (the arm stopped or not)."""
    halt = HaltWatch(HaltKind.RELEASE, None, time.monotonic())
    _confirm(client, halt)
    if not halt.over:
        ctx.warn(_halt_failed("jog", halt) + "; teach mode was left on")
        return halt
    if halt.refusals:
        ctx.warn(_halt_confirmed("jog", halt))
    try:
        client.teach_disable()
    except TeachPadError as exc:
        ctx.warn(f"could not disable teach mode: {exc}")
    return halt


def _confirm(client: RobotClient, halt: HaltWatch) -> None:
    def write(what: HaltWrite) -> None:
        if what is HaltWrite.SPEED_ZERO:
            client.teach_set_ratio(0.0)
        elif what is HaltWrite.PAUSE:
            client.pause()
        else:
            client.stop()

    confirm_halt(write, client.read_pose, halt, interval=JOG_POLL_INTERVAL)


def _halt_failed(what: str, halt: HaltWatch) -> str:
    return f"{what}: {halt.words(time.monotonic())}: the arm may still be moving -- stop it at the controller"


def _halt_confirmed(what: str, halt: HaltWatch) -> str:
    seconds = (halt.answered_at or time.monotonic()) - halt.since
    answered = {HaltWrite.STOP: "stop (441)", HaltWrite.PAUSE: "pause (442)"}.get(
        halt.answered_by or HaltWrite.SPEED_ZERO, "speed 0"
    )
    return (
        f"{what}: the controller refused or did not answer {halt.refusals} time(s) "
        f"({halt.last_error}); it took the {answered} after {seconds:.1f} s and the arm stands still"
    )


def cmd_point_create(ctx: CliContext) -> ExitCode:
    args = ctx.args
    client = ctx.client
    pose = args.xyzabc  # None: from the current pose
    result = client.create_point(args.id, pose=pose, gv_start=args.gv_start, tool=args.tool)
    ctx.print(f"point {args.id}: {result.message}")
    if pose is None:
        # The controller forgets temp points on restart: show the pose the host should keep.
        ctx.print(_pose_line(client.read_pose()))
    return ExitCode.OK


def cmd_move(ctx: CliContext) -> ExitCode:
    """Guarded by the project's copy of the points with ``--project`` (app/cli/point_move.py)."""
    args = ctx.args
    if args.via is not None and args.via == args.id:  # a usage error before any other check
        raise InvalidInput("the arc's middle point must differ from its end point")
    guard = point_move.move_guard(ctx)  # before connecting: a bad project sends nothing
    client = ctx.client
    tool = args.tool
    if ctx.safety is not None:  # the envelope, from the pose now (refused: nothing is sent)
        _check_move(ctx, client, guard)
    if guard is not None:
        point_move.prepare_points(guard, client, args)
        tool = guard.point(args.id).tool if tool is None else tool
    result = wait_motion(
        ctx,
        lambda: client.move_to_point(
            args.id,
            via_id=args.via,
            orientation_changes=not args.keep_orientation,
            ignore_middle=args.ignore_middle,
            speed=args.speed,
            tool=registers.TOOL_NONE if tool is None else tool,
            wait=not args.no_wait,
            timeout=args.wait_timeout,
        ),
    )
    if args.no_wait:
        ctx.print(result.message)
        if guard is not None:
            ctx.warn(f"P{args.id}: the arrival is not checked with --no-wait")
        return ExitCode.OK
    pose = client.read_pose()
    if guard is not None:
        point_move.check_arrival(guard, pose, args.id)  # elsewhere: exit 1, in words
    ctx.print(result.message)
    ctx.print(_pose_line(pose))
    if guard is None:
        ctx.warn(point_move.UNCHECKED_WARNING.format(id=args.id))
    return ExitCode.OK


def _check_move(ctx: CliContext, client: RobotClient, guard: PointGuard | None) -> None:
    """The move's path from the pose now against the envelope (with the project's copy of its
    points; without one only what can be checked, app/cli/guard.py)."""
    assert ctx.safety is not None
    args = ctx.args
    if args.via is None:
        segment = Segment.line(args.id, args.speed)
    else:
        segment = Segment.arc(args.via, args.id, args.speed)
    points = point_move.point_ids(args)
    ledger = None if guard is None else PointLedger.from_checked([guard.point(i) for i in points])
    ctx.safety.check_move(client.read_pose(), segment, ledger)


def cmd_zero(ctx: CliContext) -> ExitCode:
    axis = parse_zero_axis(ctx.args.axis)
    client = ctx.client
    return _follow_watch(ctx, lambda: client.go_zero(axis, switch_to_auto=ctx.args.auto))


_PROGRAM_MODES = {
    "step": ProgramMotionMode.SINGLE_STEP,
    "single": ProgramMotionMode.SINGLE_RUN,
    "cycle": ProgramMotionMode.CYCLE,
}


def cmd_program_run(ctx: CliContext) -> ExitCode:
    args = ctx.args
    client = ctx.client
    mode = _PROGRAM_MODES[args.mode]
    return _follow_watch(
        ctx,
        lambda: client.run_program(
            args.id, mode, cycles=args.cycles, speed_ratio=args.speed, switch_to_auto=args.auto
        ),
        until_started=args.no_wait,
    )


def _follow_watch(
    ctx: CliContext, start: Callable[[], MotionWatch], *, until_started: bool = False
) -> ExitCode:
    """Send a command told by motion (go to zero, run program) and follow it to its outcome (or,
    ``until_started``, until it is seen under way); Ctrl-C meanwhile sends stop."""
    client = ctx.client
    writes_before = client.write_count
    sent = time.monotonic()
    try:
        watch = start()
        result = client.follow(watch, until_started=until_started)
    except KeyboardInterrupt:
        # Ctrl-C while the command was being sent or followed: what it started is a motion under way
        if client.write_count != writes_before:
            stop_after_ctrl_c(ctx, command_sent=sent)
        raise
    if result is None:
        return ctx.report(f"{watch.text}: started (under way; its end is not waited for)")
    return ctx.report(result.message)


def cmd_stop(ctx: CliContext) -> ExitCode:
    """441 until the controller takes it and the pose is seen still (app/link/halt.py); the audit
    records the outcome against every 441 sent (done, refused, unknown)."""
    client = ctx.client
    halt = HaltWatch(HaltKind.STOP, None, time.monotonic())
    with client.judged_writes() as judged:
        _confirm(client, halt)
    note = outcome_note(client.audit, judged) or (lambda _result: None)
    if halt.given_up and halt.refusals == 1 and halt.last_error is not None:
        note(_stop_result(False, str(halt.last_error), "refused"))
        raise halt.last_error  # refused for good (not busy): the controller's own words, at once
    if not halt.over:
        note(_stop_result(False, _halt_failed("stop", halt), "outcome_unknown"))
        raise TeachPadError(_halt_failed("stop", halt), code="halt_unconfirmed")
    if halt.refusals:
        ctx.warn(_halt_confirmed("stop", halt))
    note(_stop_result(True, "stop: done (the arm stands still)", "done"))
    return ctx.report("stop: done (the arm stands still)")


def _stop_result(ok: bool, message: str, code: str) -> CommandResult:
    """The outcome of the CLI's stop as the audit records it (no GV291 result: told by motion)."""
    return CommandResult(None, None, None, ok, message, reason=Reason(code))


def cmd_pause(ctx: CliContext) -> ExitCode:
    """442 until the controller answers it and the pose is seen still (app/link/halt.py): refused
    or unanswered, sent again every ``JOG_POLL_INTERVAL``; not answered within
    ``timing.PAUSE_ESCALATE_AFTER`` s, a Stop instead (exit 1: the arm was stopped, not paused);
    nothing taken within ``timing.HALT_CONFIRM_BUDGET`` s: said, exit 1. Then the program state
    is followed as before (paused, or nothing under way: the arm stands still)."""
    client = ctx.client
    halt = HaltWatch(HaltKind.PAUSE, None, time.monotonic())
    with client.judged_writes() as judged:
        _confirm(client, halt)
    note = outcome_note(client.audit, judged)
    if halt.given_up and halt.refusals == 1 and halt.last_error is not None:
        raise halt.last_error  # refused for good (not busy): the controller's own words, at once
    failure = _pause_failure(halt)
    if failure is not None:
        if note is not None:
            note(CommandResult(None, None, None, False, str(failure), reason=failure.as_reason()))
        raise failure
    if halt.refusals:
        ctx.warn(_halt_confirmed("pause", halt))
    # nothing under way (stopped) is what a pause wants too: the arm stands still
    paused = (ProgramState.PAUSED, ProgramState.STOPPED)
    check = StateCheck("pause", lambda s: s.program_state in paused, _state_words, 0.0)
    check.started = time.monotonic()
    check.note = note
    result = client.follow(check)
    assert result is not None
    return ctx.report(result.message)


def _pause_failure(halt: HaltWatch) -> TeachPadError | None:
    """The CLI's pause did not pause: not confirmed at all, or a Stop was taken instead."""
    if not halt.over:
        return TeachPadError(_halt_failed("pause", halt), code="halt_unconfirmed")
    if halt.answered_by is HaltWrite.STOP:
        seconds = (halt.answered_at or time.monotonic()) - halt.since
        return TeachPadError(
            f"pause: the controller did not take the pause within {seconds:.1f} s "
            f"({halt.refusals} refused or unanswered: {halt.last_error}); Stop (441) was sent instead "
            "and the arm stands still -- it was stopped, not paused",
            code="pause_stopped",
        )
    return None


def cmd_resume(ctx: CliContext) -> ExitCode:
    check = StateCheck("resume", lambda s: s.program_state == ProgramState.RUNNING, _state_words, 0.0)
    return _judged(ctx, check, ctx.client.resume)


def _mode_words(status: ControllerStatus) -> str:
    return f"the controller's mode reads {controller_mode_text(int(status.mode))}"


def _state_words(status: ControllerStatus) -> str:
    return f"the program state reads {program_state_text(int(status.program_state))}"


def _judged(ctx: CliContext, check: StateCheck, send: Callable[[], object]) -> ExitCode:
    """Send a plain command (its writes judged in the audit trail) and follow ``check`` to the
    controller's outcome: done (exit 0), not taken (1) or unknown (4)."""
    client = ctx.client
    with client.judged_writes() as judged:
        send()
    check.started = time.monotonic()
    check.note = outcome_note(client.audit, judged)
    result = client.follow(check)
    assert result is not None
    return ctx.report(result.message)


def cmd_read(ctx: CliContext) -> ExitCode:
    gv, count = ctx.args.gv, ctx.args.count
    if gv < 0:
        raise InvalidInput(f"read: GV must be >= 0, got {gv}")
    if not 1 <= count <= 62:
        raise InvalidInput(f"read: COUNT must be 1..62 (one request), got {count}")
    regs = ctx.client.read_registers(registers.gv_reg(gv), 2 * count)
    for i, value in enumerate(decode_floats(regs, ctx.settings.word_order)):
        raw = " ".join(f"{r:04X}" for r in regs[2 * i : 2 * i + 2])
        ctx.print(f"GV{gv + i} = {value!r}  ({raw})")
    return ExitCode.OK


def cmd_write(ctx: CliContext) -> ExitCode:
    """Write GVs, then read them back: the controller kept them (done), overwrote or did not keep
    them (refused, exit 1), or the read-back failed (unknown, exit 4)."""
    gv, values = ctx.args.gv, ctx.args.values
    client = ctx.client
    order = ctx.settings.word_order
    regs = encode_floats(values, order)
    what = f"GV{gv}" if len(values) == 1 else f"GV{gv}..GV{gv + len(values) - 1}"
    with client.judged_writes() as judged:
        client.write_gv(gv, values)
    note = outcome_note(client.audit, judged) or (lambda result: None)
    raw = " ".join(f"{r:04X}" for r in regs)
    try:
        back = client.read_registers(registers.gv_reg(gv), len(regs))
    except TeachPadError as exc:
        unknown = OutcomeUnknown(f"{what} write: {UNKNOWN_ADVICE} (the read-back failed: {exc})")
        note(CommandResult(None, None, None, False, str(unknown), reason=unknown.as_reason()))
        raise unknown from None
    if list(back) != list(regs):
        got = ", ".join(repr(v) for v in decode_floats(back, order))
        refused = TeachPadError(
            f"{what} written ({raw}), but they read back {got}: the controller did not keep them"
        )
        note(CommandResult(None, None, None, False, str(refused), reason=Reason("not_kept")))
        raise refused
    text = f"{what} written ({raw}), read back the same"
    note(CommandResult(None, None, None, True, text, reason=Reason("done")))
    return ctx.report(text)


# --------------------------------------------------------------------------------------------
# Parsers
# --------------------------------------------------------------------------------------------

_MANUAL_TEXT = (
    "A controller in manual mode is refused (exit 1, nothing written): switching the work mode is "
    "the operator's decision; --auto switches it to auto first (444 <- 1, its own audited write), "
    "then sends {what}."
)


def _add_auto(parser: Any) -> None:
    parser.add_argument(
        "--auto",
        action="store_true",
        help="in manual mode, switch the controller to auto (444 <- 1) first; without it manual mode "
        "is refused (exit 1, nothing written)",
    )


def register(sub: Any) -> None:
    """Add the controller commands to the main parser's subcommands (``sub``)."""
    p = sub.add_parser("status", help="pose, joints, mode, program state, alarms, command status, clock")
    p.add_argument("--json", action="store_true", help="one JSON object")
    p.set_defaults(handler=cmd_status)

    add_watch_parser(sub)  # app/cli/watching.py

    p = sub.add_parser("mode", help="set the work mode")
    p.add_argument("mode", choices=("auto", "manual"), help="auto or manual (register 444)")
    p.set_defaults(handler=cmd_mode)

    p = sub.add_parser("step", help="incremental move (function 1), e.g. step --frame base X=10 Z=-5")
    p.add_argument(
        "--frame",
        choices=("joint", "base"),
        required=True,
        help="joint: offsets in degrees per joint; base: X Y Z in mm, A B C in degrees",
    )
    p.add_argument(
        "offsets", nargs="+", metavar="AXIS=VALUE", help="J1..J11 (joint) or X Y Z A B C (+ J7..J11) (base)"
    )
    p.add_argument("--speed", type=parse_positive_float, default=10.0, help="rpm (joint) or mm/s (base)")
    p.add_argument("--no-wait", action="store_true", help="return once the command is sent")
    p.set_defaults(handler=cmd_step)

    p = sub.add_parser(
        "jog",
        help="teach-mode jog for a bounded time (function 4); always stops and disables",
        description="Jog one axis in teach mode, then write ratio 0 and disable teach mode. The jog is "
        f"bounded: it stops after --seconds (default {JOG_SECONDS_DEFAULT:g} s, at most "
        f"{JOG_SECONDS_MAX:g} s), on Ctrl-C and on any error. The safety envelope binds it as in the "
        "GUI: the ratio is capped at the envelope's jog cap, a jog that would have to stop at once "
        "is refused, and the jog guard stops it before a boundary (exit 1). Example: "
        "teachpad-cli --host 192.168.1.10 jog --axis Z --dir + --ratio 10 --seconds 1.5",
    )
    p.add_argument(
        "--frame",
        choices=("base", "user", "tool", "joint"),
        default="base",
        help="the frame the axis belongs to (default %(default)s)",
    )
    p.add_argument("--user", type=int, default=0, metavar="N", help="user frame id (frame user)")
    p.add_argument("--tool", type=int, default=0, metavar="N", help="tool frame id (frame tool)")
    p.add_argument("--axis", required=True, help="X Y Z A B C, or J1..J11 in the joint frame")
    p.add_argument("--dir", required=True, help="+ or -")
    p.add_argument("--ratio", type=float, required=True, help="speed ratio in percent, 0 < N <= 100")
    p.add_argument(
        "--seconds",
        "--for",
        dest="duration",
        type=parse_jog_seconds,
        default=JOG_SECONDS_DEFAULT,
        metavar="S",
        help=f"how long to jog, in seconds: 0 < S <= {JOG_SECONDS_MAX:g} "
        f"(default {JOG_SECONDS_DEFAULT:g}); --for is the same",
    )
    p.set_defaults(handler=cmd_jog)

    p = sub.add_parser("point", help="temp points (function 2)")
    psub = p.add_subparsers(dest="point_command", metavar="ACTION", required=True)
    pc = psub.add_parser("create", help="create or overwrite a temp point")
    pc.add_argument("id", type=int, help=f"temp point id, {_POINT_ID_RANGE}")
    src = pc.add_mutually_exclusive_group()
    src.add_argument("--from-pose", action="store_true", help="from the current pose (default)")
    src.add_argument(
        "--xyzabc",
        type=float,
        nargs=6,
        metavar=("X", "Y", "Z", "A", "B", "C"),
        help="the pose: X Y Z in mm, A B C in degrees (base frame)",
    )
    pc.add_argument(
        "--tool",
        type=int,
        default=registers.TOOL_NONE,
        metavar="N",
        help="tool frame 0..199 as GV245, the CSV and the GUI number it; 200 none (default)",
    )
    pc.add_argument("--gv-start", type=int, default=0, metavar="N", help="first of the six pose GVs")
    pc.set_defaults(handler=cmd_point_create)

    p = sub.add_parser("move", help="move to a temp point: line, or arc with --via (function 3)")
    p.add_argument("id", type=int, help=f"temp point id of the end point, {_POINT_ID_RANGE}")
    p.add_argument("--via", type=int, metavar="MID", help="temp point id of an arc's middle point")
    p.add_argument("--speed", type=parse_positive_float, default=50.0, help="mm/s (default %(default)g)")
    p.add_argument(
        "--keep-orientation", action="store_true", help="keep the tool's orientation (A B C) along an arc"
    )
    p.add_argument(
        "--ignore-middle",
        action="store_true",
        help="arc: use the middle point's position only, not its orientation",
    )
    p.add_argument(
        "--tool",
        type=int,
        default=None,
        metavar="N",
        help=f"tool frame id (default: the point's in --project, else {registers.TOOL_NONE}: none)",
    )
    p.add_argument(
        "--project",
        type=Path,
        metavar="FILE",
        help="the project holding the points (the host's copy): they are created again from it right "
        "before the move and the arrival is checked against it (1 mm), and the path is checked "
        "against the safety envelope. Without it the point cannot be checked: refused when the "
        "envelope has a keep-in box or keep-out zones (a fresh install's has one)",
    )
    p.add_argument("--no-wait", action="store_true", help="return once the command is sent")
    p.add_argument(
        "--wait-timeout",
        type=parse_positive_float,
        default=None,
        metavar="SECONDS",
        help="give up waiting after this many seconds (default: by distance and speed)",
    )
    p.set_defaults(handler=cmd_move)

    p = sub.add_parser(
        "zero",
        help="go to zero: one axis (J1..J11) or all; waits until the arm stands at zero",
        description="Send one axis or all axes to zero (register 445) and wait until the arm stands at zero. "
        + _MANUAL_TEXT.format(what="go to zero")
        + " Refused with --reduced-speed: go to zero runs at the controller's own speed.",
    )
    p.add_argument("axis", metavar="AXIS|all", help="J1..J11, or all")
    _add_auto(p)
    p.set_defaults(handler=cmd_zero)

    p = sub.add_parser("program", help="controller programs")
    psub = p.add_subparsers(dest="program_command", metavar="ACTION", required=True)
    pr = psub.add_parser(
        "run",
        help="run a program",
        description="Run a controller program (446..449, then 440 <- 0x01). "
        + _MANUAL_TEXT.format(what="the program")
        + " With --reduced-speed the speed ratio is capped.",
    )
    pr.add_argument("id", type=int, help="program id on the controller (register 446)")
    pr.add_argument(
        "--mode",
        choices=tuple(_PROGRAM_MODES),
        default="single",
        help="step: one segment; single: one run; cycle: --cycles runs (default %(default)s)",
    )
    pr.add_argument("--cycles", type=int, default=1, help="cycle count (0: endless)")
    pr.add_argument(
        "--speed", type=int, default=100, help="speed ratio in percent, 1..100 (default %(default)s)"
    )
    pr.add_argument(
        "--no-wait",
        action="store_true",
        help="return once the program is seen running (a refusal is still told); its end is not waited for",
    )
    _add_auto(pr)
    pr.set_defaults(handler=cmd_program_run)

    for name, handler, text in (
        ("stop", cmd_stop, "stop the motion or program"),
        ("pause", cmd_pause, "pause"),
        ("resume", cmd_resume, "resume"),
    ):
        p = sub.add_parser(name, help=text)
        p.set_defaults(handler=handler)

    p = sub.add_parser("read", help="read GVs (float32)")
    p.add_argument("gv", type=int, metavar="GV", help="first GV number, 0..299 (e.g. 291)")
    p.add_argument("count", type=int, nargs="?", default=1, metavar="COUNT", help="how many GVs (default 1)")
    p.set_defaults(handler=cmd_read)

    p = sub.add_parser("write", help="write GVs (float32, one 0x10)")
    p.add_argument("gv", type=int, metavar="GV", help="first GV number, 0..299")
    p.add_argument(
        "values",
        type=float,
        nargs="+",
        metavar="VALUE",
        help="float32 values, written to GV, GV+1, ... (units as the GV's meaning)",
    )
    p.set_defaults(handler=cmd_write)

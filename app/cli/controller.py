"""teachpad-cli's controller commands: monitor, move, jog, teach points, programs, raw GVs.

``status``, ``watch``, ``mode``, ``step``, ``jog``, ``point create``, ``move``, ``zero``,
``program run``, ``stop`` / ``pause`` / ``resume``, ``read``, ``write``: each a handler
``cmd_*(ctx) -> ExitCode`` (see :mod:`app.cli.context`), added to the main parser by
:func:`register`. Errors are raised (typed) and turned into a one-line message and an exit code
once, by ``app/cli/main.py``.
"""

from __future__ import annotations

import json
import time
from typing import Any

from app.cli.context import CliContext, sigint_deferred, stop_after_ctrl_c, wait_motion
from app.cli.exit_codes import ExitCode
from app.cli.format import (
    JOG_SECONDS_MAX,
    format_number,
    format_status,
    format_watch_line,
    parse_axis,
    parse_direction,
    parse_jog_seconds,
    parse_positive_float,
    parse_step_offsets,
    parse_zero_axis,
    status_to_dict,
)
from app.errors import AlarmRaised, CommandRefused, InvalidInput, TeachPadError
from app.link.client import RobotClient, StepFrame
from app.link.tracker import pose_moved
from app.models import Pose
from app.protocol import registers
from app.protocol.codec import decode_floats, encode_floats
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    JOINT_AXIS_NAMES,
    CommandStatus,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    WorkMode,
    alarm_names,
)

__all__ = ["JOG_SECONDS_DEFAULT", "register"]

JOG_POLL_INTERVAL = 0.05  # s between status checks while a jog runs (keeps a watchdog fed)
JOG_SECONDS_DEFAULT = 2.0  # s a jog runs when --seconds is not given
WATCH_RATE_DEFAULT = 10.0  # Hz
# A program the controller accepted shows program state running (or has moved the arm) within
# this time; one that stays stopped was not started (unknown id, or refused).
PROGRAM_START_TIMEOUT = 1.0  # s
PROGRAM_START_POLL = 0.02  # s between status reads while waiting for the start


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
    if ctx.args.json:
        ctx.print(json.dumps({**status_to_dict(pose, status), "link": client.stats.as_dict()}))
    else:
        ctx.print(format_status(pose, status))
    return ExitCode.OK


def cmd_watch(ctx: CliContext) -> ExitCode:
    client = ctx.client
    period = 1.0 / ctx.args.rate
    count = ctx.args.count
    start = time.monotonic()
    next_t = start
    n = 0
    try:
        timeout = ctx.settings.effective_poll_timeout
        while count <= 0 or n < count:
            status = client.read_status(timeout=timeout)
            pose = client.read_pose(timeout=timeout)
            ctx.print(format_watch_line(time.monotonic() - start, pose, status))
            n += 1
            if count > 0 and n >= count:
                break
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                next_t = time.monotonic()  # fell behind: do not burst
    except KeyboardInterrupt:
        return ExitCode.OK  # Ctrl-C is how a watch normally ends
    return ExitCode.OK


def cmd_mode(ctx: CliContext) -> ExitCode:
    mode = WorkMode.AUTO if ctx.args.mode == "auto" else WorkMode.MANUAL
    ctx.client.set_work_mode(mode)
    return ctx.report(f"work mode set to {ctx.args.mode}")


def cmd_step(ctx: CliContext) -> ExitCode:
    frame = StepFrame(ctx.args.frame)
    offsets, ext = parse_step_offsets(frame, ctx.args.offsets)
    client = ctx.client
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
    args = ctx.args
    frame = TeachFrame[args.frame.upper()]
    axis = parse_axis(args.axis, frame is TeachFrame.JOINT)
    direction = parse_direction(args.dir)
    ratio = float(args.ratio)
    if not 0 < ratio <= 100:
        raise InvalidInput(f"jog ratio must be in (0, 100], got {args.ratio}")
    client = ctx.client
    writes_before = client.write_count
    try:
        result = client.teach_enable(frame, axis, direction, user_frame=args.user, tool_frame=args.tool)
        ctx.print(result.message)
        client.teach_set_ratio(ratio)
        deadline = time.monotonic() + args.duration
        while (remaining := deadline - time.monotonic()) > 0:
            status = client.read_status()
            if status.alarms:
                names = ", ".join(alarm_names(int(status.alarms)))
                raise AlarmRaised(int(status.alarms), f"jog: alarm while jogging: {names}")
            time.sleep(min(remaining, JOG_POLL_INTERVAL))
    except KeyboardInterrupt:
        client.close()  # a request may have been cut in half: clean up on a fresh link
        raise
    finally:
        # Always leave the arm still and teach mode off, also after Ctrl-C or an error
        # (but not when nothing was written, e.g. monitor-only or no link at all).
        if client.write_count != writes_before:
            with sigint_deferred():
                _jog_cleanup(ctx, client)
    ctx.print(_pose_line(client.read_pose()))
    return ExitCode.OK


def _jog_cleanup(ctx: CliContext, client: RobotClient) -> None:
    try:
        client.teach_set_ratio(0.0)
    except TeachPadError as exc:
        ctx.warn(f"could not set the jog ratio to 0: {exc}")
    try:
        client.teach_disable()
    except TeachPadError as exc:
        ctx.warn(f"could not disable teach mode: {exc}")


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
    args = ctx.args
    client = ctx.client
    result = wait_motion(
        ctx,
        lambda: client.move_to_point(
            args.id,
            via_id=args.via,
            orientation_changes=not args.keep_orientation,
            ignore_middle=args.ignore_middle,
            speed=args.speed,
            tool=args.tool,
            wait=not args.no_wait,
            timeout=args.wait_timeout,
        ),
    )
    ctx.print(result.message)
    if not args.no_wait:
        ctx.print(_pose_line(client.read_pose()))
    return ExitCode.OK


def cmd_zero(ctx: CliContext) -> ExitCode:
    axis = parse_zero_axis(ctx.args.axis)
    ctx.client.go_zero(axis, switch_to_auto=ctx.args.auto)
    target = "all axes" if axis is None else JOINT_AXIS_NAMES[axis]
    return ctx.report(f"go to zero sent ({target})")


_PROGRAM_MODES = {
    "step": ProgramMotionMode.SINGLE_STEP,
    "single": ProgramMotionMode.SINGLE_RUN,
    "cycle": ProgramMotionMode.CYCLE,
}


def cmd_program_run(ctx: CliContext) -> ExitCode:
    client = ctx.client
    before = client.read_pose()
    writes_before = client.write_count
    sent = time.monotonic()
    try:
        return _start_program(ctx, client, before)
    except KeyboardInterrupt:
        # Ctrl-C while the program was being started: what it started is a motion under way
        if client.write_count != writes_before:
            stop_after_ctrl_c(ctx, command_sent=sent)
        raise


def _start_program(ctx: CliContext, client: RobotClient, before: Pose) -> ExitCode:
    """Send the run command, then wait to see the program run (the controller answers a run
    command only through its state)."""
    args = ctx.args
    client.run_program(
        args.id,
        _PROGRAM_MODES[args.mode],
        cycles=args.cycles,
        speed_ratio=args.speed,
        switch_to_auto=args.auto,
    )
    deadline = time.monotonic() + PROGRAM_START_TIMEOUT
    while True:
        status = client.read_status()
        if status.alarms:
            names = ", ".join(alarm_names(int(status.alarms)))
            raise AlarmRaised(int(status.alarms), f"program {args.id} not started: alarm {names}")
        if status.program_state in (ProgramState.RUNNING, ProgramState.PAUSED):
            return ctx.report(f"program {args.id} running ({args.mode})")
        if pose_moved(client.read_pose(), before):
            return ctx.report(f"program {args.id} ran and ended ({args.mode})")
        if time.monotonic() >= deadline:
            raise CommandRefused(
                CommandStatus(None, status.command_status_code),
                f"the controller did not start program {args.id}: its program state stayed stopped for "
                f"{PROGRAM_START_TIMEOUT:g} s (no such program, or the controller refused it)",
                code="program_not_started",
                params={"program": args.id},
            )
        time.sleep(PROGRAM_START_POLL)


def cmd_stop(ctx: CliContext) -> ExitCode:
    ctx.client.stop()
    return ctx.report("stop sent")


def cmd_pause(ctx: CliContext) -> ExitCode:
    ctx.client.pause()
    return ctx.report("pause sent")


def cmd_resume(ctx: CliContext) -> ExitCode:
    ctx.client.resume()
    return ctx.report("resume sent")


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
    gv, values = ctx.args.gv, ctx.args.values
    ctx.client.write_gv(gv, values)
    raw = " ".join(f"{r:04X}" for r in encode_floats(values, ctx.settings.word_order))
    return ctx.report(f"GV{gv}..GV{gv + len(values) - 1} written ({raw})")


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

    p = sub.add_parser("watch", help="stream one status line per sample")
    p.add_argument(
        "--rate",
        type=parse_positive_float,
        default=WATCH_RATE_DEFAULT,
        metavar="HZ",
        help="samples per second, Hz (default %(default)g)",
    )
    p.add_argument("--count", type=int, default=0, metavar="N", help="stop after N lines (0: until Ctrl-C)")
    p.set_defaults(handler=cmd_watch)

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
        f"{JOG_SECONDS_MAX:g} s), on Ctrl-C and on any error. Example: "
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
    pc.add_argument("id", type=int, help="temp point id, 1..10000")
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
        help="GV245: 200 none (default), N = tool N+1",
    )
    pc.add_argument("--gv-start", type=int, default=0, metavar="N", help="first of the six pose GVs")
    pc.set_defaults(handler=cmd_point_create)

    p = sub.add_parser("move", help="move to a temp point: line, or arc with --via (function 3)")
    p.add_argument("id", type=int, help="temp point id of the end point, 1..10000")
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
        default=registers.TOOL_NONE,
        metavar="N",
        help=f"tool frame id ({registers.TOOL_NONE}: none, the default)",
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
        help="go to zero: one axis (J1..J11) or all",
        description="Send one axis or all axes to zero (register 445). "
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

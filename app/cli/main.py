"""teachpad-cli: script the controller from a shell.

    teachpad-cli [--host H --port P --unit U | --rtu DEV --baud B --parity N] [--word-order W]
                 [--timeout S] [--monitor-only] COMMAND ...

Exit codes: 0 success; 1 the command failed (refused by the controller, Modbus exception,
command timeout, alarm, stopped, or blocked by --monitor-only); 2 usage (bad arguments or
values, nothing sent); 3 link problem (cannot connect, no answer in time, malformed answer);
130 interrupted
(Ctrl-C; a motion that was under way is stopped first). Errors are one line on stderr.

Adding subcommands: a *registrar* is a callable ``register(subparsers)`` that adds parsers to
the ``argparse`` sub-parser action and sets ``handler=fn`` on each with ``set_defaults``;
``fn(ctx: CliContext) -> int`` gets the parsed arguments as ``ctx.args`` and a connected
:class:`~app.link.client.RobotClient` from ``ctx.client`` (connected on first use, so commands that
work offline never touch the link). Put a registrar in :data:`REGISTRARS`, or ship a module
named in :data:`PLUGIN_MODULES` (``app.cli.points``, ``app.cli_run``) with a ``register``
function: it is picked up when it exists.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import json
import logging
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, TextIO

from app.errors import (
    AlarmRaised,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ResponseTimeout,
    TeachPadError,
)
from app.link.client import ConnectionSettings, RobotClient, StepFrame
from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.codec import WordOrder, decode_floats, encode_floats
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    JOINT_AXIS_NAMES,
    CommandStatus,
    ProgramMotionMode,
    TeachFrame,
    WorkMode,
    alarm_names,
    controller_mode_text,
    program_state_text,
)
from app.safety.audit import AuditLog

PROG = "teachpad-cli"

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_LINK = 3
EXIT_INTERRUPTED = 130

JOG_POLL_INTERVAL = 0.05  # s between status checks while a jog runs (keeps a watchdog fed)
JOG_SECONDS_DEFAULT = 2.0  # s a jog runs when --seconds is not given
JOG_SECONDS_MAX = 30.0  # s: no jog from the CLI runs longer
WATCH_RATE_DEFAULT = 10.0  # Hz

Registrar = Callable[[Any], None]  # register(subparsers: argparse._SubParsersAction)
Handler = Callable[["CliContext"], int]


@dataclass
class CliContext:
    """What a subcommand handler gets: the arguments, a lazily connected client, the streams."""

    args: argparse.Namespace
    settings: ConnectionSettings
    out: TextIO = field(default_factory=lambda: sys.stdout)
    err: TextIO = field(default_factory=lambda: sys.stderr)
    _client: RobotClient | None = None

    @property
    def client(self) -> RobotClient:
        if self._client is None:
            client = RobotClient(self.settings)
            # The CLI is an administrator's tool; its writes go to the same audit trail as the GUI's.
            client.audit = AuditLog(role="administrator (cli)", word_order=self.settings.word_order)
            self._client = client
            client.connect()
        return self._client

    def print(self, *parts: object) -> None:
        print(*parts, file=self.out, flush=True)

    def warn(self, message: str) -> None:
        print(f"{PROG}: warning: {message}", file=self.err, flush=True)

    def close(self) -> None:
        if self._client is not None:
            self._client.close()


# --------------------------------------------------------------------------------------------
# Formatting
# --------------------------------------------------------------------------------------------


def _num(value: float) -> str:
    return f"{value:.3f}"


def status_to_dict(pose: Pose, status: ControllerStatus) -> dict[str, Any]:
    """The JSON shape of ``status --json``."""
    code = status.command_status_code
    decoded = CommandStatus(None, code)
    clock = status.clock
    return {
        "pose": dict(zip(("x", "y", "z", "a", "b", "c"), pose.xyzabc, strict=True)),
        "external_axes": list(pose.ext),
        "joints": list(pose.joints) if pose.joints is not None else None,
        "mode": {"value": int(status.mode), "name": controller_mode_text(int(status.mode))},
        "program_state": {"value": int(status.program_state),
                          "name": program_state_text(int(status.program_state))},
        "alarms": {"value": int(status.alarms), "names": alarm_names(int(status.alarms))},
        "command_status": {"code": code, "text": decoded.text},
        "clock": None if clock is None else {
            "iso": clock.value.isoformat() if clock.value is not None else None,
            "raw": list(clock.raw),
            "raw_hex": clock.raw_hex,
        },
    }


def format_status(pose: Pose, status: ControllerStatus) -> str:
    data = status_to_dict(pose, status)
    cart = "  ".join(f"{n} {_num(v)}" for n, v in zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True))
    ext = "  ".join(f"EJ{i} {_num(v)}" for i, v in enumerate(pose.ext, start=1))
    joints = ("  ".join(f"J{i} {_num(v)}" for i, v in enumerate(pose.joints, start=1))
              if pose.joints is not None else "-")
    alarms = ", ".join(data["alarms"]["names"]) or "none"
    lines = [
        f"pose      {cart}",
        f"external  {ext}",
        f"joints    {joints}",
        f"mode      {data['mode']['name']} ({data['mode']['value']})",
        f"program   {data['program_state']['name']} ({data['program_state']['value']})",
        f"alarms    {alarms} ({data['alarms']['value']})",
        f"command   {data['command_status']['code']} {data['command_status']['text']}",
    ]
    clock = data["clock"]
    if clock is not None:
        when = clock["iso"].replace("T", " ") if clock["iso"] else "invalid"
        lines.append(f"clock     {when} (raw {clock['raw_hex']})")
    return "\n".join(lines)


def format_watch_line(elapsed: float, pose: Pose, status: ControllerStatus) -> str:
    cart = " ".join(f"{n}={_num(v)}" for n, v in zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True))
    alarms = ",".join(alarm_names(int(status.alarms))) or "none"
    return (f"t={elapsed:.3f} {cart} mode={controller_mode_text(int(status.mode))} "
            f"program={program_state_text(int(status.program_state))} alarms={alarms} "
            f"cmd={status.command_status_code}")


# --------------------------------------------------------------------------------------------
# Argument helpers
# --------------------------------------------------------------------------------------------


def _axis_index(name: str, joint_frame: bool) -> int:
    key = name.strip().upper()
    names = JOINT_AXIS_NAMES if joint_frame else CARTESIAN_AXIS_NAMES
    if key in names:
        return names.index(key)
    frame = "joint frame" if joint_frame else "this frame"
    raise InvalidInput(f"axis {name!r} does not exist in the {frame} (use {', '.join(names)})")


def _parse_direction(text: str) -> int:
    key = text.strip().lower()
    if key in ("+", "pos", "positive", "1"):
        return 1
    if key in ("-", "neg", "negative", "0"):
        return 0
    raise InvalidInput(f"direction must be + or -, got {text!r}")


def _parse_step_offsets(frame: StepFrame, items: Sequence[str]) -> tuple[list[float], list[float]]:
    offsets = [0.0] * registers.NUM_ROBOT_AXES
    ext = [0.0] * registers.NUM_EXTERNAL_AXES
    main_names = JOINT_AXIS_NAMES[:6] if frame is StepFrame.JOINT else CARTESIAN_AXIS_NAMES
    ext_names = JOINT_AXIS_NAMES[6:]
    if not items:
        raise InvalidInput(f"step needs offsets like {main_names[0]}=10")
    for item in items:
        name, sep, value_text = item.partition("=")
        if not sep:
            raise InvalidInput(f"offset {item!r} is not AXIS=VALUE")
        key = name.strip().upper()
        try:
            value = float(value_text)
        except ValueError:
            raise InvalidInput(f"offset {item!r}: {value_text!r} is not a number") from None
        if key in main_names:
            offsets[main_names.index(key)] = value
        elif key in ext_names:
            ext[ext_names.index(key)] = value
        else:
            allowed = ", ".join((*main_names, *ext_names))
            raise InvalidInput(f"axis {name!r} is not valid for a {frame.value} step (use {allowed})")
    return offsets, ext


def _parse_zero_axis(text: str) -> int | None:
    key = text.strip().upper()
    if key == "ALL":
        return None
    if key in JOINT_AXIS_NAMES:
        return JOINT_AXIS_NAMES.index(key)
    if key.isdigit() and 1 <= int(key) <= registers.NUM_AXES_TOTAL:
        return int(key) - 1
    raise InvalidInput(f"zero: axis must be J1..J11, 1..11 or all, got {text!r}")


def _word_order(text: str) -> WordOrder:
    try:
        return WordOrder.parse(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _jog_seconds(text: str) -> float:
    value = _positive_float(text)
    if value > JOG_SECONDS_MAX:
        raise argparse.ArgumentTypeError(f"a jog runs at most {JOG_SECONDS_MAX:g} s, got {text[:20]}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


# --------------------------------------------------------------------------------------------
# Handlers
# --------------------------------------------------------------------------------------------


def _report(ctx: CliContext, message: str) -> int:
    ctx.print(message)
    return EXIT_OK


def _wait_motion(ctx: CliContext, start: Callable[[], Any]) -> Any:
    """Run a blocking motion; on Ctrl-C send stop before giving up."""
    try:
        return start()
    except KeyboardInterrupt:
        client = ctx.client
        tracker = client.last_tracker
        if tracker is not None and not tracker.finished and not ctx.settings.monitor_only:
            client.close()  # a request may have been cut in half: stop on a fresh link
            with _sigint_deferred():
                try:
                    client.stop()
                    ctx.warn("interrupted: stop sent")
                except TeachPadError as exc:
                    ctx.warn(f"interrupted, and stop failed: {exc}")
        raise


@contextlib.contextmanager
def _sigint_deferred() -> Iterator[None]:
    """Ignore Ctrl-C while cleaning up (each request is bounded by the link timeout)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def cmd_status(ctx: CliContext) -> int:
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
    return EXIT_OK


def cmd_watch(ctx: CliContext) -> int:
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
        return EXIT_OK  # Ctrl-C is how a watch normally ends
    return EXIT_OK


def cmd_mode(ctx: CliContext) -> int:
    mode = WorkMode.AUTO if ctx.args.mode == "auto" else WorkMode.MANUAL
    ctx.client.set_work_mode(mode)
    return _report(ctx, f"work mode set to {ctx.args.mode}")


def cmd_step(ctx: CliContext) -> int:
    frame = StepFrame(ctx.args.frame)
    offsets, ext = _parse_step_offsets(frame, ctx.args.offsets)
    client = ctx.client
    result = _wait_motion(ctx, lambda: client.step(frame, offsets, ext, speed=ctx.args.speed,
                                                   wait=not ctx.args.no_wait))
    ctx.print(result.message)
    if not ctx.args.no_wait:
        ctx.print(_pose_line(client.read_pose()))
    return EXIT_OK


def _pose_line(pose: Pose) -> str:
    pairs = zip(CARTESIAN_AXIS_NAMES, pose.xyzabc, strict=True)
    return "pose " + " ".join(f"{n}={_num(v)}" for n, v in pairs)


def cmd_jog(ctx: CliContext) -> int:
    args = ctx.args
    frame = TeachFrame[args.frame.upper()]
    axis = _axis_index(args.axis, frame is TeachFrame.JOINT)
    direction = _parse_direction(args.dir)
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
            with _sigint_deferred():
                _jog_cleanup(ctx, client)
    ctx.print(_pose_line(client.read_pose()))
    return EXIT_OK


def _jog_cleanup(ctx: CliContext, client: RobotClient) -> None:
    try:
        client.teach_set_ratio(0.0)
    except TeachPadError as exc:
        ctx.warn(f"could not set the jog ratio to 0: {exc}")
    try:
        client.teach_disable()
    except TeachPadError as exc:
        ctx.warn(f"could not disable teach mode: {exc}")


def cmd_point_create(ctx: CliContext) -> int:
    args = ctx.args
    client = ctx.client
    pose = args.xyzabc  # None: from the current pose
    result = client.create_point(args.id, pose=pose, gv_start=args.gv_start, tool=args.tool)
    ctx.print(f"point {args.id}: {result.message}")
    if pose is None:
        # The controller forgets temp points on restart: show the pose the host should keep.
        ctx.print(_pose_line(client.read_pose()))
    return EXIT_OK


def cmd_move(ctx: CliContext) -> int:
    args = ctx.args
    client = ctx.client
    result = _wait_motion(ctx, lambda: client.move_to_point(
        args.id, via_id=args.via, orientation_changes=not args.keep_orientation,
        ignore_middle=args.ignore_middle, speed=args.speed, tool=args.tool, wait=not args.no_wait,
        timeout=args.wait_timeout))
    ctx.print(result.message)
    if not args.no_wait:
        ctx.print(_pose_line(client.read_pose()))
    return EXIT_OK


def cmd_zero(ctx: CliContext) -> int:
    axis = _parse_zero_axis(ctx.args.axis)
    ctx.client.go_zero(axis)
    target = "all axes" if axis is None else JOINT_AXIS_NAMES[axis]
    return _report(ctx, f"go to zero sent ({target})")


_PROGRAM_MODES = {"step": ProgramMotionMode.SINGLE_STEP, "single": ProgramMotionMode.SINGLE_RUN,
                  "cycle": ProgramMotionMode.CYCLE}


def cmd_program_run(ctx: CliContext) -> int:
    args = ctx.args
    ctx.client.run_program(args.id, _PROGRAM_MODES[args.mode], cycles=args.cycles, speed_ratio=args.speed)
    return _report(ctx, f"program {args.id} started ({args.mode})")


def cmd_stop(ctx: CliContext) -> int:
    ctx.client.stop()
    return _report(ctx, "stop sent")


def cmd_pause(ctx: CliContext) -> int:
    ctx.client.pause()
    return _report(ctx, "pause sent")


def cmd_resume(ctx: CliContext) -> int:
    ctx.client.resume()
    return _report(ctx, "resume sent")


def cmd_read(ctx: CliContext) -> int:
    gv, count = ctx.args.gv, ctx.args.count
    if gv < 0:
        raise InvalidInput(f"read: GV must be >= 0, got {gv}")
    if not 1 <= count <= 62:
        raise InvalidInput(f"read: COUNT must be 1..62 (one request), got {count}")
    regs = ctx.client.read_registers(registers.gv_reg(gv), 2 * count)
    for i, value in enumerate(decode_floats(regs, ctx.settings.word_order)):
        raw = " ".join(f"{r:04X}" for r in regs[2 * i : 2 * i + 2])
        ctx.print(f"GV{gv + i} = {value!r}  ({raw})")
    return EXIT_OK


def cmd_write(ctx: CliContext) -> int:
    gv, values = ctx.args.gv, ctx.args.values
    ctx.client.write_gv(gv, values)
    raw = " ".join(f"{r:04X}" for r in encode_floats(values, ctx.settings.word_order))
    return _report(ctx, f"GV{gv}..GV{gv + len(values) - 1} written ({raw})")


# --------------------------------------------------------------------------------------------
# Parser
# --------------------------------------------------------------------------------------------


def register_core(sub: Any) -> None:
    """The built-in subcommands."""
    p = sub.add_parser("status", help="pose, joints, mode, program state, alarms, command status, clock")
    p.add_argument("--json", action="store_true", help="one JSON object")
    p.set_defaults(handler=cmd_status)

    p = sub.add_parser("watch", help="stream one status line per sample")
    p.add_argument("--rate", type=_positive_float, default=WATCH_RATE_DEFAULT, metavar="HZ")
    p.add_argument("--count", type=int, default=0, metavar="N", help="stop after N lines (0: until Ctrl-C)")
    p.set_defaults(handler=cmd_watch)

    p = sub.add_parser("mode", help="set the work mode")
    p.add_argument("mode", choices=("auto", "manual"))
    p.set_defaults(handler=cmd_mode)

    p = sub.add_parser("step", help="incremental move (function 1), e.g. step --frame base X=10 Z=-5")
    p.add_argument("--frame", choices=("joint", "base"), required=True)
    p.add_argument("offsets", nargs="+", metavar="AXIS=VALUE",
                   help="J1..J11 (joint) or X Y Z A B C (+ J7..J11) (base)")
    p.add_argument("--speed", type=_positive_float, default=10.0, help="rpm (joint) or mm/s (base)")
    p.add_argument("--no-wait", action="store_true", help="return once the command is sent")
    p.set_defaults(handler=cmd_step)

    p = sub.add_parser(
        "jog", help="teach-mode jog for a bounded time (function 4); always stops and disables",
        description="Jog one axis in teach mode, then write ratio 0 and disable teach mode. The jog is "
                    f"bounded: it stops after --seconds (default {JOG_SECONDS_DEFAULT:g} s, at most "
                    f"{JOG_SECONDS_MAX:g} s), on Ctrl-C and on any error. Example: "
                    "teachpad-cli --host 192.168.1.10 jog --axis Z --dir + --ratio 10 --seconds 1.5")
    p.add_argument("--frame", choices=("base", "user", "tool", "joint"), default="base")
    p.add_argument("--user", type=int, default=0, metavar="N", help="user frame id (frame user)")
    p.add_argument("--tool", type=int, default=0, metavar="N", help="tool frame id (frame tool)")
    p.add_argument("--axis", required=True, help="X Y Z A B C, or J1..J11 in the joint frame")
    p.add_argument("--dir", required=True, help="+ or -")
    p.add_argument("--ratio", type=float, required=True, help="speed ratio in percent, 0 < N <= 100")
    p.add_argument("--seconds", "--for", dest="duration", type=_jog_seconds, default=JOG_SECONDS_DEFAULT,
                   metavar="S", help=f"how long to jog, in seconds: 0 < S <= {JOG_SECONDS_MAX:g} "
                                     f"(default {JOG_SECONDS_DEFAULT:g}); --for is the same")
    p.set_defaults(handler=cmd_jog)

    p = sub.add_parser("point", help="temp points (function 2)")
    psub = p.add_subparsers(dest="point_command", metavar="ACTION", required=True)
    pc = psub.add_parser("create", help="create or overwrite a temp point")
    pc.add_argument("id", type=int)
    src = pc.add_mutually_exclusive_group()
    src.add_argument("--from-pose", action="store_true", help="from the current pose (default)")
    src.add_argument("--xyzabc", type=float, nargs=6, metavar=("X", "Y", "Z", "A", "B", "C"))
    pc.add_argument("--tool", type=int, default=registers.TOOL_NONE, metavar="N",
                    help="GV245: 200 none (default), N = tool N+1")
    pc.add_argument("--gv-start", type=int, default=0, metavar="N", help="first of the six pose GVs")
    pc.set_defaults(handler=cmd_point_create)

    p = sub.add_parser("move", help="move to a temp point: line, or arc with --via (function 3)")
    p.add_argument("id", type=int)
    p.add_argument("--via", type=int, metavar="MID", help="middle point of an arc")
    p.add_argument("--speed", type=_positive_float, default=50.0)
    p.add_argument("--keep-orientation", action="store_true")
    p.add_argument("--ignore-middle", action="store_true")
    p.add_argument("--tool", type=int, default=registers.TOOL_NONE, metavar="N")
    p.add_argument("--no-wait", action="store_true")
    p.add_argument("--wait-timeout", type=_positive_float, default=None, metavar="SECONDS")
    p.set_defaults(handler=cmd_move)

    p = sub.add_parser("zero", help="go to zero: one axis (J1..J11) or all")
    p.add_argument("axis", metavar="AXIS|all")
    p.set_defaults(handler=cmd_zero)

    p = sub.add_parser("program", help="controller programs")
    psub = p.add_subparsers(dest="program_command", metavar="ACTION", required=True)
    pr = psub.add_parser("run", help="run a program")
    pr.add_argument("id", type=int)
    pr.add_argument("--mode", choices=tuple(_PROGRAM_MODES), default="single")
    pr.add_argument("--cycles", type=int, default=1, help="cycle count (0: endless)")
    pr.add_argument("--speed", type=int, default=100, help="speed ratio 1..100")
    pr.set_defaults(handler=cmd_program_run)

    for name, handler, text in (("stop", cmd_stop, "stop the motion or program"),
                                ("pause", cmd_pause, "pause"), ("resume", cmd_resume, "resume")):
        p = sub.add_parser(name, help=text)
        p.set_defaults(handler=handler)

    p = sub.add_parser("read", help="read GVs (float32)")
    p.add_argument("gv", type=int, metavar="GV")
    p.add_argument("count", type=int, nargs="?", default=1, metavar="COUNT")
    p.set_defaults(handler=cmd_read)

    p = sub.add_parser("write", help="write GVs (float32, one 0x10)")
    p.add_argument("gv", type=int, metavar="GV")
    p.add_argument("values", type=float, nargs="+", metavar="VALUE")
    p.set_defaults(handler=cmd_write)


# Registrars run in order; other modules may append theirs.
REGISTRARS: list[Registrar] = [register_core]
# Optional modules with a ``register(subparsers)`` function, used when they exist.
PLUGIN_MODULES: tuple[str, ...] = ("app.cli.points", "app.cli_run", "app.cli.support")


def _plugin_registrars() -> Iterator[Registrar]:
    for name in PLUGIN_MODULES:
        try:
            module = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name == name:
                continue
            raise
        yield module.register


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Talk to a Bochuang robot controller over Modbus. An administrator's tool: "
                    "TeachPad's operator roles apply to the GUI, not here.",
        epilog="exit codes: 0 ok, 1 command failed/refused, 2 usage, 3 link/timeout/malformed answer, "
               "130 interrupted",
    )
    link = parser.add_argument_group("link")
    link.add_argument("--host", default="127.0.0.1")
    link.add_argument("--port", type=int, default=502)
    link.add_argument("--unit", type=int, default=1, help="Modbus unit (slave) id")
    link.add_argument("--rtu", metavar="PORT", help="Modbus RTU on this serial port instead of TCP")
    link.add_argument("--baud", type=int, default=115200)
    link.add_argument("--parity", choices=("N", "E", "O"), default="N")
    link.add_argument("--framer", choices=("socket", "rtu"), default="socket",
                      help="frame format over TCP (rtu: RTU frames over a TCP socket)")
    link.add_argument("--word-order", type=_word_order, default=WordOrder.LOW_FIRST,
                      metavar="low-first|high-first")
    link.add_argument("--timeout", type=_positive_float, default=1.0, metavar="SECONDS",
                      help="Modbus request timeout of commands and one-off reads")
    link.add_argument("--poll-timeout", type=_positive_float, default=None, metavar="SECONDS",
                      help="timeout of the monitoring reads of status and watch (default: 0.15 "
                           "over TCP, by baud rate over RTU)")
    link.add_argument("--monitor-only", action="store_true", help="refuse every write")
    parser.add_argument("-v", "--verbose", action="store_true", help="log every write and the link")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for registrar in (*REGISTRARS, *_plugin_registrars()):
        registrar(sub)
    return parser


def settings_from_args(args: argparse.Namespace) -> ConnectionSettings:
    return ConnectionSettings(
        host=args.host, port=args.port, unit=args.unit, serial_port=args.rtu, baudrate=args.baud,
        parity=args.parity, framer=args.framer, word_order=args.word_order, timeout=args.timeout,
        poll_timeout=args.poll_timeout, monitor_only=args.monitor_only,
    )


def _configure_logging(verbose: bool) -> None:
    if verbose:
        logging.basicConfig(level=logging.DEBUG, format=f"{PROG}: %(name)s: %(message)s")
    else:
        # Our own one-line errors say what pymodbus would log, in words an operator reads.
        logging.getLogger("pymodbus").setLevel(logging.CRITICAL)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, or a usage error already printed by argparse
        return exc.code if isinstance(exc.code, int) else EXIT_USAGE
    _configure_logging(args.verbose)
    ctx = CliContext(args, settings_from_args(args))
    handler: Handler = args.handler

    def fail(code: int, message: str) -> int:
        print(f"{PROG}: error: {message}", file=sys.stderr, flush=True)
        return code

    try:
        return handler(ctx)
    except InvalidInput as exc:
        return fail(EXIT_USAGE, str(exc))
    except (LinkError, ResponseTimeout, MalformedResponse) as exc:
        return fail(EXIT_LINK, str(exc))
    except TeachPadError as exc:
        return fail(EXIT_FAILED, str(exc))
    except KeyboardInterrupt:
        return fail(EXIT_INTERRUPTED, "interrupted")
    finally:
        ctx.close()


if __name__ == "__main__":
    sys.exit(main())

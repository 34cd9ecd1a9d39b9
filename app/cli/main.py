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
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any, TextIO

from app.cli.format import (
    JOG_SECONDS_MAX,
    _axis_index,
    _jog_seconds,
    _num,
    _parse_direction,
    _parse_step_offsets,
    _parse_zero_axis,
    _positive_float,
    _word_order,
    format_status,
    format_watch_line,
    status_to_dict,
)
from app.cli.help import add_examples
from app.errors import (
    AlarmRaised,
    CommandRefused,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ResponseTimeout,
    TeachPadError,
)
from app.link.client import ConnectionSettings, RobotClient, StepFrame
from app.link.tracker import pose_moved
from app.models import Pose
from app.protocol import registers
from app.protocol.codec import WordOrder, decode_floats, encode_floats
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
from app.safety.audit import AuditLog

PROG = "teachpad-cli"

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
EXIT_LINK = 3
EXIT_INTERRUPTED = 130

JOG_POLL_INTERVAL = 0.05  # s between status checks while a jog runs (keeps a watchdog fed)
JOG_SECONDS_DEFAULT = 2.0  # s a jog runs when --seconds is not given
WATCH_RATE_DEFAULT = 10.0  # Hz
# A program the controller accepted shows program state running (or has moved the arm) within
# this time; one that stays stopped was not started (unknown id, or refused).
PROGRAM_START_TIMEOUT = 1.0  # s
PROGRAM_START_POLL = 0.02  # s between status reads while waiting for the start

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
    client = ctx.client
    before = client.read_pose()
    client.run_program(args.id, _PROGRAM_MODES[args.mode], cycles=args.cycles, speed_ratio=args.speed)
    # The controller answers a run command only through its state: wait to see the program run.
    deadline = time.monotonic() + PROGRAM_START_TIMEOUT
    while True:
        status = client.read_status()
        if status.alarms:
            names = ", ".join(alarm_names(int(status.alarms)))
            raise AlarmRaised(int(status.alarms), f"program {args.id} not started: alarm {names}")
        if status.program_state in (ProgramState.RUNNING, ProgramState.PAUSED):
            return _report(ctx, f"program {args.id} running ({args.mode})")
        if pose_moved(client.read_pose(), before):
            return _report(ctx, f"program {args.id} ran and ended ({args.mode})")
        if time.monotonic() >= deadline:
            raise CommandRefused(
                CommandStatus(None, status.command_status_code),
                f"the controller did not start program {args.id}: its program state stayed stopped for "
                f"{PROGRAM_START_TIMEOUT:g} s (no such program, or the controller refused it)",
                code="program_not_started", params={"program": args.id})
        time.sleep(PROGRAM_START_POLL)


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
    p.add_argument("--rate", type=_positive_float, default=WATCH_RATE_DEFAULT, metavar="HZ",
                   help="samples per second, Hz (default %(default)g)")
    p.add_argument("--count", type=int, default=0, metavar="N", help="stop after N lines (0: until Ctrl-C)")
    p.set_defaults(handler=cmd_watch)

    p = sub.add_parser("mode", help="set the work mode")
    p.add_argument("mode", choices=("auto", "manual"), help="auto or manual (register 444)")
    p.set_defaults(handler=cmd_mode)

    p = sub.add_parser("step", help="incremental move (function 1), e.g. step --frame base X=10 Z=-5")
    p.add_argument("--frame", choices=("joint", "base"), required=True,
                   help="joint: offsets in degrees per joint; base: X Y Z in mm, A B C in degrees")
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
    p.add_argument("--frame", choices=("base", "user", "tool", "joint"), default="base",
                   help="the frame the axis belongs to (default %(default)s)")
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
    pc.add_argument("id", type=int, help="temp point id, 1..10000")
    src = pc.add_mutually_exclusive_group()
    src.add_argument("--from-pose", action="store_true", help="from the current pose (default)")
    src.add_argument("--xyzabc", type=float, nargs=6, metavar=("X", "Y", "Z", "A", "B", "C"),
                     help="the pose: X Y Z in mm, A B C in degrees (base frame)")
    pc.add_argument("--tool", type=int, default=registers.TOOL_NONE, metavar="N",
                    help="GV245: 200 none (default), N = tool N+1")
    pc.add_argument("--gv-start", type=int, default=0, metavar="N", help="first of the six pose GVs")
    pc.set_defaults(handler=cmd_point_create)

    p = sub.add_parser("move", help="move to a temp point: line, or arc with --via (function 3)")
    p.add_argument("id", type=int, help="temp point id of the end point, 1..10000")
    p.add_argument("--via", type=int, metavar="MID", help="temp point id of an arc's middle point")
    p.add_argument("--speed", type=_positive_float, default=50.0, help="mm/s (default %(default)g)")
    p.add_argument("--keep-orientation", action="store_true",
                   help="keep the tool's orientation (A B C) along an arc")
    p.add_argument("--ignore-middle", action="store_true",
                   help="arc: use the middle point's position only, not its orientation")
    p.add_argument("--tool", type=int, default=registers.TOOL_NONE, metavar="N",
                   help=f"tool frame id ({registers.TOOL_NONE}: none, the default)")
    p.add_argument("--no-wait", action="store_true", help="return once the command is sent")
    p.add_argument("--wait-timeout", type=_positive_float, default=None, metavar="SECONDS",
                   help="give up waiting after this many seconds (default: by distance and speed)")
    p.set_defaults(handler=cmd_move)

    p = sub.add_parser("zero", help="go to zero: one axis (J1..J11) or all")
    p.add_argument("axis", metavar="AXIS|all", help="J1..J11, or all")
    p.set_defaults(handler=cmd_zero)

    p = sub.add_parser("program", help="controller programs")
    psub = p.add_subparsers(dest="program_command", metavar="ACTION", required=True)
    pr = psub.add_parser("run", help="run a program")
    pr.add_argument("id", type=int, help="program id on the controller (register 446)")
    pr.add_argument("--mode", choices=tuple(_PROGRAM_MODES), default="single",
                    help="step: one segment; single: one run; cycle: --cycles runs (default %(default)s)")
    pr.add_argument("--cycles", type=int, default=1, help="cycle count (0: endless)")
    pr.add_argument("--speed", type=int, default=100,
                    help="speed ratio in percent, 1..100 (default %(default)s)")
    pr.set_defaults(handler=cmd_program_run)

    for name, handler, text in (("stop", cmd_stop, "stop the motion or program"),
                                ("pause", cmd_pause, "pause"), ("resume", cmd_resume, "resume")):
        p = sub.add_parser(name, help=text)
        p.set_defaults(handler=handler)

    p = sub.add_parser("read", help="read GVs (float32)")
    p.add_argument("gv", type=int, metavar="GV", help="first GV number, 0..299 (e.g. 291)")
    p.add_argument("count", type=int, nargs="?", default=1, metavar="COUNT",
                   help="how many GVs (default 1)")
    p.set_defaults(handler=cmd_read)

    p = sub.add_parser("write", help="write GVs (float32, one 0x10)")
    p.add_argument("gv", type=int, metavar="GV", help="first GV number, 0..299")
    p.add_argument("values", type=float, nargs="+", metavar="VALUE",
                   help="float32 values, written to GV, GV+1, ... (units as the GV's meaning)")
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
    link.add_argument("--host", default="127.0.0.1",
                      help="controller's IP address or host name (default %(default)s)")
    link.add_argument("--port", type=int, default=502, help="Modbus TCP port (default %(default)s)")
    link.add_argument("--unit", type=int, default=1, help="Modbus unit (slave) id")
    link.add_argument("--rtu", metavar="PORT", help="Modbus RTU on this serial port instead of TCP")
    link.add_argument("--baud", type=int, default=115200, help="RTU baud rate, bit/s (default %(default)s)")
    link.add_argument("--parity", choices=("N", "E", "O"), default="N",
                      help="RTU parity: none, even, odd (default %(default)s)")
    link.add_argument("--framer", choices=("socket", "rtu"), default="socket",
                      help="frame format over TCP (rtu: RTU frames over a TCP socket)")
    link.add_argument("--word-order", type=_word_order, default=WordOrder.LOW_FIRST,
                      metavar="low-first|high-first",
                      help="float32 word order of the controller (default low-first)")
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
    add_examples(parser)
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


def _quiet_broken_pipe() -> None:
    """The reader of our output went away (``status | head -1``): say nothing more.

    Later writes and the interpreter's final flush go to /dev/null, so no BrokenPipeError
    traceback reaches the terminal. The exit code is 0: the reader had what it wanted (a script
    with ``set -o pipefail`` does not fail because ``head`` stopped reading).
    """
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def main(argv: Sequence[str] | None = None) -> int:
    try:
        code = _main(argv)
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_broken_pipe()
        return EXIT_OK
    return code


def _main(argv: Sequence[str] | None = None) -> int:
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
    except BrokenPipeError:
        _quiet_broken_pipe()
        return EXIT_OK
    finally:
        ctx.close()


if __name__ == "__main__":
    sys.exit(main())

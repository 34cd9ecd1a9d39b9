"""``teachpad-sim``: run the simulated controller in the foreground."""

from __future__ import annotations

import argparse
import logging
import os
import sys
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TextIO

from pymodbus.constants import ExcCodes

from app.protocol.codec import WordOrder
from app.protocol.enums import Alarm
from app.sim.config import GV291_MODES, TIMING_PROFILES, SimConfig
from app.sim.fleet import SimFleet
from app.sim.guard import WATCHDOG_TIMEOUT
from app.sim.server import SimController
from app.stop_signals import SignalNote, stop_signals
from app.version import VersionAction

log = logging.getLogger(__name__)

MAX_CONTROLLERS = 256

ALARM_NAMES: dict[str, Alarm] = {
    "estop": Alarm.ESTOP,
    "servo": Alarm.SERVO,
    "brake": Alarm.BRAKE,
    "algorithm": Alarm.ALGORITHM,
    "encoder": Alarm.ENCODER,
}

COMMANDS_HELP = """\
commands typed on stdin while running (one per line):
  alarm NAME on|off   raise / clear an alarm; NAME: estop servo brake algorithm encoder
  delay SECONDS       delay every answer (0 = off)
  status-delay SECONDS  GV291 keeps its old value this long after a command
  drop                close the connections of the connected clients
  watchdog SECONDS|off  stop a jog whose host went away (see --watchdog)
  exception CODE      answer every request with Modbus exception CODE (1-11)
  exception CODE S    the same for S seconds (e.g. "exception 6 2": busy for 2 s)
  exception off       answer normally again
  silent on|off       receive requests but never answer
  restart             the controller logs in again: temp points wiped, motion stopped
  status              print the state (pose, joints, mode, alarms, GV291, points, bad frames)
  help                this list
  quit                stop the simulator
"""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="teachpad-sim",
        description="Simulated Bochuang robot controller (Modbus TCP slave, or RTU on a serial line "
        "with --serial) for TeachPad.",
        epilog=COMMANDS_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action=VersionAction)
    parser.add_argument("--host", default="127.0.0.1", help="address to bind (default 127.0.0.1)")
    parser.add_argument("--port", type=int, default=5020, help="TCP port (default 5020, 0 = any free port)")
    parser.add_argument("--unit", type=int, default=1, help="Modbus unit id (default 1)")
    parser.add_argument(
        "--word-order",
        choices=[w.value for w in WordOrder],
        default=WordOrder.LOW_FIRST.value,
        help="word order of float32 values (default low-first)",
    )
    parser.add_argument(
        "--status-encoding",
        choices=["float", "int"],
        default="float",
        help="GV291 as float32 (default) or integer in register 582",
    )
    parser.add_argument(
        "--status-delay",
        type=float,
        default=0.0,
        metavar="S",
        help="GV291 keeps its old value S seconds after a command",
    )
    parser.add_argument(
        "--timing",
        choices=list(TIMING_PROFILES),
        default="classic",
        help="GV291 timing: classic (0 held until read), fast (result within one scan), "
        "slow (tens of ms, seeded jitter); default classic",
    )
    parser.add_argument(
        "--gv291",
        choices=list(GV291_MODES),
        default="ignored",
        help="a host's write to GV291: ignored (default), writable (kept until the next "
        "result) or read-only (exception 2)",
    )
    parser.add_argument(
        "--refuse-point",
        type=int,
        action="append",
        default=[],
        metavar="ID",
        help="answer create point ID with status 1, bad point id (repeatable)",
    )
    parser.add_argument("--seed", type=int, default=0, help="seed of the slow profile's jitter (default 0)")
    parser.add_argument("--rtu-framing", action="store_true", help="RTU framing over TCP instead of MBAP")
    parser.add_argument("--tick-hz", type=float, default=100.0, help="simulation rate (default 100)")
    parser.add_argument(
        "--watchdog",
        type=_watchdog,
        default=WATCHDOG_TIMEOUT,
        metavar="SECONDS|off",
        help="stop a teach jog when its connection closes or no request arrives for "
        f"SECONDS (default {WATCHDOG_TIMEOUT:g}; off: keep jogging, like a controller "
        "without a watchdog)",
    )
    serial = parser.add_argument_group("RTU on a serial line (instead of TCP)")
    serial.add_argument("--serial", metavar="PORT", help="serial device to serve, e.g. /dev/ttyUSB0 or COM3")
    serial.add_argument("--baud", type=int, default=115200, help="baud rate (default 115200)")
    serial.add_argument("--parity", choices=["N", "E", "O"], default="N", help="parity (default N)")
    serial.add_argument("--stopbits", type=int, choices=[1, 2], default=1, help="stop bits (default 1)")
    parser.add_argument(
        "--controllers",
        type=_controllers,
        default=None,
        metavar="N",
        help="serve N controllers from this process, each on its own port (--port 0: free ports, "
        "otherwise PORT, PORT+1, ...), with its own arm and its own built-in program running; "
        "one line per controller is printed; stdin commands apply to every one; TCP only",
    )
    parser.add_argument(
        "--idle", action="store_true", help="with --controllers: no program runs (the arms stand still)"
    )
    parser.add_argument(
        "--replay",
        metavar="CAPTURE",
        help="answer every request with what the captured controller answered: CAPTURE is the traffic "
        "inspector's export (.csv or .txt) or a support bundle (.zip); matched by function, address "
        "and order; what cannot be matched is logged and answered with Modbus exception 4 (TCP only; "
        "stdin: status, quit)",
    )
    parser.add_argument("--no-stdin", action="store_true", help="do not read commands from stdin")
    parser.add_argument(
        "--stop-with-stdin",
        action="store_true",
        help="stop when stdin reaches its end (a parent's pipe closed: it went away); "
        "with --no-stdin, for `teachpad --sim`",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="debug logging")
    return parser


def _watchdog(text: str) -> float | None:
    if text.strip().lower() in ("off", "0", "none"):
        return None
    try:
        seconds = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds or 'off', got {text[:20]!r}") from None
    if not 0 < seconds <= 60:
        raise argparse.ArgumentTypeError(f"watchdog must be in (0, 60] s or 'off', got {text[:20]!r}")
    return seconds


def _controllers(text: str) -> int:
    try:
        count = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of controllers, got {text[:20]!r}") from None
    if not 1 <= count <= MAX_CONTROLLERS:
        raise argparse.ArgumentTypeError(f"--controllers must be 1..{MAX_CONTROLLERS}, got {count}")
    return count


def _print_status(sim: SimController, _args: list[str], out: TextIO) -> None:
    s = sim.state()
    print(f"pose {' '.join(f'{v:.3f}' for v in s.pose)}", file=out)
    print(f"joints {' '.join(f'{v:.3f}' for v in s.joints)}", file=out)
    print(
        f"mode {s.mode.name} program {s.program_state.name} alarms {int(s.alarms)} "
        f"teach {'on' if s.teach_enabled else 'off'} ratio {s.teach_ratio:g} "
        f"GV291 {s.command_status} points {len(s.points)}",
        file=out,
    )
    bad = sim.bad_frame_counts()
    print(
        f"bad frames {sum(bad.values())}"
        + "".join(f", {n} {reason}" for reason, n in sorted(bad.items()))
        + f"; watchdog stops {len(sim.watchdog_events())}",
        file=out,
    )


def _set_watchdog(sim: SimController, args: list[str], _out: TextIO) -> None:
    try:
        sim.set_watchdog(_watchdog(args[0]))
    except argparse.ArgumentTypeError as exc:
        raise ValueError(str(exc)) from None


def _set_exception(sim: SimController, args: list[str], _out: TextIO) -> None:
    """``exception CODE|off`` or ``exception CODE SECONDS``."""
    if len(args) == 1:
        sim.set_exception(None if args[0] == "off" else ExcCodes(int(args[0], 0)))
    else:
        sim.set_exception(ExcCodes(int(args[0], 0)), seconds=float(args[1]))


@dataclass(frozen=True)
class _Command:
    """A stdin command: whether its words fit it, and what it does (ValueError: a bad value)."""

    fits: Callable[[list[str]], bool]
    run: Callable[[SimController, list[str], TextIO], object]


def _no_words(args: list[str]) -> bool:
    return not args


def _one_word(args: list[str]) -> bool:
    return len(args) == 1


def _on_off(word: str) -> bool:
    return word in ("on", "off")


#: The stdin commands by name (``quit`` / ``exit`` end the loop, see :func:`execute`).
_COMMANDS: dict[str, _Command] = {
    "alarm": _Command(
        lambda a: len(a) == 2 and a[0] in ALARM_NAMES and _on_off(a[1]),
        lambda sim, a, _out: sim.set_alarm(ALARM_NAMES[a[0]], a[1] == "on"),
    ),
    "delay": _Command(_one_word, lambda sim, a, _out: sim.set_response_delay(float(a[0]))),
    "status-delay": _Command(_one_word, lambda sim, a, _out: sim.set_status_delay(float(a[0]))),
    "drop": _Command(_no_words, lambda sim, _a, _out: sim.drop_connections()),
    "watchdog": _Command(_one_word, _set_watchdog),
    "exception": _Command(lambda a: len(a) == 1 or (len(a) == 2 and a[0] != "off"), _set_exception),
    "silent": _Command(
        lambda a: len(a) == 1 and _on_off(a[0]), lambda sim, a, _out: sim.set_silent(a[0] == "on")
    ),
    "restart": _Command(_no_words, lambda sim, _a, _out: sim.restart_controller()),
    "status": _Command(_no_words, _print_status),
    "help": _Command(lambda _a: True, lambda _sim, _a, out: print(COMMANDS_HELP, file=out)),
}


def execute(sim: SimController, line: str, out: TextIO) -> bool:
    """Run one stdin command. Returns False when the simulator should quit."""
    words = line.split()
    if not words:
        return True
    cmd, args = words[0].lower(), [w.lower() for w in words[1:]]
    if cmd in ("quit", "exit"):
        return False
    command = _COMMANDS.get(cmd)
    try:
        if command is not None and command.fits(args):
            command.run(sim, args, out)
        else:
            print(f"unknown command: {line.strip()!r} (type help)", file=out)
    except ValueError as exc:
        print(f"bad command {line.strip()!r}: {exc}", file=out)
    out.flush()
    return True


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.controllers is not None and args.serial:
        parser.error("--controllers serves TCP ports; it cannot be used with --serial")
    if args.replay is not None:
        return _replay(parser, args)
    _configure_logging(args.verbose)
    config = _sim_config(args)
    fleet = _started_fleet(args, config)
    if fleet is None:
        return 1
    done = threading.Event()
    stop = _stop_on_signals()
    # Announced only now: whoever waits for this line may stop us at once (SIGTERM), and before
    # the handler exists that would kill the process instead of stopping it cleanly.
    for sim in fleet:
        _say(f"teachpad-sim listening on {sim.endpoint} (unit {config.unit}); Ctrl-C to stop")

    if args.stop_with_stdin:
        watch = threading.Thread(target=_wait_for_end_of_stdin, args=(done,), daemon=True)
        watch.start()
    if not args.no_stdin:
        threading.Thread(target=_read_commands, args=(fleet, done), name="sim-stdin", daemon=True).start()
    try:
        while not stop.wait(0.2, done):
            pass
    except KeyboardInterrupt:
        pass
    finally:
        fleet.stop()
        stop.restore()
    if stop.signum is not None:
        log.info("signal %d: stopped", stop.signum)
    _say("teachpad-sim stopped")
    return 0


def _replay(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    """``--replay CAPTURE``: a traffic capture answers instead of the simulated robot."""
    if args.serial or args.controllers is not None:
        parser.error("--replay serves one TCP port; it cannot be used with --serial or --controllers")
    _configure_logging(args.verbose)
    from app.sim.replay_cli import run_replay

    return run_replay(args, _stop_on_signals, _say, _wait_for_end_of_stdin)


def _started_fleet(args: argparse.Namespace, config: SimConfig) -> SimFleet | None:
    """The simulator(s) of the command line, started; None (said on stderr) when one cannot bind."""
    fleet = SimFleet(args.controllers or 1, config, programs=args.controllers is not None and not args.idle)
    for sim in fleet:
        for point_id in args.refuse_point:
            sim.refuse_point(point_id)
    try:
        fleet.start()
    except OSError as exc:
        print(f"teachpad-sim: {exc}", file=sys.stderr)
        return None
    return fleet


def _configure_logging(verbose: bool) -> None:
    logging.basicConfig(
        level=logging.DEBUG if verbose else logging.INFO,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    if not verbose:
        logging.getLogger("pymodbus").setLevel(logging.WARNING)


def _sim_config(args: argparse.Namespace) -> SimConfig:
    """The simulator's configuration from the command line's options."""
    return SimConfig(
        host=args.host,
        port=args.port,
        unit=args.unit,
        word_order=WordOrder.parse(args.word_order),
        status_encoding=args.status_encoding,
        status_delay=args.status_delay,
        framer="rtu" if args.rtu_framing else "socket",
        tick_hz=args.tick_hz,
        watchdog=args.watchdog,
        serial_port=args.serial,
        baudrate=args.baud,
        parity=args.parity,
        stopbits=args.stopbits,
        timing=args.timing,
        gv291=args.gv291,
        seed=args.seed,
    )


def _read_commands(fleet: SimFleet, done: threading.Event) -> None:
    """The stdin commands, one a line, until ``quit`` or the end of stdin; then ``done``. With
    several controllers each command goes to every one."""
    try:
        for line in sys.stdin:
            several = len(fleet) > 1 and line.split()[:1] == ["status"]
            going = True
            for sim in fleet:
                if several:
                    print(f"-- {sim.endpoint}", flush=True)
                going = execute(sim, line, sys.stdout) and going
            if not going:
                break
    except BrokenPipeError:  # nobody reads our answers any more: stop, quietly
        pass
    done.set()


def _stop_on_signals() -> SignalNote:
    """Ctrl-C and SIGTERM noted for the main loop (app/stop_signals.py: the handler takes no lock);
    installed from the main thread only (elsewhere Python cannot install a handler)."""
    return SignalNote(stop_signals()).install()


def _wait_for_end_of_stdin(done: threading.Event) -> None:
    """``--stop-with-stdin``: the parent (``teachpad --sim``) holds the other end of our stdin;
    when it goes away, however it goes (closed, killed, crashed), the pipe ends and so do we. The
    file descriptor is read, not ``sys.stdin``: a wait inside sys.stdin's buffer holds its lock,
    which the interpreter's exit after a Ctrl-C then cannot take ("Fatal Python error:
    _enter_buffered_busy"). Portable: no signal to ourselves."""
    try:
        while os.read(0, 4096):
            pass
    except OSError:  # stdin closed or not readable: no parent to watch
        pass
    done.set()


def _say(line: str) -> None:
    """One line on stdout, flushed; nobody reading any more is not an error.

    ``teachpad --sim`` reads this process's stdout through a pipe; when the GUI goes away (closed,
    killed, crashed) the pipe's reader is gone, and the simulator stops by itself (its stdin
    closed): the last line then meets a closed pipe. The line is dropped and stdout points to
    the null device from then on, so neither this print nor the interpreter's flush at exit
    raises BrokenPipeError."""
    try:
        print(line, flush=True)
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        try:
            os.dup2(devnull, sys.stdout.fileno())
        finally:
            os.close(devnull)


if __name__ == "__main__":
    raise SystemExit(main())

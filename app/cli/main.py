"""teachpad-cli: script the controller from a shell.

    teachpad-cli [--host H --port P | --rtu DEV --baud B --parity N] [--timeout S]
                 [--register-profile FILE] [--unit U] [--word-order W] [--completion C]
                 [--poll-timeout S] [--monitor-only] [--reduced-speed] COMMAND ...

The connection options say where the controller is; ``--register-profile`` how its registers
read (:mod:`app.safety.register_profile`, as the GUI applies it); ``--unit``, ``--word-order``,
``--completion`` and ``--poll-timeout`` override the profile's field (:func:`settings_from_args`).
``--reduced-speed`` caps every motion the command sends (:func:`caps_from_args`).

Every command, by the module whose ``register`` adds it (:data:`REGISTRARS`, in this order):

* :mod:`app.cli.controller`: ``status``, ``watch``, ``mode``, ``step``, ``jog``,
  ``point create``, ``move``, ``zero``, ``program run``, ``stop``, ``pause``, ``resume``,
  ``read``, ``write``
* :mod:`app.cli.points`: ``points list | upload | export | import``
* :mod:`app.cli.run_plan`: ``run``
* :mod:`app.cli.selftest`: ``selftest`` (the register-map self-test, reads only)
* :mod:`app.cli.support`: ``support-bundle``, ``audit``, ``roles`` (offline)

Adding a command: give its module a ``register(subparsers)`` that adds the parser and sets
``handler=fn`` with ``set_defaults``, ``fn(ctx: CliContext) -> ExitCode`` (see
:mod:`app.cli.context`), and list that ``register`` in :data:`REGISTRARS`. Exit codes:
:mod:`app.cli.exit_codes`, the one table (also at the end of ``--help``). Errors are one line
on stderr.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import os
import sys
import textwrap
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from app.cli import controller, points, run_plan, selftest, support
from app.cli.context import PROG, CliContext, Handler, ctrl_c_remembered
from app.cli.exit_codes import EPILOG, ExitCode, exit_code_for
from app.cli.format import parse_positive_float, parse_word_order
from app.cli.guard import (
    COMMAND_ACTIONS,
    ENVELOPE_FILE,
    PASSWORD_ENV,
    ROLE_ENV,
    ROLES_TEXT,
    CliSafety,
    command_path,
)
from app.cli.help import add_examples
from app.connection import ConnectionSettings
from app.errors import InvalidInput, TeachPadError
from app.link.outcome import UNKNOWN_ADVICE
from app.safety.caps import MotionCaps
from app.safety.envelope import Envelope
from app.safety.register_profile import (
    COMPLETION_MODES,
    PROFILE_NAME,
    UNIT_RANGE,
    load_register_profile,
)
from app.safety.roles import default_config_dir
from app.version import VersionAction

__all__ = [
    "EXIT_FAILED",
    "EXIT_INTERRUPTED",
    "EXIT_LINK",
    "EXIT_OK",
    "EXIT_UNKNOWN",
    "EXIT_USAGE",
    "REGISTRARS",
    "build_parser",
    "main",
]

Registrar = Callable[[Any], None]  # register(subparsers: argparse._SubParsersAction)

#: Every command module's ``register(subparsers)``, in the order of ``--help``.
REGISTRARS: tuple[Registrar, ...] = (
    controller.register,
    points.register,
    run_plan.register,
    selftest.register,
    support.register,
)

# The table's members under the names callers imported before the table existed.
EXIT_OK = ExitCode.OK
EXIT_FAILED = ExitCode.FAILED
EXIT_USAGE = ExitCode.USAGE
EXIT_LINK = ExitCode.LINK
EXIT_INTERRUPTED = ExitCode.INTERRUPTED
EXIT_UNKNOWN = ExitCode.UNKNOWN

_PATH_SHOWN = 100  # characters of a path in an error message

_DESCRIPTION = "Talk to a Bochuang robot controller over Modbus. " + ROLES_TEXT


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG,
        description=textwrap.fill(
            f"{_DESCRIPTION} The GUI's envelope file: {_shown_path(default_config_dir() / ENVELOPE_FILE)}.",
            90,
        ),
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,  # keeps the exit code table's lines
    )
    parser.add_argument("--version", action=VersionAction)
    link = parser.add_argument_group("link")
    link.add_argument(
        "--host", default="127.0.0.1", help="controller's IP address or host name (default %(default)s)"
    )
    link.add_argument("--port", type=int, default=502, help="Modbus TCP port (default %(default)s)")
    link.add_argument("--rtu", metavar="PORT", help="Modbus RTU on this serial port instead of TCP")
    link.add_argument("--baud", type=int, default=115200, help="RTU baud rate, bit/s (default %(default)s)")
    link.add_argument(
        "--parity",
        choices=("N", "E", "O"),
        default="N",
        help="RTU parity: none, even, odd (default %(default)s)",
    )
    link.add_argument(
        "--framer",
        choices=("socket", "rtu"),
        default="socket",
        help="frame format over TCP (rtu: RTU frames over a TCP socket)",
    )
    link.add_argument(
        "--timeout",
        type=parse_positive_float,
        default=1.0,
        metavar="SECONDS",
        help="Modbus request timeout of commands and one-off reads",
    )
    regs = parser.add_argument_group(
        "register profile",
        textwrap.fill(
            "How the controller's registers read. --register-profile applies a register profile file "
            "(.registers.json, as saved by the GUI's Safety > Register profile; the GUI's own is "
            f"{_shown_path(default_config_dir() / PROFILE_NAME)}); the options below override the "
            "profile's field of the same name.",
            90,
        ),
    )
    regs.add_argument(
        "--register-profile",
        type=Path,
        metavar="FILE",
        help="apply this register profile (word order, unit id, completion rule, poll "
        "timeout, date/time layout, point ids)",
    )
    regs.add_argument(
        "--unit",
        type=int,
        default=None,
        help="Modbus unit (slave) id (default: the register profile's, else 1)",
    )
    regs.add_argument(
        "--word-order",
        type=parse_word_order,
        default=None,
        metavar="low-first|high-first",
        help="float32 word order of the controller (default: the profile's, else low-first)",
    )
    regs.add_argument(
        "--completion",
        choices=COMPLETION_MODES,
        default=None,
        help="how a command's completion is told (default: the profile's, else auto)",
    )
    regs.add_argument(
        "--poll-timeout",
        type=parse_positive_float,
        default=None,
        metavar="SECONDS",
        help="timeout of the monitoring reads of status and watch (default: the "
        "profile's, else 0.15 over TCP, by baud rate over RTU)",
    )
    link.add_argument("--monitor-only", action="store_true", help="refuse every write")
    parser.add_argument(
        "--reduced-speed",
        action="store_true",
        help="reduced-speed mode: cap every motion at the envelope's reduced caps (run --safety FILE's, "
        "else the envelope in force, the GUI's; its defaults: 10 %% for jog and program speed "
        "ratios, 250 mm/s for steps, moves and plan segments; joint steps at the rpm that keeps "
        "the arm under that speed at the robot "
        "model's reach); go to zero is refused (it runs at the controller's own speed)",
    )
    parser.add_argument(
        "--role",
        choices=("operator", "engineer", "administrator"),
        default=None,
        help=f"the role a writing command acts as once the administrator has a password (default: "
        f"${ROLE_ENV}, else operator); its password is asked for in a terminal or taken from "
        f"${PASSWORD_ENV}",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log every write and the link")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in REGISTRARS:
        register(sub)
    add_examples(parser)
    return parser


#: Options that override the register profile's field of the same name (when given).
PROFILE_OVERRIDES: tuple[str, ...] = ("unit", "word_order", "completion", "poll_timeout")


def settings_from_args(args: argparse.Namespace) -> ConnectionSettings:
    """Where to connect (the link options), how the registers read (``--register-profile``,
    else the defaults), then each explicit override (``--unit``, ``--word-order``, ...).

    Raises :class:`RegisterProfileError` (a usage error) for a profile that cannot be used."""
    where = ConnectionSettings(
        host=args.host,
        port=args.port,
        serial_port=args.rtu,
        baudrate=args.baud,
        parity=args.parity,
        framer=args.framer,
        timeout=args.timeout,
        monitor_only=args.monitor_only,
    )
    path = getattr(args, "register_profile", None)
    settings = where if path is None else load_register_profile(path).apply(where)
    overrides = {
        name: value for name in PROFILE_OVERRIDES if (value := getattr(args, name, None)) is not None
    }
    if "unit" in overrides and not UNIT_RANGE[0] <= overrides["unit"] <= UNIT_RANGE[1]:
        raise InvalidInput(f"--unit must be {UNIT_RANGE[0]}..{UNIT_RANGE[1]}, got {overrides['unit']}")
    return dataclasses.replace(settings, **overrides)


def caps_from_args(args: argparse.Namespace, envelope: Envelope | None = None) -> MotionCaps | None:
    """Reduced-speed mode's caps (None without ``--reduced-speed``): those of ``envelope`` (the
    one in force: ``--safety`` when the command has one, else the GUI's, app/cli/guard.py); the
    reach of its ``--robot-profile``, else the default robot model's. A file that cannot be used
    raises a :class:`TeachPadError` naming it (a usage error: nothing sent)."""
    if not args.reduced_speed:
        return None
    from app.cli.guard import envelope_in_force
    from app.view3d.profile import default_profile
    from app.view3d.profile import load_profile as load_robot_profile

    if envelope is None:
        envelope = envelope_in_force(getattr(args, "safety", None))
    robot = getattr(args, "robot_profile", None)
    model = default_profile() if robot is None else load_robot_profile(robot)
    return envelope.motion_caps(model.reach)


def _shown_path(path: Path) -> str:
    text = str(path)
    return text if len(text) <= _PATH_SHOWN else "…" + text[-(_PATH_SHOWN - 1) :]


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
        with ctrl_c_remembered():  # a Ctrl-C Python drops (in a finaliser) still ends the command
            code = _main(argv)
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_broken_pipe()
        return ExitCode.OK
    return code


def _main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0), or a usage error already printed by argparse (2)
        return exc.code if isinstance(exc.code, int) else ExitCode.USAGE
    _configure_logging(args.verbose)
    try:
        settings = settings_from_args(args)
    except TeachPadError as exc:  # a register profile that cannot be used, a bad --unit
        print(f"{PROG}: error: {exc}", file=sys.stderr, flush=True)
        return exit_code_for(exc)
    ctx = CliContext(args, settings)
    try:  # the envelope and the role store the GUI uses (a command that writes): nothing sent yet
        if command_path(args) in COMMAND_ACTIONS:
            ctx.safety = CliSafety.load(args, ctx.audit)
        ctx.caps = caps_from_args(args, ctx.safety.envelope if ctx.safety is not None else None)
    except TeachPadError as exc:  # a safety or robot profile that cannot be used: nothing sent
        print(f"{PROG}: error: {exc}", file=sys.stderr, flush=True)
        return ExitCode.USAGE
    handler: Handler = args.handler
    try:
        if ctx.safety is not None:
            ctx.safety.log_in(args)  # the role a writing command acts as, and its permission
        return handler(ctx)
    except BrokenPipeError:
        _quiet_broken_pipe()
        return ExitCode.OK
    except (TeachPadError, OSError, KeyboardInterrupt) as exc:
        code = exit_code_for(exc)
        message = "interrupted" if isinstance(exc, KeyboardInterrupt) else _error_text(exc)
        if code is ExitCode.UNKNOWN and UNKNOWN_ADVICE not in message:
            message = f"{message}: {UNKNOWN_ADVICE}"  # a command that did not finish in time
        print(f"{PROG}: error: {message}", file=sys.stderr, flush=True)
        return code
    finally:
        ctx.close()


def _error_text(exc: BaseException) -> str:
    """One line: a typed error says what happened; a file error names the file (its end, when
    the path is long: the name tells more than the folders above it)."""
    if isinstance(exc, OSError) and not isinstance(exc, TeachPadError):
        path = str(exc.filename or "")
        if len(path) > _PATH_SHOWN:
            path = "…" + path[-(_PATH_SHOWN - 1) :]
        return f"{path}: {exc.strerror or exc}" if path else str(exc.strerror or exc)
    return str(exc)


if __name__ == "__main__":
    sys.exit(main())

"""teachpad-cli: script the controller from a shell.

    teachpad-cli [--host H --port P --unit U | --rtu DEV --baud B --parity N] [--word-order W]
                 [--timeout S] [--monitor-only] COMMAND ...

Every command, by the module whose ``register`` adds it (:data:`REGISTRARS`, in this order):

* :mod:`app.cli.controller`: ``status``, ``watch``, ``mode``, ``step``, ``jog``,
  ``point create``, ``move``, ``zero``, ``program run``, ``stop``, ``pause``, ``resume``,
  ``read``, ``write``
* :mod:`app.cli.points`: ``points list | upload | export | import``
* :mod:`app.cli.run_plan`: ``run``
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
import logging
import os
import sys
import textwrap
from collections.abc import Callable, Sequence
from typing import Any

from app.cli import controller, points, run_plan, support
from app.cli.context import PROG, CliContext, Handler
from app.cli.exit_codes import EPILOG, ExitCode, exit_code_for
from app.cli.format import parse_positive_float, parse_word_order
from app.cli.help import add_examples
from app.errors import TeachPadError
from app.link.client import ConnectionSettings
from app.protocol.codec import WordOrder

__all__ = [
    "EXIT_FAILED",
    "EXIT_INTERRUPTED",
    "EXIT_LINK",
    "EXIT_OK",
    "EXIT_USAGE",
    "PROG",
    "REGISTRARS",
    "CliContext",
    "ExitCode",
    "build_parser",
    "main",
]

Registrar = Callable[[Any], None]  # register(subparsers: argparse._SubParsersAction)

#: Every command module's ``register(subparsers)``, in the order of ``--help``.
REGISTRARS: tuple[Registrar, ...] = (controller.register, points.register, run_plan.register,
                                     support.register)

# The table's members under the names callers imported before the table existed.
EXIT_OK = ExitCode.OK
EXIT_FAILED = ExitCode.FAILED
EXIT_USAGE = ExitCode.USAGE
EXIT_LINK = ExitCode.LINK
EXIT_INTERRUPTED = ExitCode.INTERRUPTED

_PATH_SHOWN = 100  # characters of a path in an error message

_DESCRIPTION = ("Talk to a Bochuang robot controller over Modbus. An administrator's tool: "
                "TeachPad's operator roles apply to the GUI, not here.")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description=textwrap.fill(_DESCRIPTION, 90), epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,  # keeps the exit code table's lines
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
    link.add_argument("--word-order", type=parse_word_order, default=WordOrder.LOW_FIRST,
                      metavar="low-first|high-first",
                      help="float32 word order of the controller (default low-first)")
    link.add_argument("--timeout", type=parse_positive_float, default=1.0, metavar="SECONDS",
                      help="Modbus request timeout of commands and one-off reads")
    link.add_argument("--poll-timeout", type=parse_positive_float, default=None, metavar="SECONDS",
                      help="timeout of the monitoring reads of status and watch (default: 0.15 "
                           "over TCP, by baud rate over RTU)")
    link.add_argument("--monitor-only", action="store_true", help="refuse every write")
    parser.add_argument("-v", "--verbose", action="store_true", help="log every write and the link")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for register in REGISTRARS:
        register(sub)
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
        return ExitCode.OK
    return code


def _main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help (0), or a usage error already printed by argparse (2)
        return exc.code if isinstance(exc.code, int) else ExitCode.USAGE
    _configure_logging(args.verbose)
    ctx = CliContext(args, settings_from_args(args))
    handler: Handler = args.handler
    try:
        return handler(ctx)
    except BrokenPipeError:
        _quiet_broken_pipe()
        return ExitCode.OK
    except (TeachPadError, OSError, KeyboardInterrupt) as exc:
        message = "interrupted" if isinstance(exc, KeyboardInterrupt) else _error_text(exc)
        print(f"{PROG}: error: {message}", file=sys.stderr, flush=True)
        return exit_code_for(exc)
    finally:
        ctx.close()


def _error_text(exc: BaseException) -> str:
    """One line: a typed error says what happened; a file error names the file (its end, when
    the path is long: the name tells more than the folders above it)."""
    if isinstance(exc, OSError) and not isinstance(exc, TeachPadError):
        path = str(exc.filename or "")
        if len(path) > _PATH_SHOWN:
            path = "…" + path[-(_PATH_SHOWN - 1):]
        return f"{path}: {exc.strerror or exc}" if path else str(exc.strerror or exc)
    return str(exc)


if __name__ == "__main__":
    sys.exit(main())

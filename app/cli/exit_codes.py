"""teachpad-cli's exit codes: the one table, and which failure maps to which code.

Every command returns a member of :class:`ExitCode`; an error that escapes a command is mapped
by :func:`exit_code_for` (``app/cli/main.py`` does it once for every command). The same table
is printed at the end of ``teachpad-cli --help`` (:data:`EPILOG`) and in the README's CLI
section.
"""

from __future__ import annotations

import enum

from app.errors import (
    CommandTimeout,
    InvalidInput,
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    ResponseTimeout,
    TeachPadError,
)
from app.protocol.exceptions import GATEWAY_EXCEPTIONS
from app.safety.register_profile import RegisterProfileError

__all__ = ["EPILOG", "LINK_ERRORS", "ExitCode", "exit_code_for"]


class ExitCode(enum.IntEnum):
    """What a ``teachpad-cli`` run ended with (the process's exit status)."""

    OK = 0
    #: the command ran and failed: refused by the controller (its status code in words), busy,
    #: Modbus exception, alarm, stopped, blocked by --monitor-only, a plan the robot model cannot
    #: reach, a file that cannot be written
    FAILED = 1
    #: bad arguments or values, an unreadable or malformed input file, a plan with errors:
    #: nothing was sent
    USAGE = 2
    #: the link: cannot connect, no answer in time, a malformed answer, nothing answers at the
    #: unit id (a gateway's Modbus exception 10 / 11: check the unit id)
    LINK = 3
    #: the controller took the command (its write was answered) but what it did is not known:
    #: its status could not be read, it did not finish within its time, it was never
    #: acknowledged. The robot may have acted on it: check it before sending it again
    UNKNOWN = 4
    #: Ctrl-C (a motion that was under way is stopped first)
    INTERRUPTED = 130

    @property
    def meaning(self) -> str:
        return _MEANING[self]


_MEANING = {
    ExitCode.OK: "ok",
    ExitCode.FAILED: (
        "command failed or refused (controller, busy, alarm, stopped, monitor-only, out of the robot's "
        "reach, safety envelope, role)"
    ),
    ExitCode.USAGE: "usage: bad arguments, values or input files (nothing sent)",
    ExitCode.LINK: "link: cannot connect, no answer in time, malformed answer, no device at the unit id",
    ExitCode.UNKNOWN: (
        "sent; the outcome is unknown (status unreadable, not finished in time, not acknowledged, "
        "another master seen before its end): check the robot before sending it again"
    ),
    ExitCode.INTERRUPTED: "interrupted (Ctrl-C; a motion under way is stopped first)",
}

#: The errors that mean the link, not the command, failed.
LINK_ERRORS: tuple[type[TeachPadError], ...] = (LinkError, ResponseTimeout, MalformedResponse)

#: The end of ``teachpad-cli --help``: the table, one code a line.
EPILOG = "exit codes:\n" + "\n".join(f"  {int(code):>3}  {code.meaning}" for code in ExitCode)


def exit_code_for(error: BaseException) -> ExitCode:
    """The exit code of a run that ended with ``error`` (a :class:`TeachPadError`, an
    ``OSError`` of a file, or Ctrl-C)."""
    if isinstance(error, KeyboardInterrupt):
        return ExitCode.INTERRUPTED
    if isinstance(error, InvalidInput | RegisterProfileError):  # bad arguments or input files
        return ExitCode.USAGE
    if isinstance(error, LINK_ERRORS):
        return ExitCode.LINK
    gateway = getattr(error, "exception_code", None) in GATEWAY_EXCEPTIONS
    if isinstance(error, ModbusExceptionError) and gateway:
        return ExitCode.LINK  # nothing answers at this unit id: the link, not the command
    if isinstance(error, CommandTimeout):  # OutcomeUnknown too: taken, what it did is not known
        return ExitCode.UNKNOWN
    return ExitCode.FAILED  # a TeachPadError of the command, or a file that cannot be written

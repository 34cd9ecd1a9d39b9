"""Typed errors of the core. Each carries a message an operator can read.

``str(exc)`` is plain English (the CLI prints it). Beside it every error has a :class:`Reason`:
a stable ``code`` and its arguments (numbers, register names, enum values -- never English
sentences), which the GUI turns into a sentence in the operator's language (``ui/messages.py``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from app.protocol.enums import CommandStatus


@dataclass(frozen=True)
class Reason:
    """Why something ended, as a code and its arguments (translated by the GUI)."""

    code: str
    args: Mapping[str, Any] = field(default_factory=dict)


class TeachPadError(Exception):
    """Base of every error the core raises on purpose.

    ``code`` names the kind (a class default, or given per raise); ``params`` are its arguments.
    """

    code = "error"

    def __init__(
        self, message: str = "", *, code: str | None = None, params: Mapping[str, Any] | None = None
    ) -> None:
        super().__init__(message)
        if code is not None:
            self.code = code
        self.params: dict[str, Any] = dict(params or {})

    def as_reason(self) -> Reason:
        """Its code and arguments (a method: some subclasses keep a text ``reason`` attribute)."""
        return Reason(self.code, dict(self.params))


class LinkError(TeachPadError):
    """No connection to the controller (refused, dropped, not connected)."""

    code = "link_lost"


class ResponseTimeout(TeachPadError):
    """The controller did not answer a request in time."""

    code = "no_answer"


class MalformedResponse(TeachPadError):
    """The controller answered, but the answer does not match the request (never used as a value).

    ``field`` names what was wrong ("function", "byte count", "CRC", ...); ``expected`` and
    ``got`` are its values (None when the answer was cut short or had bytes too many).
    """

    code = "malformed_answer"

    def __init__(self, message: str, *, field: str = "", expected: object = None, got: object = None) -> None:
        super().__init__(message, params={"field": field, "expected": _short(expected), "got": _short(got)})
        self.field = field
        self.expected = expected
        self.got = got


class ModbusExceptionError(TeachPadError):
    """The controller answered with a Modbus exception."""

    code = "modbus_exception"

    def __init__(self, function_code: int, exception_code: int, message: str) -> None:
        super().__init__(message, params={"function": function_code, "exception": exception_code})
        self.function_code = function_code
        self.exception_code = exception_code


class WriteBlocked(TeachPadError):
    """A write was refused before the wire because the client is monitor-only."""

    code = "monitor_only"


class CommandRefused(TeachPadError):
    """The controller refused or failed a command; ``status`` is GV291 decoded."""

    code = "command_refused"

    def __init__(
        self,
        status: CommandStatus,
        message: str | None = None,
        *,
        code: str | None = None,
        params: Mapping[str, Any] | None = None,
    ) -> None:
        super().__init__(
            message or f"command failed: {status.text} (status {status.code})",
            code=code,
            params={
                "kind": status.kind.value if status.kind else None,
                "status": status.code,
                **(params or {}),
            },
        )
        self.status = status


class CommandTimeout(TeachPadError):
    """A command did not complete in time (codes: command_timeout, not_acknowledged,
    result_unknown)."""

    code = "command_timeout"


class OutcomeUnknown(CommandTimeout):
    """A command the controller took (its write was answered) whose outcome could not be told: its
    status reads kept failing, the link went down, or the host stopped following it. The robot
    may have acted on it: check it before sending the command again (code: outcome_unknown)."""

    code = "outcome_unknown"


class ControllerBusy(TeachPadError):
    """Not sent: the controller shows a program or motion under way, and a command whose outcome
    is told only by motion (run program, go to zero) could not be told from it."""

    code = "controller_busy"


class AlarmRaised(TeachPadError):
    """An alarm appeared while waiting for a command to complete."""

    code = "alarm_while_waiting"

    def __init__(self, alarms: int, message: str, *, params: Mapping[str, Any] | None = None) -> None:
        super().__init__(message, params={"alarms": alarms, **(params or {})})
        self.alarms = alarms


class CommandStopped(TeachPadError):
    """The wait ended because the motion was stopped (codes: stopped_by_operator, the host sent
    the stop; stopped_by_controller)."""

    code = "stopped_by_controller"


class ManualModeRefused(TeachPadError):
    """A command that needs auto mode found the controller in manual (or a mode it does not know)
    and was not allowed to switch it: nothing was written. Switching the work mode is the
    operator's decision (the GUI asks, naming the switch; the CLI needs ``--auto``). ``mode`` is
    register 560 as read; the reason carries it only when it is manual (0), a mode the GUI names."""

    code = "manual_mode"

    def __init__(self, operation: str, mode: int | None) -> None:
        where = "is in manual mode" if mode == 0 else "is not in auto mode"
        super().__init__(
            f"{operation} refused: the controller {where} (register 560 reads {mode}); nothing was "
            "sent. Switch it to auto first (or allow the switch: --auto in teachpad-cli)",
            params={"operation": operation} if mode != 0 else {"operation": operation, "mode": mode},
        )


class ReducedSpeedRefused(TeachPadError):
    """A motion reduced-speed mode cannot cap (it has no speed the host sets, e.g. go to zero):
    refused before the wire."""

    code = "reduced_speed_refused"

    def __init__(self, operation: str) -> None:
        super().__init__(
            f"{operation} refused in reduced-speed mode: it runs at the controller's own speed, "
            "which TeachPad cannot cap; nothing was sent",
            params={"operation": operation},
        )


class ForeignMasterRefused(TeachPadError):
    """Not sent: another Modbus master wrote to the controller moments ago (app/link/foreign.py),
    so a move's parameters may be its own; nothing was started."""

    code = "foreign_master"

    def __init__(self, operation: str, seconds: float, sign: str, command: int | None = None) -> None:
        params: dict[str, Any] = {"operation": operation, "seconds": round(seconds)}
        if command is not None:
            params["command"] = command
        super().__init__(
            f"{operation} not sent: {sign} less than {seconds:g} s ago; its writes could change this "
            "move. Make sure no other master is commanding the robot, then send it again",
            params=params,
        )


class InvalidInput(TeachPadError, ValueError):
    """A value the host refuses before sending (range, NaN, unknown enum)."""

    code = "invalid_input"


class ProfileError(InvalidInput):
    """A profile file that cannot be used: a robot model (:mod:`app.view3d.profile`) or a safety
    envelope (:mod:`app.safety.profile`); the message says which file, where and why. A robot
    profile's code (``profile_*``) and params say the same for the GUI's words
    (ui/messages_profile.py): ``where`` the field (``joint``, 1-based, and ``key``), ``file`` the
    file when it came from one. (A register profile has its own error, a usage error of the CLI:
    :class:`app.safety.register_profile.RegisterProfileError`.)"""


def _short(value: object, limit: int = 24) -> object:
    """A bad value quoted in a reason: numbers as they are, anything else cut to a short prefix."""
    if value is None or isinstance(value, int | float):
        return value
    text = value.hex() if isinstance(value, bytes | bytearray) else str(value)
    return text if len(text) <= limit else text[:limit] + "…"

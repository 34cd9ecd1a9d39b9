"""Typed errors of the core. Each carries a message an operator can read."""

from __future__ import annotations

from app.protocol.enums import CommandStatus


class TeachPadError(Exception):
    """Base of every error the core raises on purpose."""


class LinkError(TeachPadError):
    """No connection to the controller (refused, dropped, not connected)."""


class ResponseTimeout(TeachPadError):
    """The controller did not answer a request in time."""


class MalformedResponse(TeachPadError):
    """The controller answered, but the answer does not match the request (never used as a value).

    ``field`` names what was wrong ("function", "byte count", "CRC", ...); ``expected`` and
    ``got`` are its values (None when the answer was cut short or had bytes too many).
    """

    def __init__(self, message: str, *, field: str = "", expected: object = None,
                 got: object = None) -> None:
        super().__init__(message)
        self.field = field
        self.expected = expected
        self.got = got


class ModbusExceptionError(TeachPadError):
    """The controller answered with a Modbus exception."""

    def __init__(self, function_code: int, exception_code: int, message: str) -> None:
        super().__init__(message)
        self.function_code = function_code
        self.exception_code = exception_code


class WriteBlocked(TeachPadError):
    """A write was refused before the wire because the client is monitor-only."""


class CommandRefused(TeachPadError):
    """The controller refused or failed a command; ``status`` is GV291 decoded."""

    def __init__(self, status: CommandStatus, message: str | None = None) -> None:
        super().__init__(message or f"command failed: {status.text} (status {status.code})")
        self.status = status


class CommandTimeout(TeachPadError):
    """A command did not complete in time."""


class AlarmRaised(TeachPadError):
    """An alarm appeared while waiting for a command to complete."""

    def __init__(self, alarms: int, message: str) -> None:
        super().__init__(message)
        self.alarms = alarms


class CommandStopped(TeachPadError):
    """The wait ended because the motion was stopped (by us or the controller)."""


class InvalidInput(TeachPadError, ValueError):
    """A value the host refuses before sending (range, NaN, unknown enum)."""

"""What every ``teachpad-cli`` command handler gets: :class:`CliContext`.

A handler is ``fn(ctx: CliContext) -> ExitCode``, set on its sub-parser with
``set_defaults(handler=fn)`` by its module's ``register(subparsers)``. ``ctx.args`` are the
parsed arguments; ``ctx.client`` is a :class:`~app.link.client.RobotClient` connected on first
use (commands that work offline never touch the link), closed by ``app/cli/main.py``.
"""

from __future__ import annotations

import argparse
import contextlib
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, TextIO, TypeVar

from app import timing
from app.cli.exit_codes import ExitCode
from app.connection import ConnectionSettings
from app.errors import ModbusExceptionError, TeachPadError
from app.link.client import RobotClient
from app.link.foreign import ForeignSighting, audit_sighting
from app.link.halt import RETRY_EXCEPTIONS
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps

if TYPE_CHECKING:
    from app.cli.guard import CliSafety

__all__ = [
    "PROG",
    "CliContext",
    "Handler",
    "ctrl_c_remembered",
    "sigint_deferred",
    "stop_after_ctrl_c",
    "stop_on_a_fresh_link",
    "stop_while_busy",
    "wait_motion",
]

PROG = "teachpad-cli"

T = TypeVar("T")


@dataclass
class CliContext:
    """What a subcommand handler gets: the arguments, a lazily connected client, the streams."""

    args: argparse.Namespace
    settings: ConnectionSettings
    out: TextIO = field(default_factory=lambda: sys.stdout)
    err: TextIO = field(default_factory=lambda: sys.stderr)
    #: where the client comes from (default: a RobotClient from ``settings``, with the audit
    #: trail); the context closes it either way
    make_client: Callable[[], RobotClient] | None = None
    #: reduced-speed mode's caps (``--reduced-speed``), given to the client (None: not reduced)
    caps: MotionCaps | None = None
    #: the GUI's envelope and roles for this command (app/cli/guard.py); None: a command that
    #: only reads
    safety: CliSafety | None = None
    _client: RobotClient | None = None
    _audit: AuditLog | None = None

    @property
    def audit(self) -> AuditLog:
        """The audit trail the GUI writes too; its records carry the role the command acts as."""
        if self._audit is None:
            self._audit = AuditLog(
                role="administrator (cli)", word_order=self.settings.word_order, on_error=self.warn
            )
        return self._audit

    @property
    def client(self) -> RobotClient:
        if self._client is None:
            if _CtrlC.pressed:  # a Ctrl-C Python lost (see ctrl_c_remembered): nothing is sent
                raise KeyboardInterrupt
            if self.caps is not None:
                self._say_caps(self.caps)
            if self.make_client is not None:
                self._client = self.make_client()
                self._client.caps = self.caps
                return self._client
            client = RobotClient(self.settings)
            client.caps = self.caps
            # The CLI's writes go to the same audit trail as the GUI's, with the role it acts as.
            # No write goes out without its record (a full disk refuses it, Stop excepted, see
            # AuditLog.writing); a record that cannot be written is said, once per problem.
            client.audit = self.audit
            self._watch_foreign(client)
            self._client = client
            client.connect()
        return self._client

    def _watch_foreign(self, client: RobotClient) -> None:
        """Another Modbus master seen while this command reads the controller (app/link/foreign.py):
        one warning line per kind of sign, every sighting audited."""
        said: set[str] = set()

        def seen(sighting: ForeignSighting) -> None:
            audit_sighting(client.audit, sighting)
            if sighting.what not in said:
                said.add(sighting.what)
                self.warn(f"{sighting.message}; its writes can change what ours do")

        client.foreign.on_sighting = seen
        client.watch_shared_every = timing.CLOCK_POLL_PERIOD

    def _say_caps(self, caps: MotionCaps) -> None:
        self.warn(
            f"reduced speed: motions capped at {caps.ratio:g} % (jog, programs), {caps.speed:g} mm/s "
            f"(moves, base steps), {caps.joint_rpm_cap:.2g} rpm (one joint); go to zero refused"
        )

    def print(self, *parts: object) -> None:
        print(*parts, file=self.out, flush=True)

    def warn(self, message: str) -> None:
        print(f"{PROG}: warning: {message}", file=self.err, flush=True)

    def error(self, message: str) -> None:
        """Say what went wrong (one line) for a command that returns its exit code itself."""
        print(f"{PROG}: error: {message}", file=self.err, flush=True)

    def report(self, message: str) -> ExitCode:
        """Print the one line a command that only sends something says; it succeeded."""
        self.print(message)
        return ExitCode.OK

    def close(self) -> None:
        if self._client is not None:
            _not_followed(self._client)
            self._client.close()


Handler = Callable[[CliContext], int]


def _not_followed(client: RobotClient) -> None:
    """A command still under way when the CLI is done with it (``--no-wait``, or an error before
    its end): its outcome is unknown, and the audit trail says so in these words."""
    now = time.monotonic()
    for command in (client.last_tracker, client.last_watch):
        if command is not None and not command.finished:
            command.unknown(
                now,
                message=f"{command.text}: not followed to its end by teachpad-cli; its outcome is unknown",
            )


def wait_motion(ctx: CliContext, start: Callable[[], T]) -> T:
    """Run a blocking motion; on Ctrl-C send stop before giving up."""
    try:
        return start()
    except KeyboardInterrupt:
        tracker = ctx.client.last_tracker
        if tracker is not None and not tracker.finished and not ctx.settings.monitor_only:
            stop_after_ctrl_c(ctx)
        raise


def stop_after_ctrl_c(ctx: CliContext, *, command_sent: float | None = None) -> None:
    """Send stop after Ctrl-C (:func:`stop_on_a_fresh_link`), and say how it went (one warning line)."""
    try:
        stop_on_a_fresh_link(ctx.client, command_sent=command_sent)
        ctx.warn("interrupted: stop sent")
    except TeachPadError as exc:
        ctx.warn(f"interrupted, and stop failed: {exc}")


def stop_on_a_fresh_link(client: Any, *, command_sent: float | None = None) -> None:
    """Stop the robot after an interruption; raises the stop's :class:`TeachPadError`.

    The link is closed first: Ctrl-C may have cut a request in half, and its late answer would
    be read as the stop's. But the command may still be on its way on the old link, and a
    controller may take it after the stop that came on the new one: when its effect was not
    seen yet (the client's last tracker, or ``command_sent``: ``time.monotonic()`` when a
    command without a tracker went out), a second stop goes out once that command is older than
    the link timeout (a controller takes a request within the timeout, or it counts as lost).
    Ctrl-C is ignored meanwhile; it all takes at most the connect, two requests and the rest of
    one timeout -- unless the controller answers *busy*: then the stop goes out again
    (:func:`stop_while_busy`)."""
    with sigint_deferred():  # from the start: a second Ctrl-C (operators press it again) cancels no stop
        tracker = getattr(client, "last_tracker", None)
        if command_sent is None and tracker is not None and not tracker.finished and not tracker.acknowledged:
            command_sent = tracker.started
        client.close()
        stop_while_busy(client)
        if command_sent is not None:
            time.sleep(max(0.0, command_sent + client.settings.timeout - time.monotonic()))
            stop_while_busy(client)


#: s between two stops while the controller answers *busy* (:func:`stop_while_busy`)
STOP_RETRY_INTERVAL = 0.05


def stop_while_busy(client: Any) -> None:
    """441 <- 1, again every :data:`STOP_RETRY_INTERVAL` while the controller answers "not now"
    (Modbus exception 4, 5 or 6: app/link/halt.py), for ``timing.HALT_CONFIRM_BUDGET`` at most;
    then (or on any other failure) the last error is raised."""
    deadline = time.monotonic() + timing.HALT_CONFIRM_BUDGET
    while True:
        try:
            client.stop()
            return
        except ModbusExceptionError as exc:
            if exc.exception_code not in RETRY_EXCEPTIONS or time.monotonic() >= deadline:
                raise
        time.sleep(STOP_RETRY_INTERVAL)


class _CtrlC:
    """Whether Ctrl-C came while :func:`ctrl_c_remembered` was in force."""

    pressed = False


def _on_ctrl_c(signum: int, frame: object) -> None:
    _CtrlC.pressed = True
    raise KeyboardInterrupt


def _quiet_lost_ctrl_c(unraisable: Any, default: Callable[[Any], None]) -> None:
    if not isinstance(unraisable.exc_value, KeyboardInterrupt):
        default(unraisable)


@contextlib.contextmanager
def ctrl_c_remembered() -> Iterator[None]:
    """Python's Ctrl-C (KeyboardInterrupt), and a memory of it for the Ctrl-C Python loses.

    A KeyboardInterrupt raised where Python cannot raise (a finaliser, a weakref callback, as
    during an import: "Exception ignored in ...") is printed and dropped, and the command went
    on to move the robot. Here the Ctrl-C is remembered: the link is not opened after it
    (:attr:`CliContext.client` raises KeyboardInterrupt), and the dropped one is not printed.
    Nothing changes where Ctrl-C is ignored (a background job) or off the main thread."""
    if (
        threading.current_thread() is not threading.main_thread()
        or signal.getsignal(signal.SIGINT) is not signal.default_int_handler
    ):
        yield
        return
    _CtrlC.pressed = False
    default_hook = sys.unraisablehook
    sys.unraisablehook = lambda unraisable: _quiet_lost_ctrl_c(unraisable, default_hook)
    signal.signal(signal.SIGINT, _on_ctrl_c)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        sys.unraisablehook = default_hook
        _CtrlC.pressed = False


@contextlib.contextmanager
def sigint_deferred() -> Iterator[None]:
    """Ignore Ctrl-C while cleaning up (each request is bounded by the link timeout)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)

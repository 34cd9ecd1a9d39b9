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
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TextIO, TypeVar

from app.cli.exit_codes import ExitCode
from app.errors import TeachPadError
from app.link.client import ConnectionSettings, RobotClient
from app.safety.audit import AuditLog

__all__ = ["PROG", "CliContext", "Handler", "sigint_deferred", "stop_after_ctrl_c", "wait_motion"]

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
    _client: RobotClient | None = None

    @property
    def client(self) -> RobotClient:
        if self._client is None:
            if self.make_client is not None:
                self._client = self.make_client()
                return self._client
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

    def error(self, message: str) -> None:
        """Say what went wrong (one line) for a command that returns its exit code itself."""
        print(f"{PROG}: error: {message}", file=self.err, flush=True)

    def report(self, message: str) -> ExitCode:
        """Print the one line a command that only sends something says; it succeeded."""
        self.print(message)
        return ExitCode.OK

    def close(self) -> None:
        if self._client is not None:
            self._client.close()


Handler = Callable[[CliContext], int]


def wait_motion(ctx: CliContext, start: Callable[[], T]) -> T:
    """Run a blocking motion; on Ctrl-C send stop before giving up."""
    try:
        return start()
    except KeyboardInterrupt:
        tracker = ctx.client.last_tracker
        if tracker is not None and not tracker.finished and not ctx.settings.monitor_only:
            stop_after_ctrl_c(ctx)
        raise


def stop_after_ctrl_c(ctx: CliContext) -> None:
    """Send stop after Ctrl-C, and say how it went (one warning line).

    The link is closed first: Ctrl-C may have cut a request in half, and its late answer would
    be read as the stop's. Ctrl-C is ignored meanwhile; the stop is bounded by the link timeout
    (connect, then one request)."""
    client = ctx.client
    client.close()
    with sigint_deferred():
        try:
            client.stop()
            ctx.warn("interrupted: stop sent")
        except TeachPadError as exc:
            ctx.warn(f"interrupted, and stop failed: {exc}")


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

"""The worker's sequence of its parts when the link changes (worker thread; Qt-free, so the
tests' host runs the same order as :class:`~app.link.worker.RobotWorker`).

The supervisor decides and says what it decided (:mod:`app.link.supervisor`); this hands it on
to the jog, the poller, the upload, the command in flight and the worker's timers and queue, in
the order docs/DESIGN.md describes ("Link health"), as :mod:`app.link.sequence` does a poll's.
No part calls another for a change of the link.

* :func:`connect` -- the last link closed, a new client, the jog forgets teach mode, CONNECTING,
  then :func:`try_connect`: open and read, the jog made safe (ratio 0 and teach off before
  anything else after a loss), live, the poller reset, the controller identified, CONNECTED, the
  first pose and status, ``controllerReconnected``, polling, the queued jobs.
* :func:`answered` / :func:`silent` -- a silence ends (the jog's ratio 0, then CONNECTED) or
  begins (the held jog dropped) or lasts (the link lost).
* :func:`link_failed` -- a failed transaction counted; :func:`lose_link` when they are too many.
* :func:`lose_link` -- polling stops, the jog ends (switched off on return), the upload ends, the
  command in flight and the queued jobs fail, the client's connection closes, a retry is timed.
* :func:`close_link` -- no retry, no polling, the jog stopped and teach off (if the controller
  answers), the upload, the command in flight and (by default) the queue end, the client goes.
"""

from __future__ import annotations

import contextlib
import time
from typing import Protocol

from app.connection import ConnectionSettings
from app.errors import LinkError, Reason, ResponseTimeout, TeachPadError
from app.link.active import MotionTracker
from app.link.jog import JogMachine
from app.link.poller import Poller
from app.link.supervisor import Cause, LinkSupervisor, Silence
from app.link.types import LinkState, Operation
from app.link.upload import Uploader
from app.models import CommandResult
from app.safety.audit import AuditLog
from app.safety.caps import MotionCaps

__all__ = [
    "LinkParts",
    "answered",
    "close_link",
    "connect",
    "link_failed",
    "lose_link",
    "silent",
    "try_connect",
]


class LinkParts(Protocol):
    """The parts a change of the link goes through, and the worker's timers and queue."""

    @property
    def supervisor(self) -> LinkSupervisor: ...
    @property
    def poller(self) -> Poller: ...
    @property
    def jog(self) -> JogMachine: ...
    @property
    def uploader(self) -> Uploader: ...
    @property
    def motion(self) -> MotionTracker: ...
    @property
    def closed(self) -> bool: ...
    @property
    def audit(self) -> AuditLog | None: ...
    @property
    def caps(self) -> MotionCaps | None: ...

    def start_polling(self) -> None: ...
    def stop_polling(self) -> None: ...
    def start_reconnect(self, delay: float) -> None: ...
    def stop_reconnect(self) -> None: ...
    def run_jobs(self) -> None: ...
    def fail_queued(self, message: str, code: str | None = None) -> None: ...
    def publish_reconnected(self) -> None: ...
    def emit_result(self, result: CommandResult, request_id: int | None = -1) -> None: ...
    def emit_error(
        self, operation: str, message: str, request_id: int | None = -1, reason: Reason | None = None
    ) -> None: ...


# --- connecting ------------------------------------------------------------------------------
def connect(parts: LinkParts, settings: ConnectionSettings) -> None:
    """(Re)connect with ``settings``: the jobs queued since the GUI asked for it run once it is up."""
    close_link(parts, Operation.CONNECT, LinkState.DISCONNECTED, "", emit=False, fail_queued=False)
    parts.supervisor.begin(settings, audit=parts.audit, caps=parts.caps)
    parts.jog.reset()
    parts.supervisor.set_state(LinkState.CONNECTING, "")
    try_connect(parts)


def try_connect(parts: LinkParts) -> None:
    """One connection attempt: open, read status and pose, make jogging safe, go live."""
    supervisor = parts.supervisor
    if parts.closed:
        return
    try:
        opened = supervisor.open()
        if opened is None:
            return
        parts.jog.make_teach_safe(opened.status, opened.ever_connected)
    except TeachPadError as exc:
        _retry_later(parts, exc)
        return
    reconnected = supervisor.go_live()
    parts.poller.reset(time.monotonic())
    failure = supervisor.identify(opened.client)  # before the GUI hears of the link: a restart is noticed
    if failure is not None:
        link_failed(parts, failure)
        if not supervisor.link_up:
            return
    supervisor.set_state(LinkState.CONNECTED, "")
    parts.poller.publish(opened.pose, opened.status)
    if reconnected:
        parts.publish_reconnected()
    parts.start_polling()
    parts.run_jobs()


def _retry_later(parts: LinkParts, cause: Cause, prefix: str = "") -> None:
    """DOWN, and the next attempt after the backoff's delay."""
    delay = parts.supervisor.down(cause, prefix)
    if not parts.closed:
        parts.start_reconnect(delay)


# --- silence and failures --------------------------------------------------------------------
def answered(parts: LinkParts) -> None:
    """A good poll: back to CONNECTED after a silence (ratio 0 first if a jog was under way)."""
    supervisor = parts.supervisor
    if not supervisor.answering_again():
        return
    try:
        parts.jog.controller_answers()
    except TeachPadError as exc:
        parts.emit_error(Operation.JOG_RELEASE, f"could not stop the jog: {exc}", None, exc.as_reason())
        if isinstance(exc, (LinkError, ResponseTimeout)):
            link_failed(parts, exc)
            if not supervisor.link_up:
                return
    supervisor.set_state(LinkState.CONNECTED, "")


def silent(parts: LinkParts, cause: Cause, now: float) -> None:
    """A poll timed out with the link open: NOT_ANSWERING at once (the held jog dropped; the jog
    tells the operator itself when one was under way); the link lost when it lasts."""
    verdict = parts.supervisor.poll_silent(cause, now)
    if verdict is Silence.BEGAN:
        parts.jog.controller_silent()
    elif verdict is Silence.LOST:
        lose_link(parts, cause)


def link_failed(parts: LinkParts, cause: Cause) -> None:
    """A failed transaction (refused, reset, timed out, malformed): counted; the link is lost
    after :data:`app.timing.LINK_LOSS_POLLS` in a row."""
    if parts.supervisor.transport_failed(cause):
        lose_link(parts, cause)


def lose_link(parts: LinkParts, cause: Cause) -> None:
    """Declare the link down at once; the reconnect timer takes over."""
    supervisor = parts.supervisor
    if not supervisor.link_up:
        return
    supervisor.lost()
    parts.stop_polling()
    parts.jog.link_lost()
    parts.uploader.end(f"link lost: {cause}")
    unknown = "link lost while the command was under way; its outcome is unknown"
    _fail_active(parts, unknown, "outcome_unknown_link_lost")
    parts.fail_queued("the link to the controller is down: not sent", "queued_link_down")
    supervisor.drop_client()
    _retry_later(parts, cause, "link lost: ")


# --- closing ---------------------------------------------------------------------------------
def close_link(
    parts: LinkParts,
    operation: str,
    state: LinkState,
    message: str,
    *,
    emit: bool = True,
    fail_queued: bool = True,
    short: bool = False,
) -> None:
    """Stop jogging and switch teach off (if the controller answers), close, stop retrying.

    ``short`` (shutdown): those safety transactions wait at most the poll timeout each, so a
    dead controller cannot hold the window's close for the request timeout."""
    supervisor = parts.supervisor
    parts.stop_reconnect()
    parts.stop_polling()
    client = supervisor.client
    if client is not None and supervisor.link_up and not client.settings.monitor_only:
        short_io = client.io_timeout(client.settings.effective_poll_timeout) if short else None
        try:
            with short_io or contextlib.nullcontext():
                parts.jog.stop_jog_and_teach()
        except TeachPadError as exc:
            parts.emit_error(operation, f"could not stop teach mode: {exc}", None, exc.as_reason())
    parts.uploader.end(f"{operation}: the link was closed")
    unknown = f"{operation}: the link was closed while the command was under way"
    _fail_active(parts, unknown, "outcome_unknown_link_closed")
    if fail_queued:
        parts.fail_queued(f"{operation}: the link was closed: not sent", "queued_link_closed")
    supervisor.close()
    parts.poller.forget()
    if emit:
        supervisor.set_state(state, message)


def _fail_active(parts: LinkParts, message: str, code: str) -> None:
    """The command in flight: its outcome is unknown; said so, and recorded so against its
    command in the audit."""
    active = parts.motion.take()
    if active is not None:
        result = active.completion.unknown(
            time.monotonic(),
            message=f"{active.operation}: {message}",
            reason=Reason(code, {"operation": active.operation}),
        )
        parts.emit_result(result, active.request_id)

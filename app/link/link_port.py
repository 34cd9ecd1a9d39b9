"""What panels and controllers hold of the link: :class:`LinkPort`, the typed port RobotLink
fits (and the tests' small fake), :class:`Pending`, one request's progress and outcome, and
:class:`RequestRouter`, request id (ticket) -> Pending."""

from __future__ import annotations

from typing import Protocol

from PySide6.QtCore import QMetaMethod, QObject, QTimer, Signal, SignalInstance

from app.link.ops import LinkOp
from app.link.progress import Progress
from app.link.state import RobotState
from app.link.types import WorkerError
from app.models import CommandResult

__all__ = ["LinkPort", "Pending", "RequestRouter"]


class Pending(QObject):
    """One request's progress and outcome: ``progressed`` (a :mod:`~app.link.progress` report:
    an upload's points and count) for this request only, any number of times, before its
    outcome; exactly one of ``finished`` / ``failed`` fires, once; then every receiver is
    disconnected (connect before the outcome: call ``track`` right away).

    Why the disconnect: a receiver that captures its Pending (``pending.finished.connect(lambda r:
    self._on_result(pending, r))``, the controllers' way) makes a cycle that runs through Qt's
    connection, which the garbage collector cannot see: every such Pending (and what its lambdas
    captured) lived as long as the process, a leak per request (issue 18)."""

    progressed = Signal(object)  # Progress (app/link/progress.py) of this request
    finished = Signal(CommandResult)
    failed = Signal(WorkerError)

    def __init__(self, request_id: int, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._request_id = request_id
        self.result: CommandResult | None = None
        self.error: WorkerError | None = None

    @property
    def request_id(self) -> int:
        return self._request_id

    @property
    def done(self) -> bool:
        return self.result is not None or self.error is not None

    def _progress(self, progress: Progress) -> None:
        if not self.done:
            self.progressed.emit(progress)

    def _finish(self, result: CommandResult) -> None:
        if not self.done:
            self.result = result
            self.finished.emit(result)
            self._release()

    def _fail(self, error: WorkerError) -> None:
        if not self.done:
            self.error = error
            self.failed.emit(error)
            self._release()

    def _release(self) -> None:
        """Drop the receivers of both signals: nothing more will be emitted (see the class)."""
        # Looked up in the meta-object: QMetaMethod.fromSignal(self.finished) keeps a reference
        # to self (PySide 6.11), the very leak this ends; disconnecting a signal without
        # receivers warns.
        meta = self.metaObject()
        for index in range(meta.methodOffset(), meta.methodCount()):
            method = meta.method(index)
            if method.methodType() == QMetaMethod.MethodType.Signal and self.isSignalConnected(method):
                getattr(self, bytes(method.name().data()).decode()).disconnect()


class RequestRouter:
    """Request id -> :class:`Pending`; the progress and outcomes of untracked requests are
    ignored here."""

    def __init__(self) -> None:
        self._pending: dict[int, Pending] = {}

    def track(self, request_id: int) -> Pending:
        pending = self._pending.get(request_id)
        if pending is not None:
            return pending
        pending = Pending(request_id)
        if request_id <= 0:  # nothing was queued (the link is shut down): fail once connected to
            error = WorkerError("request", "the link is shut down: nothing was sent", None)
            QTimer.singleShot(0, pending, lambda: pending._fail(error))
        else:
            self._pending[request_id] = pending
        return pending

    def on_progress(self, ticket: int, progress: Progress) -> None:
        if pending := self._pending.get(ticket):
            pending._progress(progress)

    def on_result(self, result: CommandResult) -> None:
        if result.request_id is not None and (pending := self._pending.pop(result.request_id, None)):
            pending._finish(result)

    def on_error(self, error: WorkerError) -> None:
        if error.request_id is not None and (pending := self._pending.pop(error.request_id, None)):
            pending._fail(error)

    def __len__(self) -> int:
        return len(self._pending)


class LinkPort(Protocol):
    """What panels and controllers use of the link (RobotLink fits; the tests' FakeLink too):
    its state (``state.stops_requested`` included), ``submit(op)`` of one operation of
    :mod:`app.link.ops` (its ticket back: the request id) and ``track(ticket)`` (that request's
    progress and outcome); besides, every request's progress keyed by its ticket
    (``progressed``) and the signals that are not one request's (the link came back, the
    controller restarted, another master)."""

    controllerReconnected: SignalInstance  # noqa: N815 - () the link came back: the worker made it safe
    controllerRestarted: SignalInstance  # noqa: N815 - () the restart canary changed: temp points are gone
    foreignMaster: SignalInstance  # noqa: N815 - (str, float) another master seen: what, the value (app/link/foreign.py)
    progressed: SignalInstance  # (int, Progress) a request's ticket, its progress (app/link/progress.py)

    @property
    def state(self) -> RobotState: ...

    def submit(self, op: LinkOp) -> int: ...

    def track(self, request_id: int) -> Pending: ...

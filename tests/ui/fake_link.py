"""A small typed fake of the link port (:class:`app.link.robot_link.LinkPort`) for unit tests.

It holds a real :class:`RobotState` and a real :class:`RequestRouter`, so the code under test
sees the real types and the real request-id routing; the submitted operations
(:mod:`app.link.ops`) are recorded, not sent: a test reads them as data (``link.named(MoveToPoint)``). Tests
play the worker: ``commandFinished.emit(result)`` / ``errorOccurred.emit(error)`` /
``progressed.emit(ticket, progress)`` go through the router exactly like the link's,
``set_connected`` changes ``state.connection``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypeVar

from PySide6.QtCore import QObject, Signal

from app.link.link_port import LinkPort, Pending, RequestRouter
from app.link.ops import CreatePoint, LinkOp, MoveToPoint, Stop, UploadPoints
from app.link.progress import PointUploaded, UploadProgress
from app.link.state import RobotState
from app.link.types import ConnectionState, ControllerIdentity, LinkState
from app.models import CommandResult
from app.protocol.enums import CommandKind, CommandStatus, RunCommand

#: The controller a FakeLink connects to unless told otherwise (one boot, its canary token 1).
FAKE_CONTROLLER = ControllerIdentity("fake:502", 1, "low-first", 99, 1.0)


@dataclass(frozen=True)
class Submitted:
    """One operation the code under test submitted, and the ticket it got."""

    op: LinkOp
    request_id: int


_Op = TypeVar("_Op", bound=LinkOp)


class FakeLink(QObject):
    """Records the submitted operations (each gets a ticket, a request id); the ``finish_*``
    helpers answer the latest request of their kind."""

    commandFinished = Signal(CommandResult)  # noqa: N815 - the worker's side: routed like RobotLink's
    errorOccurred = Signal(object)  # noqa: N815 - WorkerError, routed likewise
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815
    foreignMaster = Signal(str, float)  # noqa: N815
    progressed = Signal(int, object)  # ticket, Progress (app/link/progress.py): routed like RobotLink's

    def __init__(self, connected: bool = True) -> None:
        super().__init__()
        self._state = RobotState(self)
        self._router = RequestRouter()
        self.commandFinished.connect(self._state.set_last_result)
        self.commandFinished.connect(self._router.on_result)
        self.errorOccurred.connect(self._router.on_error)
        self.progressed.connect(self._router.on_progress)
        self.submitted: list[Submitted] = []
        self._next_id = 100
        if connected:
            self.set_connected(True)

    # --- the port
    @property
    def state(self) -> RobotState:
        return self._state

    def track(self, request_id: int) -> Pending:
        return self._router.track(request_id)

    def submit(self, op: LinkOp) -> int:
        if isinstance(op, Stop):
            self._state.note_stop()
        self._next_id += 1
        self.submitted.append(Submitted(op, self._next_id))
        return self._next_id

    # --- for the tests
    def named(self, op_type: type[_Op]) -> list[_Op]:
        """The submitted operations of this type, in order."""
        return [s.op for s in self.submitted if isinstance(s.op, op_type)]

    def kinds(self) -> list[type[LinkOp]]:
        """The types of the submitted operations, in order."""
        return [type(s.op) for s in self.submitted]

    def ids(self, op_type: type[LinkOp]) -> list[int]:
        """The tickets of the submitted operations of this type, in order."""
        return [s.request_id for s in self.submitted if isinstance(s.op, op_type)]

    def last_id(self, op_type: type[LinkOp]) -> int:
        """The ticket of the latest op of this type (0, an id never given out, if there was none)."""
        ids = self.ids(op_type)
        return ids[-1] if ids else 0

    def set_connected(
        self,
        connected: bool,
        message: str = "",
        *,
        monitor_only: bool = False,
        controller: ControllerIdentity = FAKE_CONTROLLER,
    ) -> None:
        """Connected (to ``controller``: by default the same controller in the same boot every
        time) or down."""
        state = LinkState.CONNECTED if connected else LinkState.DOWN
        self._state.set_connection(
            ConnectionState(
                state, message, "fake:502", monitor_only, controller=controller if connected else None
            )
        )

    def finish_create(self, ok: bool = True, pose: Sequence[float] | None = None, message: str = "") -> None:
        details = dict(zip("xyzabc", pose, strict=True)) if pose is not None else {}
        status = CommandStatus(CommandKind.CREATE_POINT, 0xFF if ok else 1)
        self.commandFinished.emit(
            CommandResult(
                RunCommand.CREATE_POINT,
                CommandKind.CREATE_POINT,
                status,
                ok,
                message,
                {k: float(v) for k, v in details.items()},
                request_id=self.last_id(CreatePoint),
            )
        )

    def finish_move(self, ok: bool = True, code: int = 0xFF, message: str = "") -> None:
        status = CommandStatus(CommandKind.MOVE, code)
        result = CommandResult(
            RunCommand.MOVE_TO_POINT,
            CommandKind.MOVE,
            status,
            ok,
            message,
            request_id=self.last_id(MoveToPoint),
        )
        self.commandFinished.emit(result)

    def point_ok(self, *point_ids: int, ticket: int | None = None) -> None:
        """Each point created, reported under ``ticket`` (default: the latest upload's)."""
        for point_id in point_ids:
            self.progressed.emit(self._upload_ticket(ticket), PointUploaded(point_id, True))

    def point_failed(self, point_id: int, message: str, *, ticket: int | None = None) -> None:
        self.progressed.emit(self._upload_ticket(ticket), PointUploaded(point_id, False, message))

    def upload_progress(self, done: int, total: int, *, ticket: int | None = None) -> None:
        self.progressed.emit(self._upload_ticket(ticket), UploadProgress(done, total))

    def _upload_ticket(self, ticket: int | None) -> int:
        return self.last_id(UploadPoints) if ticket is None else ticket

    def upload_summary(self, uploaded: int, total: int, reason: str = "") -> None:
        text = f"uploaded {uploaded} of {total} points" + (f" ({reason})" if reason else "")
        self.commandFinished.emit(
            CommandResult(
                RunCommand.CREATE_POINT,
                None,
                None,
                uploaded == total,
                text,
                {"uploaded": float(uploaded)},
                request_id=self.last_id(UploadPoints),
            )
        )


def _fits(link: FakeLink) -> LinkPort:
    return link  # mypy checks that the fake fits the port

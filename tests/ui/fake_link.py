"""A small typed fake of the link port (:class:`app.link.robot_link.LinkPort`) for unit tests.

It holds a real :class:`RobotState` and a real :class:`RequestRouter`, so the code under test
sees the real types and the real request-id routing; commands are recorded, not sent. Tests
play the worker: ``commandFinished.emit(result)`` / ``errorOccurred.emit(error)`` go through the
router exactly like the link's, ``set_connected`` changes ``state.connection``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from PySide6.QtCore import QObject, Signal

from app.link.link_port import LinkPort, Pending, RequestRouter
from app.link.state import RobotState
from app.link.types import ConnectionState, ControllerIdentity, LinkState, StepFrame
from app.models import CommandResult
from app.protocol.enums import CommandKind, CommandStatus, ProgramMotionMode, RunCommand, TeachFrame, WorkMode

#: The controller a FakeLink connects to unless told otherwise (one boot, its canary token 1).
FAKE_CONTROLLER = ControllerIdentity("fake:502", 1, "low-first", 99, 1.0)


@dataclass
class Call:
    name: str
    args: tuple[Any, ...]
    kwargs: dict[str, Any] = field(default_factory=dict)
    request_id: int = 0


class FakeLink(QObject):
    """Records the calls; every command returns a request id; the ``finish_*`` helpers answer
    the latest request of their kind."""

    commandFinished = Signal(CommandResult)  # noqa: N815 - the worker's side: routed like RobotLink's
    errorOccurred = Signal(object)  # noqa: N815 - WorkerError, routed likewise
    controllerReconnected = Signal()  # noqa: N815
    controllerRestarted = Signal()  # noqa: N815
    foreignMaster = Signal(str, float)  # noqa: N815
    uploadProgress = Signal(int, int)  # noqa: N815
    pointUploaded = Signal(int, bool, str, bool)  # noqa: N815
    called = Signal(str)

    def __init__(self, connected: bool = True) -> None:
        super().__init__()
        self._state = RobotState(self)
        self._router = RequestRouter()
        self.commandFinished.connect(self._state.set_last_result)
        self.commandFinished.connect(self._router.on_result)
        self.errorOccurred.connect(self._router.on_error)
        self.calls: list[Call] = []
        self._next_id = 100
        if connected:
            self.set_connected(True)

    # --- the port
    @property
    def state(self) -> RobotState:
        return self._state

    def track(self, request_id: int) -> Pending:
        return self._router.track(request_id)

    def _record(self, name: str, *args: Any, **kwargs: Any) -> int:
        self._next_id += 1
        self.calls.append(Call(name, args, kwargs, self._next_id))
        self.called.emit(name)
        return self._next_id

    def stop(self) -> int:
        return self._record("stop")

    @property
    def stops_requested(self) -> int:
        return sum(1 for call in self.calls if call.name == "stop")

    def pause(self) -> int:
        return self._record("pause")

    def resume(self) -> int:
        return self._record("resume")

    def jog_press(
        self, frame: TeachFrame, axis: int, direction: int, ratio: float, user: int = 0, tool: int = 0
    ) -> int:
        return self._record("jog_press", frame, axis, direction, ratio, user, tool)

    def jog_release(self) -> int:
        return self._record("jog_release")

    def set_jog_ratio(self, ratio: float) -> int:
        return self._record("set_jog_ratio", ratio)

    def step(
        self,
        frame: StepFrame,
        offsets: Sequence[float],
        ext_offsets: Sequence[float] = (),
        speed: float = 10.0,
    ) -> int:
        return self._record("step", frame, tuple(offsets), tuple(ext_offsets), speed)

    def set_mode(self, mode: WorkMode) -> int:
        return self._record("set_mode", mode)

    def go_zero(self, axis: int | None, *, switch_to_auto: bool = False) -> int:
        return self._record("go_zero", axis, switch_to_auto=switch_to_auto)

    def run_program(
        self,
        program_id: int,
        mode: ProgramMotionMode = ProgramMotionMode.SINGLE_RUN,
        cycles: int = 1,
        speed_ratio: int = 100,
        *,
        switch_to_auto: bool = False,
    ) -> int:
        return self._record(
            "run_program", program_id, mode, cycles, speed_ratio, switch_to_auto=switch_to_auto
        )

    def create_point(self, point_id: int, pose: Sequence[float] | None = None, tool: int = 200) -> int:
        return self._record("create_point", point_id, pose, tool)

    def move_to_point(
        self,
        end_id: int,
        via_id: int | None = None,
        *,
        orientation_changes: bool = True,
        ignore_middle: bool = False,
        speed: float = 50.0,
        tool: int = 200,
    ) -> int:
        return self._record(
            "move_to_point",
            end_id,
            via_id,
            orientation_changes=orientation_changes,
            ignore_middle=ignore_middle,
            speed=speed,
            tool=tool,
        )

    def upload_points(
        self,
        points: Iterable[tuple[int, Sequence[float], int] | tuple[int, Sequence[float]]],
        tool: int = 200,
    ) -> int:
        items = [(p[0], tuple(p[1]), p[2] if len(p) > 2 else tool) for p in points]
        return self._record("upload_points", items)

    def cancel_upload(self) -> int:
        return self._record("cancel_upload")

    # --- for the tests
    def named(self, name: str) -> list[Call]:
        return [c for c in self.calls if c.name == name]

    def last_id(self, name: str) -> int:
        """The id of the latest ``name`` call (0, an id never given out, if there was none)."""
        calls = self.named(name)
        return calls[-1].request_id if calls else 0

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
                request_id=self.last_id("create_point"),
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
            request_id=self.last_id("move_to_point"),
        )
        self.commandFinished.emit(result)

    def point_ok(self, *point_ids: int) -> None:
        for point_id in point_ids:
            self.pointUploaded.emit(point_id, True, "", False)

    def point_failed(self, point_id: int, message: str) -> None:
        self.pointUploaded.emit(point_id, False, message, False)

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
                request_id=self.last_id("upload_points"),
            )
        )


def _fits(link: FakeLink) -> LinkPort:
    return link  # mypy checks that the fake fits the port

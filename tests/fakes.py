"""A scripted stand-in for RobotClient: records calls, fails where told. No I/O, no sleeps."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from app.errors import CommandRefused, LinkError, MalformedResponse, ModbusExceptionError, ResponseTimeout
from app.models import CommandResult, Pose
from app.protocol.enums import CommandKind, CommandStatus, RunCommand

DONE = CommandResult(RunCommand.MOVE_TO_POINT, CommandKind.MOVE, CommandStatus(CommandKind.MOVE, 0xFF), True)


def failed(code: int, message: str = "") -> CommandResult:
    status = CommandStatus(CommandKind.MOVE, code)
    return CommandResult(RunCommand.MOVE_TO_POINT, CommandKind.MOVE, status, False, message)


@dataclass
class FakeClient:
    """``moves``/``creates`` record the calls. ``move_script[i]`` (i = 0-based call number) is
    a CommandResult to return, an exception to raise, or a callable run before answering."""

    pose: Pose = field(default_factory=lambda: Pose(400.0, 0.0, 450.0, 180.0, 0.0, 0.0))
    move_script: dict[int, Any] = field(default_factory=dict)
    create_script: dict[int, Any] = field(default_factory=dict)
    moves: list[dict[str, Any]] = field(default_factory=list)
    creates: list[dict[str, Any]] = field(default_factory=list)
    stops: int = 0
    closed: bool = False
    gvs: dict[int, float] = field(default_factory=dict)
    #: the points the fake controller holds (id -> pose), from create_point; a move to one of
    #: them puts ``pose`` there, like the simulator does (a move elsewhere leaves it)
    stored: dict[int, tuple[float, ...]] = field(default_factory=dict)
    # the commands a CLI context ends as unknown when it closes with one still under way (none here)
    last_tracker: Any = None
    last_watch: Any = None

    def read_gv(self, n: int, count: int = 1) -> list[float]:
        return [self.gvs.get(n + i, 0.0) for i in range(count)]

    def write_gv(self, n: int, values: Sequence[float]) -> None:
        for i, v in enumerate(values):
            self.gvs[n + i] = float(v)

    def read_pose(self) -> Pose:
        return self.pose

    def invalidate_cache(self) -> None:
        """RobotClient forgets the tool frame it wrote last (nothing cached here)."""

    def create_point(
        self,
        point_id: int,
        *,
        pose: Sequence[float] | None = None,
        gv_start: int = 0,
        tool: int = 200,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        n = len(self.creates)
        self.creates.append({"id": point_id, "pose": tuple(pose) if pose else None, "tool": tool})
        if n not in self.create_script and pose is not None:
            self.stored[point_id] = tuple(pose)
        return self._answer(
            self.create_script.get(n),
            CommandResult(
                RunCommand.CREATE_POINT,
                CommandKind.CREATE_POINT,
                CommandStatus(CommandKind.CREATE_POINT, 0xFF),
                True,
            ),
        )

    def upload_points(
        self,
        points: Sequence[tuple[int, Sequence[float]]],
        tool: int = 200,
        progress: Any = None,
        *,
        results: list[CommandResult] | None = None,
        **_staging: Any,
    ) -> list[CommandResult]:
        """RobotClient.upload_points by :meth:`create_point` (so ``create_script`` counts points):
        a link error or Modbus exception ends the batch with a failed result without a status."""
        out: list[CommandResult] = [] if results is None else results
        for i, (pid, pose) in enumerate(points):
            try:
                result = self.create_point(pid, pose=pose, tool=tool)
            except CommandRefused as exc:
                result = CommandResult(RunCommand.CREATE_POINT, exc.status.kind, exc.status, False, str(exc))
            except (LinkError, ResponseTimeout, MalformedResponse, ModbusExceptionError) as exc:
                kind, reason = CommandKind.CREATE_POINT, exc.as_reason()
                out.append(CommandResult(RunCommand.CREATE_POINT, kind, None, False, str(exc), reason=reason))
                break
            out.append(dataclasses.replace(result, message=f"point {pid}: {result.message}"))
            if progress is not None and progress(i + 1, len(points)) is False:
                break
        return out

    def move_to_point(
        self,
        end_id: int,
        *,
        via_id: int | None = None,
        orientation_changes: bool = True,
        ignore_middle: bool = False,
        speed: float = 50.0,
        tool: int = 200,
        wait: bool = True,
        timeout: float | None = None,
    ) -> CommandResult:
        n = len(self.moves)
        self.moves.append(
            {
                "end": end_id,
                "via": via_id,
                "orientation_changes": orientation_changes,
                "ignore_middle": ignore_middle,
                "speed": speed,
                "tool": tool,
                "wait": wait,
                "timeout": timeout,
            }
        )
        result = self._answer(self.move_script.get(n), DONE)
        if result.ok and end_id in self.stored:
            x, y, z, a, b, c = self.stored[end_id][:6]
            self.pose = Pose(x, y, z, a, b, c)
        return result

    def stop(self) -> None:
        self.stops += 1

    def pause(self) -> None:
        pass

    def resume(self) -> None:
        pass

    def close(self) -> None:
        self.closed = True

    @staticmethod
    def _answer(script: Any, default: CommandResult) -> CommandResult:
        if isinstance(script, BaseException):
            raise script
        if isinstance(script, CommandResult):
            return script
        if callable(script):
            out = script()
            return out if isinstance(out, CommandResult) else default
        return default

"""Helpers of the end-to-end tests: pose checks, wire inspection, points and plans.

Every test in this package talks TCP to a :class:`~app.sim.SimController` on a free loopback
port and waits on conditions only (``sim.wait_for``, the simulator's own clock, a thread's
join), never on fixed sleeps.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from app.cli.points_upload import staged_upload
from app.link.client import RobotClient
from app.points.ledger import PointLedger
from app.points.point import make_point
from app.points.upload import apply_upload
from app.protocol import registers
from app.protocol.enums import RunCommand

# The tolerance for "the final pose matches the last point".
TOL_MM = 0.1
TOL_DEG = 0.1
# How long a condition may take to come true before a test fails (generous: 2 loaded cores).
WAIT = 10.0

MakeClient = Callable[..., RobotClient]


def angle_diff(a: float, b: float) -> float:
    """a - b in degrees, wrapped to [-180, 180) (A = 180 and A = -180 are the same pose)."""
    return (a - b + 180.0) % 360.0 - 180.0


def pose_error(pose: Sequence[float], target: Sequence[float]) -> tuple[float, float]:
    """(position error in mm, largest angle error in degrees) between two X Y Z A B C poses."""
    mm = math.dist(pose[:3], target[:3])
    deg = max(abs(angle_diff(a, b)) for a, b in zip(pose[3:6], target[3:6], strict=True))
    return mm, deg


def assert_pose_at(pose: Sequence[float], target: Sequence[float], what: str = "pose") -> None:
    mm, deg = pose_error(pose, target)
    assert mm <= TOL_MM and deg <= TOL_DEG, (
        f"{what} {tuple(round(v, 3) for v in pose)} is {mm:.3f} mm / {deg:.3f} deg from "
        f"{tuple(round(v, 3) for v in target)}"
    )


def move_commands(sim: Any) -> int:
    """How many 'move to temp point' (440 <- 0x42) commands the simulator received."""
    return sum(
        1 for w in sim.writes_to(registers.REG_RUN_COMMAND) if w.values == (int(RunCommand.MOVE_TO_POINT),)
    )


def control_writes(sim: Any, register: int) -> list[Any]:
    """The 0x06 writes of 1 to a control register (441 stop, 442 pause, 443 resume)."""
    return [w for w in sim.writes_to(register) if w.function_code == 0x06 and w.values == (1,)]


def wait_sim_time(sim: Any, seconds: float) -> None:
    """Wait until the simulator's own clock has advanced ``seconds`` (ticks really happened)."""
    start = sim.state().t
    assert sim.wait_for(lambda s: s.t >= start + seconds, WAIT), "the simulator's clock stopped"


class Background:
    """Run ``fn`` in a daemon thread; :meth:`result` joins and re-raises its exception."""

    def __init__(self, fn: Callable[[], Any]) -> None:
        self._fn = fn
        self._value: Any = None
        self._error: BaseException | None = None
        self.thread = threading.Thread(target=self._run, name="integration-runner", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        try:
            self._value = self._fn()
        except BaseException as exc:  # handed to the test thread
            self._error = exc

    @property
    def alive(self) -> bool:
        return self.thread.is_alive()

    def result(self, timeout: float = WAIT) -> Any:
        self.thread.join(timeout)
        assert not self.thread.is_alive(), "the background run did not end"
        if self._error is not None:
            raise self._error
        return self._value


# --- points and plans

TOOL_DOWN = (180.0, 0.0, 0.0)  # A B C of the simulator's home pose (tool pointing down)

# Three points for line-only plans, all within reach of the arm's home pose (525, 0, 504).
P1 = (525.0, -75.0, 450.0, *TOOL_DOWN)
P2 = (525.0, 75.0, 450.0, *TOOL_DOWN)
P3 = (450.0, -75.0, 420.0, *TOOL_DOWN)
LINE_POINTS = {1: P1, 2: P2, 3: P3}


def restore(client: RobotClient, ledger: PointLedger) -> None:
    """'Restore all': create every point the controller may not hold, record the outcome."""
    report = staged_upload(client, ledger.needing_upload())
    assert report.all_ok, (report.aborted, report.failed)
    apply_upload(ledger, report)
    assert not ledger.needing_upload()


def ledger_of(points: Mapping[int, tuple[float, ...]]) -> PointLedger:
    return PointLedger(make_point(pid, f"P{pid}", pose) for pid, pose in points.items())


def along(pose: tuple[float, ...], a: tuple[float, ...], b: tuple[float, ...]) -> float:
    """Where ``pose`` lies on the line a -> b: 0 at a, 1 at b (projection)."""
    pa, pb, p = np.array(a[:3]), np.array(b[:3]), np.array(pose[:3])
    d = pb - pa
    return float(np.dot(p - pa, d) / np.dot(d, d))


def held_points(sim: Any) -> dict[int, tuple[float, ...]]:
    """The temp points the simulated controller holds now."""
    return dict(sim.state().points)


def assert_controller_holds(sim: Any, ledger: PointLedger) -> None:
    held = held_points(sim)
    assert sorted(held) == sorted(ledger.ids())
    for point in ledger:
        assert_pose_at(held[point.id], point.xyzabc, f"P{point.id} on the controller")


# A tilted arc for geometry checks: start at 0 deg, middle at 70, end at 140.
ARC_CENTRE = np.array([520.0, 0.0, 440.0])
ARC_RADIUS = 35.0
ARC_U = np.array([0.0, -1.0, 0.0])  # centre -> start
ARC_V = np.array([1.0, 0.0, 1.0]) / math.sqrt(2.0)  # a tilted plane, not an axis plane
ARC_NORMAL = np.cross(ARC_U, ARC_V)
ARC_VIA_DEG, ARC_END_DEG = 70.0, 140.0
ARC_SPEED = 50.0  # mm/s: ~0.5 mm between 100 Hz trajectory samples


def arc_point(deg: float) -> tuple[float, ...]:
    t = math.radians(deg)
    xyz = ARC_CENTRE + ARC_RADIUS * (math.cos(t) * ARC_U + math.sin(t) * ARC_V)
    return (*(float(v) for v in xyz), *TOOL_DOWN)

"""The controller's temp points are never assumed: what a plan run does about it.

A temp point cannot be read back from the controller (PROTOCOL.md section 7), the controller
forgets them all when it restarts, and any other Modbus client may overwrite one at any time.
So a run that trusted "uploaded earlier" could send the arm to somebody else's pose. The
:class:`PointGuard` makes that impossible to happen silently:

1. **Upload up front**: before the first move, every point the plan uses is created from the
   host's copy unless *this process* created it since the last restart check
   (:meth:`PointGuard.ensure`); a refused point stops the run before anything moves.
2. **Restart check**: a random token in a spare GV (the restart canary, GV99 by default, as the
   GUI's link uses) is written after the upload and read back before each segment; a changed
   token means the controller restarted, so nothing uploaded before counts
   (:meth:`PointGuard.check_restart`).
3. **Re-create right before each move**: the segment's end (and middle) points are created
   again from the host's copy immediately before its move command
   (:meth:`PointGuard.before_segment`), so an overwrite made earlier is undone.
4. **Verify the arrival**: after the move reports done, the pose is read and compared with the
   host's copy of the end point (:meth:`PointGuard.after_segment`); a mismatch beyond
   :data:`ARRIVAL_TOLERANCE_MM` stops the run with :class:`PointMismatch`.

Residual window, stated honestly: another client that overwrites a point in the few
milliseconds between our create-point and our move command still moves the arm there once;
step 4 then stops the run at that segment's end, before any further motion. An arc's middle
point is not verified (the arm passes it, it does not stop there). With ``refresh=False``
(the CLI's ``--no-upload``) steps 1-3 are the operator's responsibility; step 4 still runs.
"""

from __future__ import annotations

import math
import random
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from typing import Protocol

from app.errors import TeachPadError
from app.models import CommandResult, Pose
from app.points.point import TempPoint
from app.protocol.registers import CANARY_GV

#: Largest distance (mm) between the pose after a segment and the host's end point.
ARRIVAL_TOLERANCE_MM = 1.0
#: How many of the create-points sent a guard remembers (PointGuard.created): a run with endless
#: loops re-creates its points before every segment, for as long as it runs.
CREATED_KEPT = 1000


class PointMismatch(TeachPadError):
    """The arm did not arrive at the host's copy of a point (overwritten by another tool?).

    Reason ``point_mismatch`` with ``point`` (label), ``got`` / ``want`` ("x, y, z" in mm) and
    ``distance`` (mm, two decimals), all preformatted text."""

    code = "point_mismatch"

    #: what the English message says happens next (a single move says its own)
    RUN_STOPPED = "The run is stopped; check the point and the robot before resuming"

    def __init__(self, point: TempPoint, pose: Pose, distance: float, then: str = RUN_STOPPED) -> None:
        self.point = point
        self.pose = pose
        self.distance = distance
        got = ", ".join(f"{v:.2f}" for v in pose.xyzabc[:3])
        want = ", ".join(f"{v:.2f}" for v in point.xyz)
        super().__init__(
            f"the arm stopped at ({got}), {distance:.2f} mm away from {point.label} at ({want}): the "
            "controller's copy of the point differs from this project's (overwritten by another tool?). "
            f"{then}",
            params={"point": point.label, "got": got, "want": want, "distance": f"{distance:.2f}"},
        )


class PointNotCreated(TeachPadError):
    """The controller refused to create a point the plan needs (reason ``point_not_created``,
    ``point`` = its label), or the project has no such point (``point_missing``)."""

    code = "point_not_created"


class GuardClient(Protocol):
    """The part of ``RobotClient`` the guard uses."""

    def create_point(
        self, point_id: int, *, pose: Sequence[float] | None = ..., tool: int = ..., wait: bool = ...
    ) -> CommandResult: ...

    def read_pose(self) -> Pose: ...

    def read_gv(self, n: int, count: int = 1) -> list[float]: ...

    def write_gv(self, n: int, values: Sequence[float]) -> None: ...


class PointGuard:
    """Keeps a run's points honest (see the module docstring). One per process and controller."""

    def __init__(
        self,
        points: Mapping[int, TempPoint],
        *,
        refresh: bool = True,
        verify: bool = True,
        canary_gv: int | None = CANARY_GV,
        tolerance_mm: float | None = None,
        rng: random.Random | None = None,
    ) -> None:
        self._points = dict(points)
        self.refresh = refresh
        self.verify = verify
        self._canary_gv = canary_gv
        self._tolerance = ARRIVAL_TOLERANCE_MM if tolerance_mm is None else tolerance_mm
        self._rng = rng or random.SystemRandom()
        self._token: float | None = None
        self._uploaded: set[int] = set()  # created by this process since the last restart check
        self.restarts = 0  # restarts noticed
        # the create-points sent, in order (for reports and tests): the last CREATED_KEPT of them,
        # an endless run re-creates points before every segment
        self._created: deque[int] = deque(maxlen=CREATED_KEPT)

    @property
    def created(self) -> list[int]:
        """The last :data:`CREATED_KEPT` create-points sent, oldest first."""
        return list(self._created)

    @property
    def uploaded(self) -> frozenset[int]:
        return frozenset(self._uploaded)

    def point(self, point_id: int) -> TempPoint:
        try:
            return self._points[point_id]
        except KeyError:
            raise PointNotCreated(
                f"the project has no point P{point_id}",
                code="point_missing",
                params={"point": f"P{point_id}"},
            ) from None

    # --- restart check
    def arm(self, client: GuardClient) -> None:
        """Write a fresh canary token (nothing uploaded before counts from here on)."""
        if self._canary_gv is None:
            return
        token = float(self._rng.randint(1, 1 << 23))  # nonzero, exact in float32
        client.write_gv(self._canary_gv, [token])
        self._token = token

    def check_restart(self, client: GuardClient) -> bool:
        """True (and forget what was uploaded) when the controller restarted since :meth:`arm`."""
        if self._canary_gv is None or self._token is None:
            return False
        value = client.read_gv(self._canary_gv)[0]
        if value == self._token:
            return False
        self.restarts += 1
        self._uploaded.clear()
        self.arm(client)
        return True

    # --- uploads
    def _create(self, client: GuardClient, point_id: int) -> None:
        point = self.point(point_id)
        result = client.create_point(point.id, pose=point.xyzabc, tool=point.tool, wait=True)
        self._created.append(point.id)
        if not result.ok:
            reason = result.message or (result.status.text if result.status is not None else "failed")
            raise PointNotCreated(
                f"the controller refused to create {point.label}: {reason}",
                params={"point": point.label, "cause": reason},
            )
        self._uploaded.add(point.id)

    def ensure(self, client: GuardClient, point_ids: Iterable[int]) -> list[int]:
        """Create the points this process has not created since the last restart check; arms
        the canary first when it is not armed. Returns the ids created."""
        if not self.refresh:
            return []
        if self._token is None:
            self.arm(client)
        else:
            self.check_restart(client)
        done: list[int] = []
        for point_id in dict.fromkeys(point_ids):
            if point_id not in self._uploaded:
                self._create(client, point_id)
                done.append(point_id)
        return done

    # --- around each segment (the runner calls these)
    def before_segment(self, client: GuardClient, point_ids: Sequence[int]) -> None:
        """Restart check, then re-create the segment's points from the host's copy."""
        if not self.refresh:
            return
        self.check_restart(client)
        for point_id in dict.fromkeys(point_ids):
            self._create(client, point_id)

    def after_segment(self, client: GuardClient, end_id: int) -> None:
        """Compare the arrival pose with the host's end point; :class:`PointMismatch` if off."""
        if not self.verify:
            return
        mismatch = self.check_arrival(client.read_pose(), end_id)
        if mismatch is not None:
            raise mismatch

    def check_arrival(self, pose: Pose, end_id: int) -> PointMismatch | None:
        """The mismatch of ``pose`` with the host's end point, or None (for callers that have
        the pose already, e.g. the GUI's step-by-step run with the link's latest pose)."""
        point = self.point(end_id)
        distance = math.dist(pose.xyzabc[:3], point.xyz)
        return None if distance <= self._tolerance else PointMismatch(point, pose, distance)

"""Where a point added by hand ("Add", not "Teach") starts: the robot's current pose when the
link is fresh, otherwise a copy of a point nearby, otherwise zeros. Never a stale pose: a pose
is the robot's only while the link is fresh (:attr:`app.link.state.RobotState.fresh`), and the
caller tells the operator when the pose is not from the controller."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from app.models import Pose
from app.points.ledger import PointLedger
from app.protocol.registers import TOOL_NONE

Pose6 = tuple[float, float, float, float, float, float]
ZERO_POSE: Pose6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


class PoseSource(enum.Enum):
    """Where a new point's pose came from."""

    LIVE = "live"  # the robot's current pose (the link is fresh)
    COPIED = "copied"  # another point's pose: no live pose
    ZEROS = "zeros"  # no live pose and no point to copy


@dataclass(frozen=True)
class NewPointPose:
    pose: Pose6
    tool: int
    source: PoseSource
    copied_from: int | None = None  # the id of the point copied (COPIED)

    @property
    def live(self) -> bool:
        return self.source is PoseSource.LIVE


def new_point_pose(
    fresh: bool, pose: Pose | None, ledger: PointLedger, near_row: int | None = None, tool: int = TOOL_NONE
) -> NewPointPose:
    """The robot's pose (with ``tool``, the teach tool) when ``fresh`` and known; else the pose
    and tool of the point at ``near_row`` (the selection; default: the last point); else zeros."""
    if fresh and pose is not None:
        return NewPointPose(pose.xyzabc, tool, PoseSource.LIVE)
    points = list(ledger)
    if points:
        row = near_row if near_row is not None and 0 <= near_row < len(points) else len(points) - 1
        near = points[row]
        return NewPointPose(near.xyzabc, near.tool, PoseSource.COPIED, near.id)
    return NewPointPose(ZERO_POSE, TOOL_NONE, PoseSource.ZEROS)


__all__ = ["ZERO_POSE", "NewPointPose", "PoseSource", "new_point_pose"]

"""Where the arm is against where it was or was sent: the pose tests of command completion.

:func:`pose_moved` (motion seen: the tracker, the motion part, the CLI) and :func:`arrived` (a
move whose GV291 never changed, still at the target this host sent, ended there; see
:class:`~app.link.tracker.CommandTracker`).
"""

from __future__ import annotations

import math

from app.models import Pose

__all__ = ["ARRIVAL_TOLERANCE", "ARRIVAL_TOLERANCE_DEG", "POSE_EPSILON", "arrived", "pose_moved"]

# A pose component that changed by more than this (mm or degrees) counts as motion.
POSE_EPSILON = 1e-3
# A move is at its end point when the TCP is this close (mm) to the X Y Z the host sent for it.
ARRIVAL_TOLERANCE = 0.5
ARRIVAL_TOLERANCE_DEG = 0.05  # the same for a joint step's joint angles (degrees)


def _pose_values(pose: Pose) -> tuple[float, ...]:
    return pose.xyzabc + tuple(pose.ext) + tuple(pose.joints or ())


def pose_moved(a: Pose, b: Pose) -> bool:
    va, vb = _pose_values(a), _pose_values(b)
    return len(va) != len(vb) or any(abs(x - y) > POSE_EPSILON for x, y in zip(va, vb, strict=True))


def arrived(
    pose: Pose,
    target: tuple[float, float, float] | None,
    target_joints: tuple[float, ...] | None,
    target_ext: tuple[float, ...] | None,
) -> bool:
    """The arm stands where this host sent it: the end point's X Y Z (within
    ARRIVAL_TOLERANCE mm) or a joint step's J1..J6 (within ARRIVAL_TOLERANCE_DEG); the
    external axes too when ``target_ext`` is given."""
    if target_ext is not None and not all(
        abs(e - t) <= ARRIVAL_TOLERANCE for e, t in zip(pose.ext, target_ext, strict=False)
    ):
        return False
    if target is not None:
        return math.dist(pose.xyzabc[:3], target) <= ARRIVAL_TOLERANCE
    if target_joints is not None and pose.joints:
        return all(
            abs(q - t) <= ARRIVAL_TOLERANCE_DEG for q, t in zip(pose.joints, target_joints, strict=False)
        )
    return False

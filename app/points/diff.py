"""Two lists of points compared: what was added, removed, moved (and how far), and re-tooled.

``teachpad-cli points diff A B`` and the GUI's *Compare with…* both use :func:`diff_points` on
the points of a project or a points CSV (:func:`load_points_source`). Points are matched by id:

* **added**: the id is only in B; **removed**: only in A;
* **moved**: in both, and the position moved more than ``tol_mm`` (the straight distance, mm)
  or the orientation turned more than ``tol_deg`` (the angle of the one rotation taking A's
  orientation to B's: A = 179.9° and A = -179.9° are 0.2° apart, not 359.8°);
* **tool**: in both, within the tolerances, but another tool frame (the controller stores it
  with the pose, so a move to it goes elsewhere).

Names, notes and external axes (which the controller does not store) are not compared; a point
within both tolerances with the same tool counts as the same.
"""

from __future__ import annotations

import enum
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from app.geometry import abc_to_matrix
from app.points.fields import DEFAULT_LIMITS, PointLimits
from app.points.point import TempPoint
from app.points.project import load_project, read_points_csv

__all__ = [
    "DEFAULT_TOL_DEG",
    "DEFAULT_TOL_MM",
    "ChangeKind",
    "PointChange",
    "PointsDiff",
    "diff_points",
    "is_csv",
    "load_points_source",
    "orientation_change_deg",
    "signed_mm",
]

DEFAULT_TOL_MM: Final = 0.1
DEFAULT_TOL_DEG: Final = 0.1


class ChangeKind(enum.Enum):
    ADDED = "added"
    REMOVED = "removed"
    MOVED = "moved"
    TOOL = "tool"


@dataclass(frozen=True)
class PointChange:
    """One point that differs. ``before`` / ``after``: the point in A / in B (None when it is not
    there); ``distance_mm`` and ``rotation_deg`` are 0 for added and removed points."""

    kind: ChangeKind
    before: TempPoint | None
    after: TempPoint | None
    distance_mm: float = 0.0
    rotation_deg: float = 0.0

    @property
    def point(self) -> TempPoint:
        found = self.after if self.after is not None else self.before
        assert found is not None
        return found

    @property
    def point_id(self) -> int:
        return self.point.id

    @property
    def delta(self) -> tuple[float, float, float]:
        """B − A in x, y, z (mm); zeros unless the point is in both."""
        if self.before is None or self.after is None:
            return (0.0, 0.0, 0.0)
        b, a = self.before, self.after
        return (a.x - b.x, a.y - b.y, a.z - b.z)

    @property
    def tool_changed(self) -> bool:
        return self.before is not None and self.after is not None and self.before.tool != self.after.tool


@dataclass(frozen=True)
class PointsDiff:
    """The differences from A to B, ordered by point id, and how many points are the same."""

    changes: tuple[PointChange, ...]
    same: int
    count_a: int
    count_b: int
    tol_mm: float
    tol_deg: float

    @property
    def differ(self) -> bool:
        return bool(self.changes)

    def of_kind(self, kind: ChangeKind) -> list[PointChange]:
        return [c for c in self.changes if c.kind is kind]


def orientation_change_deg(a: TempPoint, b: TempPoint) -> float:
    """The angle (degrees, 0..180) of the rotation from ``a``'s orientation to ``b``'s: the
    same orientation written A = 180 and A = -180 is 0 apart. atan2 keeps small angles exact
    (an acos of the trace loses them near 0)."""
    rel = abc_to_matrix(a.a, a.b, a.c).T @ abc_to_matrix(b.a, b.b, b.c)
    sine = 0.5 * math.hypot(
        float(rel[2, 1] - rel[1, 2]), float(rel[0, 2] - rel[2, 0]), float(rel[1, 0] - rel[0, 1])
    )
    cosine = 0.5 * (float(rel[0, 0] + rel[1, 1] + rel[2, 2]) - 1.0)
    return math.degrees(math.atan2(sine, cosine))


def _check_tolerance(name: str, value: float) -> None:
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a number >= 0, got {value!r}")


def diff_points(
    a: Sequence[TempPoint],
    b: Sequence[TempPoint],
    *,
    tol_mm: float = DEFAULT_TOL_MM,
    tol_deg: float = DEFAULT_TOL_DEG,
) -> PointsDiff:
    """What changed from ``a`` to ``b`` (see the module docstring). A distance or angle equal
    to its tolerance is within it; ``ValueError`` for a negative or non-finite tolerance."""
    _check_tolerance("the distance tolerance", tol_mm)
    _check_tolerance("the angle tolerance", tol_deg)
    in_a = {p.id: p for p in a}
    in_b = {p.id: p for p in b}
    changes: list[PointChange] = []
    same = 0
    for point_id in sorted(in_a.keys() | in_b.keys()):
        before, after = in_a.get(point_id), in_b.get(point_id)
        if before is None:
            changes.append(PointChange(ChangeKind.ADDED, None, after))
        elif after is None:
            changes.append(PointChange(ChangeKind.REMOVED, before, None))
        else:
            change = _compared(before, after, tol_mm, tol_deg)
            if change is None:
                same += 1
            else:
                changes.append(change)
    return PointsDiff(tuple(changes), same, len(a), len(b), tol_mm, tol_deg)


def _compared(before: TempPoint, after: TempPoint, tol_mm: float, tol_deg: float) -> PointChange | None:
    distance = math.dist(before.xyz, after.xyz)
    rotation = orientation_change_deg(before, after)
    if distance > tol_mm or rotation > tol_deg:
        return PointChange(ChangeKind.MOVED, before, after, distance, rotation)
    if before.tool != after.tool:
        return PointChange(ChangeKind.TOOL, before, after, distance, rotation)
    return None


def signed_mm(value: float) -> str:
    """``+0.200`` / ``-0.050`` / ``+0.000`` (never ``-0.000``): a coordinate's change in mm."""
    return f"{round(value, 3) or 0.0:+.3f}"


def is_csv(path: str | os.PathLike[str]) -> bool:
    return Path(path).suffix.lower() == ".csv"


def load_points_source(path: str | os.PathLike[str], limits: PointLimits = DEFAULT_LIMITS) -> list[TempPoint]:
    """The points of a points CSV (a name ending ``.csv``) or of a project (any other name).

    Raises what loading raises: :class:`~app.points.point.FileFormatError` (an
    :class:`~app.errors.InvalidInput`) for a malformed file, ``OSError`` for one that cannot be read."""
    if is_csv(path):
        return read_points_csv(path, limits)
    return list(load_project(path, limits).ledger)

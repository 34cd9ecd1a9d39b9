"""Does the robot model describe the arm the controller drives?

The controller reports its joint angles and its TCP pose in the same read (GV250-GV255 beside the
pose registers). The model's forward kinematics of those joints must land on that pose: a model
with another link length (a longer forearm, another arm's profile) puts its TCP elsewhere, and its
reach checks -- which block or allow a plan's run -- are then checks of another arm.
:func:`compare_model` measures how far apart the two are (position in mm, orientation as the
angle of the rotation between them, so the A B C convention's singularities do not matter);
beyond :data:`MODEL_TOLERANCE_MM` or :data:`MODEL_TOLERANCE_DEG` the model disagrees, and
:func:`model_issue` is the whole-plan error the planner's checks show (it blocks Run: reach
verdicts from a model the controller contradicts cannot be trusted either way, and the fix is
an engineer loading the right model). A controller that reports no joint angles cannot be
compared (None).

The tolerances are well above float32 rounding of a pose (hundredths of a millimetre) and the
skew between the joint and pose registers of one read, and well below a wrong link (tens of mm).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from app.geometry import pose_to_transform
from app.plan.checks import IssueCode, PlanIssue
from app.plan.issue_kind import IssueKind

if TYPE_CHECKING:
    import numpy as np

    from app.view3d.kinematics import ArmModel
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np

__all__ = ["MODEL_TOLERANCE_DEG", "MODEL_TOLERANCE_MM", "ModelAgreement", "compare_model", "model_issue"]

MODEL_TOLERANCE_MM: Final = 5.0  # TCP position: FK of the controller's joints vs its pose
MODEL_TOLERANCE_DEG: Final = 1.0  # TCP orientation: the angle of the rotation between them


@dataclass(frozen=True)
class ModelAgreement:
    """How far the model's TCP (FK of the controller's joints) is from the controller's pose."""

    model: str  # the robot model profile's name
    distance_mm: float
    angle_deg: float

    @property
    def position_off(self) -> bool:
        return self.distance_mm > MODEL_TOLERANCE_MM

    @property
    def orientation_off(self) -> bool:
        return self.angle_deg > MODEL_TOLERANCE_DEG

    @property
    def agrees(self) -> bool:
        return not (self.position_off or self.orientation_off)

    def differs_from(self, other: ModelAgreement | None) -> bool:
        """Worth saying again: another verdict, model, or a disagreement that moved by more
        than a tolerance (a small drift while the arm moves is not news)."""
        if other is None or other.agrees != self.agrees or other.model != self.model:
            return True
        if self.agrees:
            return False
        return (
            abs(other.distance_mm - self.distance_mm) >= MODEL_TOLERANCE_MM
            or abs(other.angle_deg - self.angle_deg) >= MODEL_TOLERANCE_DEG
        )

    def describe(self) -> str:
        """English, for logs and the plan check's message."""
        parts = []
        if self.position_off:
            parts.append(f"{self.distance_mm:.0f} mm")
        if self.orientation_off:
            parts.append(f"{self.angle_deg:.1f}°")
        if not parts:
            return f"the robot model '{self.model}' agrees with the controller's pose"
        return (
            f"the robot model '{self.model}' disagrees with the controller's pose by "
            f"{' and '.join(parts)}: reach checks may be wrong"
        )


def compare_model(model: ArmModel, joints: Sequence[float], pose: Sequence[float]) -> ModelAgreement | None:
    """FK of ``joints`` (J1.., degrees) against ``pose`` (X Y Z A B C); None when they cannot be
    compared (fewer joints than the model has, a value that is not finite)."""
    dof = model.dof
    values = [float(v) for v in joints[:dof]] + [float(v) for v in pose[:6]]
    if len(joints) < dof or len(pose) < 6 or not all(math.isfinite(v) for v in values):
        return None
    flange = model.forward(values[:dof])
    target = pose_to_transform(*values[dof:])
    distance = float(np.linalg.norm(flange[:3, 3] - target[:3, 3]))
    turn = flange[:3, :3].T @ target[:3, :3]
    cosine = max(-1.0, min(1.0, (float(np.trace(turn)) - 1.0) / 2.0))
    if not math.isfinite(distance):
        return None
    return ModelAgreement(model.profile.name, distance, math.degrees(math.acos(cosine)))


def model_issue(agreement: ModelAgreement) -> PlanIssue:
    """The whole-plan error of a model that disagrees with the controller (blocks Run)."""
    return PlanIssue(
        None,
        IssueKind.ERROR,
        IssueCode.MODEL_DISAGREES,
        agreement.describe(),
        args={
            "model": agreement.model,
            "distance": round(agreement.distance_mm),
            "angle": round(agreement.angle_deg, 1),
            "position_off": agreement.position_off,
            "orientation_off": agreement.orientation_off,
        },
    )

"""Kinematics of a :class:`~app.view3d.profile.RobotProfile`: forward (every link frame, the
arm's polyline for drawing) and numerical inverse kinematics seeded from the last solution.

IK is damped least squares (as the simulator's). Its result says how it ended: a solution
within the limits, one that passes a joint limit, or none (the target is out of reach).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from app.geometry import pose_to_transform
from app.view3d.profile import RobotProfile, joints_array

Matrix = NDArray[np.float64]
FloatArray = NDArray[np.float64]

IK_POS_TOL_MM: Final = 0.01
IK_ROT_TOL_RAD: Final = 1e-5
IK_MAX_ITER: Final = 80
ROT_WEIGHT_MM: Final = 500.0  # mm per radian when mixing position and orientation errors
MAX_STEP_RAD: Final = 0.2


class Reach(enum.Enum):
    OK = "ok"
    JOINT_LIMIT = "joint-limit"  # reachable only past a joint limit
    UNREACHABLE = "unreachable"  # no solution found


@dataclass(frozen=True)
class IKResult:
    joints: FloatArray | None  # degrees; the closest attempt when UNREACHABLE is not returned
    reach: Reach

    @property
    def ok(self) -> bool:
        return self.reach is Reach.OK


def _dh(theta: float, d: float, a: float, alpha: float) -> Matrix:
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d], [0.0, 0.0, 0.0, 1.0]])


class ArmModel:
    """FK / IK of one profile (precomputes the constant parts)."""

    def __init__(self, profile: RobotProfile) -> None:
        self.profile = profile
        self._rows = [(math.radians(j.offset_deg), j.d, j.a, math.radians(j.alpha_deg))
                      for j in profile.joints]
        self._base = profile.base_transform
        self._flange = profile.flange_transform
        self._limits = profile.limits
        self.home = np.asarray(profile.home_deg, dtype=np.float64)

    @property
    def dof(self) -> int:
        return self.profile.dof

    def frames(self, q_deg: Sequence[float] | FloatArray) -> list[Matrix]:
        """World transforms: base, after joint 1 .. after joint n, flange (n + 2 frames)."""
        q = joints_array(q_deg, self.dof)
        t = self._base.copy()
        out = [t]
        for qi, (off, d, a, alpha) in zip(q, self._rows, strict=True):
            t = t @ _dh(math.radians(float(qi)) + off, d, a, alpha)
            out.append(t)
        out.append(t @ self._flange)
        return out

    def forward(self, q_deg: Sequence[float] | FloatArray) -> Matrix:
        """4x4 flange transform in the world."""
        return self.frames(q_deg)[-1]

    def link_points(self, q_deg: Sequence[float] | FloatArray) -> FloatArray:
        """(m, 3) polyline of the arm from the base to the flange: for each DH link the point
        after its ``d`` (along the joint axis) and after its ``a`` — the arm's real shape."""
        q = joints_array(q_deg, self.dof)
        t = self._base.copy()
        pts = [t[:3, 3].copy()]
        for qi, (off, d, a, alpha) in zip(q, self._rows, strict=True):
            theta = math.radians(float(qi)) + off
            if d:
                pts.append((t @ np.array([0.0, 0.0, d, 1.0]))[:3])
            t = t @ _dh(theta, d, a, alpha)
            if a:
                pts.append(t[:3, 3].copy())
        flange = (t @ self._flange)[:3, 3]
        if float(np.linalg.norm(flange - pts[-1])) > 1e-9:
            pts.append(flange)
        return np.asarray(pts, dtype=np.float64)

    def joint_points(self, q_deg: Sequence[float] | FloatArray) -> FloatArray:
        """(n + 1, 3) origins of the joint frames (base included) and the flange."""
        frames = self.frames(q_deg)
        return np.asarray([f[:3, 3] for f in frames[:-2]] + [frames[-1][:3, 3]], dtype=np.float64)

    def within_limits(self, q_deg: FloatArray, margin: float = 1e-6) -> bool:
        lo, hi = self._limits[:, 0] - margin, self._limits[:, 1] + margin
        return bool(np.all(q_deg >= lo) and np.all(q_deg <= hi))

    def _wrap_into_limits(self, q_deg: FloatArray) -> FloatArray:
        """Each angle moved by whole turns into its limits where that is possible."""
        out = q_deg.copy()
        for i, (lo, hi) in enumerate(self._limits):
            v = float(out[i])
            for turn in (0.0, -360.0, 360.0):
                if lo <= v + turn <= hi:
                    out[i] = v + turn
                    break
        return out

    def _jacobian(self, frames: list[Matrix]) -> Matrix:
        pe = frames[-1][:3, 3]
        jac = np.empty((6, self.dof))
        for i in range(self.dof):
            z = frames[i][:3, 2]
            jac[:3, i] = np.cross(z, pe - frames[i][:3, 3])
            jac[3:, i] = z
        return jac

    def inverse(self, target: Matrix, seed_deg: Sequence[float] | FloatArray | None = None, *,
                max_iter: int = IK_MAX_ITER, position_only: bool = False) -> IKResult:
        """Joints reaching the 4x4 ``target`` from ``seed_deg`` (the home joints if None)."""
        p_target = target[:3, 3]
        if float(np.linalg.norm(p_target - self._base[:3, 3])) > self.profile.reach + IK_POS_TOL_MM:
            return IKResult(None, Reach.UNREACHABLE)
        seed = self.home if seed_deg is None else joints_array(seed_deg, self.dof)
        q = np.radians(seed)
        r_target = target[:3, :3]
        rows = 3 if position_only else 6
        lam2 = 0.25
        for _ in range(max_iter + 1):
            q_deg = np.degrees(q)
            frames = self.frames(q_deg)
            t = frames[-1]
            dp = p_target - t[:3, 3]
            dw = np.zeros(3) if position_only else _rotation_error(t[:3, :3], r_target)
            if float(np.linalg.norm(dp)) < IK_POS_TOL_MM and float(np.linalg.norm(dw)) < IK_ROT_TOL_RAD:
                solution = self._wrap_into_limits(np.asarray(q_deg, dtype=np.float64))
                reach = Reach.OK if self.within_limits(solution) else Reach.JOINT_LIMIT
                return IKResult(solution, reach)
            jac = self._jacobian(frames)[:rows]
            err = np.concatenate([dp, dw * ROT_WEIGHT_MM])[:rows]
            if rows == 6:
                jac[3:] *= ROT_WEIGHT_MM
            dq = jac.T @ np.linalg.solve(jac @ jac.T + lam2 * np.eye(rows), err)
            step = float(np.max(np.abs(dq)))
            if step > MAX_STEP_RAD:
                dq *= MAX_STEP_RAD / step
            q = q + dq
        return IKResult(None, Reach.UNREACHABLE)

    def inverse_pose(self, pose: Sequence[float], seed_deg: Sequence[float] | FloatArray | None = None,
                     **kwargs: object) -> IKResult:
        """IK of an X Y Z A B C pose."""
        x, y, z, a, b, c = (float(v) for v in pose[:6])
        return self.inverse(pose_to_transform(x, y, z, a, b, c), seed_deg, **kwargs)  # type: ignore[arg-type]


def _rotation_error(r_current: Matrix, r_target: Matrix) -> FloatArray:
    """Rotation vector (rad, world frame) taking r_current to r_target."""
    rel = r_target @ r_current.T
    cos = max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0))
    angle = math.acos(cos)
    vee = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    if angle < 1e-9:
        return np.asarray(vee / 2.0, dtype=np.float64)
    if math.pi - angle < 1e-6:
        m = (rel + np.eye(3)) / 2.0
        axis = m[:, int(np.argmax(np.diag(m)))]
        return np.asarray(axis / np.linalg.norm(axis) * angle, dtype=np.float64)
    return np.asarray(vee * (angle / (2.0 * math.sin(angle))), dtype=np.float64)


class ArmTracker:
    """The arm to draw from what the controller reports: its joints when known, else the
    pose through IK seeded from the last solution (an *estimate*)."""

    def __init__(self, model: ArmModel) -> None:
        self.model = model
        self.joints: FloatArray = model.home.copy()
        self.estimated = True
        self.reach = Reach.OK

    def from_joints(self, joints: Sequence[float]) -> FloatArray:
        self.joints = joints_array(joints, self.model.dof).copy()
        self.estimated = False
        self.reach = Reach.OK if self.model.within_limits(self.joints) else Reach.JOINT_LIMIT
        return self.joints

    def from_pose(self, pose: Sequence[float]) -> FloatArray:
        result = self.model.inverse_pose(pose, self.joints)
        if result.joints is None:
            result = self.model.inverse_pose(pose, None)  # one more try from home
        self.estimated = True
        self.reach = result.reach
        if result.joints is not None:
            self.joints = result.joints
        return self.joints

"""Kinematics of a :class:`~app.view3d.profile.RobotProfile`: forward (every link frame, the
arm's polyline for drawing) and numerical inverse kinematics seeded from the last solution.

IK is damped least squares (as the simulator's). Its result says how it ended: a solution
within the limits, one that passes a joint limit, or none (the target is out of reach).

Separate from the simulator's kinematics (:mod:`app.sim.kinematics`) on purpose: that one is the
controller's model, this one TeachPad's; the simulator checks ours independently (the model's
agreement with the controller's joints and pose, the reach checks), so neither imports the other.
"""

from __future__ import annotations

import enum
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from app.geometry import pose_to_transform
from app.view3d.profile import RobotProfile, joints_array

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np
from app.lazy_numpy import FloatArray, Matrix

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
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


class ArmModel:
    """FK / IK of one profile (precomputes the constant parts)."""

    def __init__(self, profile: RobotProfile) -> None:
        self.profile = profile
        self._rows = [
            (math.radians(j.offset_deg), j.d, j.a, math.radians(j.alpha_deg)) for j in profile.joints
        ]
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

    def inverse(
        self,
        target: Matrix,
        seed_deg: Sequence[float] | FloatArray | None = None,
        *,
        max_iter: int = IK_MAX_ITER,
        position_only: bool = False,
    ) -> IKResult:
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

    def inverse_pose(
        self, pose: Sequence[float], seed_deg: Sequence[float] | FloatArray | None = None, **kwargs: object
    ) -> IKResult:
        """IK of an X Y Z A B C pose."""
        x, y, z, a, b, c = (float(v) for v in pose[:6])
        return self.inverse(pose_to_transform(x, y, z, a, b, c), seed_deg, **kwargs)  # type: ignore[arg-type]

    # --- batched (one numpy pass for many targets: reachability of thousands of points) -----
    def _frames_batch(self, q_deg: FloatArray) -> list[FloatArray]:
        """(n, 4, 4) world transforms: base, after each joint, flange (n + 2 entries)."""
        n = q_deg.shape[0]
        t = np.broadcast_to(self._base, (n, 4, 4)).copy()
        out = [t]
        for i, (off, d, a, alpha) in enumerate(self._rows):
            theta = np.radians(q_deg[:, i]) + off
            ct, st = np.cos(theta), np.sin(theta)
            ca, sa = math.cos(alpha), math.sin(alpha)
            dh = np.zeros((n, 4, 4))
            dh[:, 0, 0], dh[:, 0, 1], dh[:, 0, 2], dh[:, 0, 3] = ct, -st * ca, st * sa, a * ct
            dh[:, 1, 0], dh[:, 1, 1], dh[:, 1, 2], dh[:, 1, 3] = st, ct * ca, -ct * sa, a * st
            dh[:, 2, 1], dh[:, 2, 2], dh[:, 2, 3], dh[:, 3, 3] = sa, ca, d, 1.0
            t = t @ dh
            out.append(t)
        out.append(t @ self._flange)
        return out

    def pointing_seeds(self, targets: FloatArray) -> FloatArray:
        """Home joints with joint 1 turned towards each target (a good first guess)."""
        seeds = np.tile(self.home, (targets.shape[0], 1))
        local = (targets[:, :3, 3] - self._base[:3, 3]) @ self._base[:3, :3]
        seeds[:, 0] = np.degrees(np.arctan2(local[:, 1], local[:, 0]))
        return seeds

    def inverse_batch(
        self, targets: FloatArray, seeds: FloatArray | None = None, *, max_iter: int = IK_MAX_ITER
    ) -> tuple[FloatArray, list[Reach]]:
        """IK of (n, 4, 4) targets at once: joints (n, dof), NaN rows where unreachable."""
        n = targets.shape[0]
        first = self.pointing_seeds(targets) if seeds is None else np.asarray(seeds, dtype=np.float64)
        q = np.radians(first)
        p_t, r_t = targets[:, :3, 3], targets[:, :3, :3]
        far = np.linalg.norm(p_t - self._base[:3, 3], axis=1) > self.profile.reach + IK_POS_TOL_MM
        done = np.zeros(n, dtype=bool)
        eye = np.eye(6) * 0.25
        for _ in range(max_iter + 1):
            idx = np.flatnonzero(~far & ~done)
            if not len(idx):
                break
            frames = self._frames_batch(np.degrees(q[idx]))
            te = frames[-1]
            dp = p_t[idx] - te[:, :3, 3]
            dw = _rotation_error_batch(te[:, :3, :3], r_t[idx])
            conv = (np.linalg.norm(dp, axis=1) < IK_POS_TOL_MM) & (
                np.linalg.norm(dw, axis=1) < IK_ROT_TOL_RAD
            )
            done[idx[conv]] = True
            keep = ~conv
            if not keep.any():
                break
            pe = te[keep, :3, 3]
            jac = np.empty((int(keep.sum()), 6, self.dof))
            for i in range(self.dof):
                z = frames[i][keep, :3, 2]
                jac[:, :3, i] = np.cross(z, pe - frames[i][keep, :3, 3])
                jac[:, 3:, i] = z * ROT_WEIGHT_MM
            err = np.concatenate([dp[keep], dw[keep] * ROT_WEIGHT_MM], axis=1)
            x = np.linalg.solve(jac @ jac.transpose(0, 2, 1) + eye, err[:, :, None])
            dq = (jac.transpose(0, 2, 1) @ x)[:, :, 0]
            step = np.max(np.abs(dq), axis=1)
            dq *= np.minimum(1.0, MAX_STEP_RAD / np.maximum(step, 1e-12))[:, None]
            q[idx[keep]] += dq
        joints = np.full((n, self.dof), np.nan)
        reach: list[Reach] = []
        for k in range(n):
            if not done[k]:
                reach.append(Reach.UNREACHABLE)
                continue
            solution = self._wrap_into_limits(np.degrees(q[k]))
            joints[k] = solution
            reach.append(Reach.OK if self.within_limits(solution) else Reach.JOINT_LIMIT)
        return joints, reach


def _rotation_error_batch(r_current: FloatArray, r_target: FloatArray) -> FloatArray:
    """(n, 3) rotation vectors taking each r_current to r_target."""
    rel = r_target @ r_current.transpose(0, 2, 1)
    cos = np.clip((np.trace(rel, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    vee = np.stack(
        [rel[:, 2, 1] - rel[:, 1, 2], rel[:, 0, 2] - rel[:, 2, 0], rel[:, 1, 0] - rel[:, 0, 1]], axis=1
    )
    sin = np.sin(angle)
    factor = np.where(angle < 1e-9, 0.5, angle / (2.0 * np.where(sin > 1e-12, sin, 1.0)))
    out = vee * factor[:, None]
    for k in np.flatnonzero(math.pi - angle < 1e-6):  # half turns: the axis from the symmetric part
        out[k] = _rotation_error(r_current[k], r_target[k])
    return np.asarray(out, dtype=np.float64)


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

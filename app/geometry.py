"""Rotation convention of A B C — the one place that owns it (PROTOCOL.md section 7).

A, B, C are fixed-axis X-Y-Z angles in degrees: roll A about the base X axis, then pitch B
about the base Y axis, then yaw C about the base Z axis, so ``R = Rz(C) @ Ry(B) @ Rx(A)``.
Lengths are millimetres.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported by its first use, not with this module (app/lazy_numpy.py)
    from app.lazy_numpy import np
from app.lazy_numpy import Matrix


def rot_x(deg: float) -> Matrix:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(deg: float) -> Matrix:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(deg: float) -> Matrix:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def abc_to_matrix(a: float, b: float, c: float) -> Matrix:
    """Rotation matrix of fixed-axis X-Y-Z angles (degrees)."""
    return rot_z(c) @ rot_y(b) @ rot_x(a)


def matrix_to_abc(r: Matrix) -> tuple[float, float, float]:
    """Inverse of :func:`abc_to_matrix`; B in [-90, 90], A and C in (-180, 180]."""
    sy = -float(r[2, 0])
    sy = max(-1.0, min(1.0, sy))
    b = math.degrees(math.asin(sy))
    if abs(sy) < 1.0 - 1e-9:
        a = math.degrees(math.atan2(float(r[2, 1]), float(r[2, 2])))
        c = math.degrees(math.atan2(float(r[1, 0]), float(r[0, 0])))
    else:  # gimbal lock: put everything in C
        a = 0.0
        c = math.degrees(math.atan2(-float(r[0, 1]), float(r[1, 1])))
    return a, b, c


def pose_to_transform(x: float, y: float, z: float, a: float, b: float, c: float) -> Matrix:
    """4x4 homogeneous transform of an XYZABC pose."""
    t = np.eye(4)
    t[:3, :3] = abc_to_matrix(a, b, c)
    t[:3, 3] = (x, y, z)
    return t


def transform_to_pose(t: Matrix) -> tuple[float, float, float, float, float, float]:
    a, b, c = matrix_to_abc(t[:3, :3])
    return float(t[0, 3]), float(t[1, 3]), float(t[2, 3]), a, b, c


def rotation_angle_deg(r1: Matrix, r2: Matrix) -> float:
    """Angle (degrees) of the rotation taking r1 to r2."""
    rel = r1.T @ r2
    cos = max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0))
    return math.degrees(math.acos(cos))


def slerp_matrix(r1: Matrix, r2: Matrix, s: float) -> Matrix:
    """Rotation interpolated from r1 (s=0) to r2 (s=1) about the fixed relative axis."""
    rel = r1.T @ r2
    angle = math.acos(max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0)))
    if angle < 1e-9:
        return r1.copy()
    if abs(angle - math.pi) < 1e-6:
        # axis from the symmetric part
        m = (rel + np.eye(3)) / 2.0
        axis = m[:, int(np.argmax(np.diag(m)))]
        axis = axis / np.linalg.norm(axis)
    else:
        axis = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
        axis = axis / (2.0 * math.sin(angle))
    th = angle * s
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    step = np.eye(3) + math.sin(th) * k + (1.0 - math.cos(th)) * (k @ k)
    result: Matrix = r1 @ step
    return result

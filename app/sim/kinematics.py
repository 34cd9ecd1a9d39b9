"""Kinematics of the simulated 6-axis arm: DH model, forward and inverse kinematics.

The arm is modelled on a 6 kg payload, 900 mm reach industrial robot (dimensions of the
KUKA KR 6 R900 sixx class): a vertical shoulder offset, a short elbow offset and a spherical
wrist. Standard (distal) Denavit-Hartenberg parameters, lengths in mm, angles in degrees;
joint ``i`` rotates ``theta_i = q_i + offset_i`` about ``z_{i-1}``:

=====  ===========  ======  ======  =========
joint  offset (deg)  d (mm)  a (mm)  alpha (deg)
=====  ===========  ======  ======  =========
J1          0         400      25      -90
J2        -90           0     455        0
J3          0           0      35      -90
J4          0         420       0       90
J5          0           0       0      -90
J6          0          80       0        0
=====  ===========  ======  ======  =========

At all-zero joints the upper arm points straight up and the forearm and flange point along
base +X: the flange is at (525, 0, 890) with the wrist singular (J5 = 0). The TCP is the
flange centre (tool frames are stored with points but carry no geometry in the simulator).
Joint limits are in :data:`JOINT_LIMITS`; the home pose :data:`HOME_JOINTS` is away from every
singularity, with the tool pointing down in front of the robot.

Orientation A B C follows :mod:`app.geometry` (fixed X-Y-Z, ``R = Rz(C) Ry(B) Rx(A)``).
Inverse kinematics is numerical (damped least squares from a seed, usually the current
joints); it fails (returns ``None``) when it does not converge or leaves the joint limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from app.geometry import abc_to_matrix, matrix_to_abc

Vector = NDArray[np.float64]
Matrix = NDArray[np.float64]
Pose6 = tuple[float, float, float, float, float, float]
JointsLike = Sequence[float] | NDArray[np.float64]


@dataclass(frozen=True)
class DHRow:
    offset_deg: float
    d: float
    a: float
    alpha_deg: float


DH_TABLE: Final[tuple[DHRow, ...]] = (
    DHRow(0.0, 400.0, 25.0, -90.0),
    DHRow(-90.0, 0.0, 455.0, 0.0),
    DHRow(0.0, 0.0, 35.0, -90.0),
    DHRow(0.0, 420.0, 0.0, 90.0),
    DHRow(0.0, 0.0, 0.0, -90.0),
    DHRow(0.0, 80.0, 0.0, 0.0),
)

#: (min, max) in degrees for J1..J6.
JOINT_LIMITS: Final[tuple[tuple[float, float], ...]] = (
    (-170.0, 170.0),
    (-100.0, 135.0),
    (-120.0, 156.0),
    (-185.0, 185.0),
    (-120.0, 120.0),
    (-350.0, 350.0),
)
#: External axes J7..J11 (degrees or mm, the simulator does not care): +-1000.
EXT_LIMITS: Final[tuple[float, float]] = (-1000.0, 1000.0)

#: Home: shoulder leaning forward, elbow bent down, wrist pitched so the tool points down.
HOME_JOINTS: Final[tuple[float, ...]] = (0.0, 20.0, 20.0, 0.0, 50.0, 0.0)

IK_POS_TOL_MM: Final = 1e-3
IK_ROT_TOL_RAD: Final = 1e-6
IK_MAX_ITER: Final = 100
_ROT_WEIGHT_MM: Final = 500.0  # mm per radian when mixing position and orientation errors


def _dh_matrix(theta: float, row: DHRow) -> Matrix:
    alpha = math.radians(row.alpha_deg)
    ct, st = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, row.a * ct],
            [st, ct * ca, -ct * sa, row.a * st],
            [0.0, sa, ca, row.d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def _frames(q_deg: JointsLike) -> list[Matrix]:
    """Base-to-frame transforms T0..T6 (T0 is identity)."""
    frames = [np.eye(4)]
    t = np.eye(4)
    for qi, row in zip(q_deg[:6], DH_TABLE, strict=True):
        t = t @ _dh_matrix(math.radians(qi + row.offset_deg), row)
        frames.append(t)
    return frames


def forward(q_deg: JointsLike) -> Matrix:
    """4x4 flange transform of joints J1..J6 (degrees)."""
    return _frames(q_deg)[-1]


def forward_pose(q_deg: JointsLike) -> Pose6:
    """X Y Z A B C of joints J1..J6."""
    return transform_to_pose6(forward(q_deg))


def transform_to_pose6(t: Matrix) -> Pose6:
    a, b, c = matrix_to_abc(t[:3, :3])
    return (float(t[0, 3]), float(t[1, 3]), float(t[2, 3]), a, b, c)


def pose6_to_transform(pose: Sequence[float]) -> Matrix:
    t = np.eye(4)
    t[:3, :3] = abc_to_matrix(pose[3], pose[4], pose[5])
    t[:3, 3] = (pose[0], pose[1], pose[2])
    return t


def jacobian(q_deg: JointsLike) -> Matrix:
    """Geometric Jacobian (6x6): rows vx vy vz (mm/rad) wx wy wz (rad/rad)."""
    frames = _frames(q_deg)
    pe = frames[-1][:3, 3]
    jac = np.zeros((6, 6))
    for i in range(6):
        z = frames[i][:3, 2]
        p = frames[i][:3, 3]
        jac[:3, i] = np.cross(z, pe - p)
        jac[3:, i] = z
    return jac


def rotation_error(r_current: Matrix, r_target: Matrix) -> Vector:
    """Rotation vector (rad, base frame) taking r_current to r_target."""
    rel = r_target @ r_current.T
    cos = max(-1.0, min(1.0, (float(np.trace(rel)) - 1.0) / 2.0))
    angle = math.acos(cos)
    vee = np.array([rel[2, 1] - rel[1, 2], rel[0, 2] - rel[2, 0], rel[1, 0] - rel[0, 1]])
    if angle < 1e-9:
        return vee / 2.0
    if math.pi - angle < 1e-6:
        m = (rel + np.eye(3)) / 2.0
        axis = m[:, int(np.argmax(np.diag(m)))]
        return np.asarray(axis / np.linalg.norm(axis) * angle, dtype=np.float64)
    return np.asarray(vee * (angle / (2.0 * math.sin(angle))), dtype=np.float64)


def within_limits(q_deg: JointsLike, margin: float = 1e-6) -> bool:
    return all(lo - margin <= qi <= hi + margin for qi, (lo, hi) in zip(q_deg[:6], JOINT_LIMITS, strict=True))


def inverse(target: Matrix, seed_deg: JointsLike, *, max_iter: int = IK_MAX_ITER) -> Vector | None:
    """Joints J1..J6 (degrees) reaching ``target`` (4x4), starting from ``seed_deg``.

    Damped least squares; returns None when it does not converge within the tolerances or the
    solution leaves the joint limits.
    """
    q = np.radians(np.asarray(seed_deg[:6], dtype=np.float64))
    p_target = target[:3, 3]
    r_target = target[:3, :3]
    lam = 0.5
    for _ in range(max_iter + 1):
        q_deg: Vector = np.asarray(np.degrees(q), dtype=np.float64)
        t = forward(q_deg)
        dp = p_target - t[:3, 3]
        dw = rotation_error(t[:3, :3], r_target)
        if float(np.linalg.norm(dp)) < IK_POS_TOL_MM and float(np.linalg.norm(dw)) < IK_ROT_TOL_RAD:
            result = np.asarray(q_deg, dtype=np.float64)
            return result if within_limits(result) else None
        err = np.concatenate([dp, dw * _ROT_WEIGHT_MM])
        jac = jacobian(q_deg)
        jac[3:, :] *= _ROT_WEIGHT_MM
        jjt = jac @ jac.T
        # Damping grows near singularities (small singular values), as in Nakamura's DLS.
        dq = jac.T @ np.linalg.solve(jjt + (lam**2) * np.eye(6), err)
        step = float(np.max(np.abs(dq)))
        if step > 0.2:
            dq *= 0.2 / step
        q = q + dq
    return None


def inverse_pose(pose: Sequence[float], seed_deg: JointsLike) -> Vector | None:
    return inverse(pose6_to_transform(pose), seed_deg)

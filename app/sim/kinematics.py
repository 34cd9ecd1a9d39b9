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

Separate from TeachPad's own kinematics (:mod:`app.view3d.kinematics`) on purpose, though both
solve a DH arm: this is the controller's model, the other TeachPad's; kept apart, the simulator
is an independent check of ours (the 3D view's agreement with the controller, the reach checks),
and a mistake in one is not copied into the other. Do not merge them.
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


# Per joint: (offset rad, d, a, cos alpha, sin alpha), computed once (the IK calls this a lot).
_DH_CONST: Final[tuple[tuple[float, float, float, float, float], ...]] = tuple(
    (
        math.radians(r.offset_deg),
        r.d,
        r.a,
        math.cos(math.radians(r.alpha_deg)),
        math.sin(math.radians(r.alpha_deg)),
    )
    for r in DH_TABLE
)


def _frame_stack(q_deg: JointsLike) -> Matrix:
    """Base-to-frame transforms T0..T6 as one (7, 4, 4) array (T0 is identity).

    Plain float arithmetic, one array at the end: the IK calls this for every iteration, and
    numpy's per-call overhead on 4x4 matrices cost more than the arithmetic itself."""
    rows = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]
    chain = [rows]
    for qi, (offset, d, a, ca, sa) in zip(q_deg[:6], _DH_CONST, strict=True):
        theta = math.radians(float(qi)) + offset
        ct, st = math.cos(theta), math.sin(theta)
        # rows @ DH(theta), DH = [[ct, -st ca, st sa, a ct], [st, ct ca, -ct sa, a st],
        #                        [0, sa, ca, d], [0, 0, 0, 1]]
        rows = [
            [
                r0 * ct + r1 * st,
                (r1 * ct - r0 * st) * ca + r2 * sa,
                (r0 * st - r1 * ct) * sa + r2 * ca,
                a * (r0 * ct + r1 * st) + r2 * d + r3,
            ]
            for r0, r1, r2, r3 in rows
        ]
        chain.append(rows)
    return np.array([[*m, [0.0, 0.0, 0.0, 1.0]] for m in chain], dtype=np.float64)


def _frames(q_deg: JointsLike) -> list[Matrix]:
    """Base-to-frame transforms T0..T6 (T0 is identity)."""
    return list(_frame_stack(q_deg))


def forward(q_deg: JointsLike) -> Matrix:
    """4x4 flange transform of joints J1..J6 (degrees)."""
    flange: Matrix = _frame_stack(q_deg)[-1]
    return flange


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
    return _jacobian_of(_frame_stack(q_deg))


def _jacobian_of(frames: Matrix) -> Matrix:
    """The Jacobian from the (7, 4, 4) frames T0..T6 (all six columns at once)."""
    z = frames[:6, :3, 2]
    lever = frames[6, :3, 3] - frames[:6, :3, 3]
    linear = np.empty((6, 3))
    linear[:, 0] = z[:, 1] * lever[:, 2] - z[:, 2] * lever[:, 1]
    linear[:, 1] = z[:, 2] * lever[:, 0] - z[:, 0] * lever[:, 2]
    linear[:, 2] = z[:, 0] * lever[:, 1] - z[:, 1] * lever[:, 0]
    jac = np.empty((6, 6))
    jac[:3, :] = linear.T
    jac[3:, :] = z.T
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
        frames = _frame_stack(q_deg)  # once per iteration: the pose and the Jacobian share them
        t = frames[-1]
        dp = p_target - t[:3, 3]
        dw = rotation_error(t[:3, :3], r_target)
        if float(np.linalg.norm(dp)) < IK_POS_TOL_MM and float(np.linalg.norm(dw)) < IK_ROT_TOL_RAD:
            result = np.asarray(q_deg, dtype=np.float64)
            return result if within_limits(result) else None
        err = np.concatenate([dp, dw * _ROT_WEIGHT_MM])
        jac = _jacobian_of(frames)
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

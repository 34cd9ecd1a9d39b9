"""Motion segments of the simulated arm: joint interpolation, Cartesian line and arc paths, jog steps.

Pure numerics (no controller state): :class:`~app.sim.robot.SimRobot` builds a :class:`Motion`
for each move and calls :meth:`Motion.advance` from its tick; :func:`jog_step` is one tick of a
teach-mode jog.
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Final, Protocol

import numpy as np
from numpy.typing import NDArray

from app.geometry import rot_x, rot_y, rot_z, rotation_angle_deg, slerp_matrix
from app.protocol.enums import TeachFrame
from app.protocol.registers import NUM_ROBOT_AXES
from app.sim import kinematics as kin

Vector = NDArray[np.float64]
Matrix = NDArray[np.float64]
Pose6 = tuple[float, float, float, float, float, float]

MAX_ANGULAR_SPEED: Final = 360.0  # deg/s, orientation change of Cartesian moves
JOG_MAX_LINEAR: Final = 250.0  # mm/s at ratio 100
JOG_MAX_ANGULAR: Final = 30.0  # deg/s at ratio 100 (Cartesian rotation)
JOG_MAX_JOINT: Final = 30.0  # deg/s at ratio 100
CHECK_STEP_MM: Final = 5.0  # path sampling when checking reachability at the start
CHECK_STEP_DEG: Final = 2.0
CHECK_MAX_SAMPLES: Final = 400
COLLINEAR_TOL_MM: Final = 1e-3  # an arc whose middle point is closer than this to the chord line


class MotionKind(enum.Enum):
    STEP = "step"  # function 1 (0x40 / 0x41)
    POINT = "point"  # function 3 (0x42)
    ZERO = "zero"  # go to zero (445)
    PROGRAM = "program"  # built-in program (440 <- 0x01)


@dataclass(frozen=True)
class TraceSample:
    t: float
    pose: Pose6
    joints: tuple[float, ...]


class Arm(Protocol):
    """What a motion moves: the 11 joint values (J1..J6 and the external axes J7..J11)."""

    @property
    def joints(self) -> Vector: ...

    def set_joints(self, joints: Vector) -> None: ...


class Motion:
    """One segment of motion; :meth:`advance` moves the robot and says when it is over."""

    def advance(self, robot: Arm, dt: float) -> bool | None:
        """True: finished; False: still running; None: failed (algorithm error)."""
        raise NotImplementedError


class JointMotion(Motion):
    """Synchronous joint interpolation of all 11 axes (the slowest axis sets the pace)."""

    def __init__(self, start: Vector, target: Vector, speed_deg_s: float) -> None:
        self.start = start.copy()
        self.delta = target - start
        biggest = float(np.max(np.abs(self.delta))) if self.delta.size else 0.0
        self.duration = biggest / speed_deg_s if speed_deg_s > 0 else 0.0
        self.elapsed = 0.0

    def advance(self, robot: Arm, dt: float) -> bool | None:
        self.elapsed += dt
        s = 1.0 if self.duration <= 0 else min(1.0, self.elapsed / self.duration)
        robot.set_joints(self.start + s * self.delta)
        return s >= 1.0


class Geometry:
    """A position path p(s), s in [0, 1]."""

    length: float

    def point(self, s: float) -> Vector:
        raise NotImplementedError


class Line(Geometry):
    def __init__(self, p0: Vector, p1: Vector) -> None:
        self.p0, self.p1 = p0, p1
        self.length = float(np.linalg.norm(p1 - p0))

    def point(self, s: float) -> Vector:
        return np.asarray(self.p0 + s * (self.p1 - self.p0), dtype=np.float64)


class Arc(Geometry):
    """The circle through p1 (start), p2 (middle) and p3 (end), from p1 via p2 to p3."""

    def __init__(self, p1: Vector, p2: Vector, p3: Vector) -> None:
        a, b = p2 - p1, p3 - p1
        normal = np.cross(a, b)
        nn = float(np.linalg.norm(normal))
        chord = float(np.linalg.norm(b))
        if chord < COLLINEAR_TOL_MM or nn / max(chord, 1e-12) < COLLINEAR_TOL_MM:
            raise ValueError("arc points are collinear")
        if float(np.linalg.norm(a)) < COLLINEAR_TOL_MM or float(np.linalg.norm(p3 - p2)) < COLLINEAR_TOL_MM:
            raise ValueError("arc points coincide")
        # circumcentre
        centre = p1 + (np.dot(b, b) * np.cross(normal, a) + np.dot(a, a) * np.cross(b, normal)) / (
            2.0 * nn * nn
        )
        self.centre = centre
        self.radius = float(np.linalg.norm(p1 - centre))
        n = normal / nn
        self.u = (p1 - centre) / self.radius
        self.v = np.cross(n, self.u)
        rel = p3 - centre
        angle = math.atan2(float(np.dot(rel, self.v)), float(np.dot(rel, self.u)))
        self.angle = angle if angle > 0 else angle + 2.0 * math.pi
        self.length = self.radius * self.angle
        rel_mid = p2 - centre
        mid = math.atan2(float(np.dot(rel_mid, self.v)), float(np.dot(rel_mid, self.u)))
        mid = mid if mid > 0 else mid + 2.0 * math.pi
        self.middle_fraction = mid / self.angle  # where along the path the middle point lies

    def point(self, s: float) -> Vector:
        th = s * self.angle
        return np.asarray(
            self.centre + self.radius * (math.cos(th) * self.u + math.sin(th) * self.v), dtype=np.float64
        )


class CartesianMotion(Motion):
    """Linear or circular TCP path at constant speed, orientation slerped, IK every tick.

    With ``via`` = (middle rotation, path fraction at the middle point) the orientation goes
    r0 -> middle -> r1, reaching the middle point's orientation at the middle point.
    """

    def __init__(
        self,
        geometry: Geometry,
        r0: Matrix,
        r1: Matrix,
        speed: float,
        ext0: Vector,
        ext1: Vector,
        via: tuple[Matrix, float] | None = None,
    ) -> None:
        self.geometry = geometry
        self.r0, self.r1 = r0, r1
        self.via = via if via is not None and 0.0 < via[1] < 1.0 else None
        if self.via is not None:
            angle = rotation_angle_deg(r0, self.via[0]) + rotation_angle_deg(self.via[0], r1)
        else:
            angle = rotation_angle_deg(r0, r1)
        ang_speed = min(speed, MAX_ANGULAR_SPEED)
        self.duration = max(geometry.length / speed, angle / ang_speed)
        wanted = max(2, math.ceil(geometry.length / CHECK_STEP_MM), math.ceil(angle / CHECK_STEP_DEG))
        self.samples = int(min(CHECK_MAX_SAMPLES, wanted))
        self.ext0, self.ext1 = ext0, ext1
        self.elapsed = 0.0

    def rotation(self, s: float) -> Matrix:
        if self.via is None:
            return slerp_matrix(self.r0, self.r1, s)
        r_mid, s_mid = self.via
        if s <= s_mid:
            return slerp_matrix(self.r0, r_mid, s / s_mid)
        return slerp_matrix(r_mid, self.r1, (s - s_mid) / (1.0 - s_mid))

    def target(self, s: float) -> Matrix:
        t = np.eye(4)
        t[:3, :3] = self.rotation(s)
        t[:3, 3] = self.geometry.point(s)
        return t

    def check(self, seed: Vector) -> bool:
        """Chained IK along the path: is every sample reachable inside the joint limits?"""
        q = seed[:NUM_ROBOT_AXES]
        for i in range(1, self.samples + 1):
            solved = kin.inverse(self.target(i / self.samples), q)
            if solved is None:
                return False
            q = solved
        return True

    def advance(self, robot: Arm, dt: float) -> bool | None:
        self.elapsed += dt
        s = 1.0 if self.duration <= 0 else min(1.0, self.elapsed / self.duration)
        q = kin.inverse(self.target(s), robot.joints[:NUM_ROBOT_AXES])
        if q is None:
            return None
        joints = robot.joints.copy()
        joints[:NUM_ROBOT_AXES] = q
        joints[NUM_ROBOT_AXES:] = self.ext0 + s * (self.ext1 - self.ext0)
        robot.set_joints(joints)
        return s >= 1.0


def jog_step(
    joints: Vector, flange: Matrix, frame: TeachFrame, axis: int, direction: int, ratio: float, dt: float
) -> Vector | None:
    """The joints after ``dt`` seconds of jogging ``axis`` in ``frame`` at ``ratio`` (0..100).

    A joint jog stops at the joint limit (the joints come back unchanged); a Cartesian jog
    that has no inverse kinematics solution (workspace or joint limit) returns None."""
    frac = ratio / 100.0
    sign = float(direction)
    if frame is TeachFrame.JOINT:
        moved = joints.copy()
        lo, hi = kin.JOINT_LIMITS[axis] if axis < NUM_ROBOT_AXES else kin.EXT_LIMITS
        moved[axis] = min(hi, max(lo, moved[axis] + sign * JOG_MAX_JOINT * frac * dt))
        return moved
    t = flange.copy()
    if axis < 3:
        offset = np.zeros(3)
        offset[axis] = sign * JOG_MAX_LINEAR * frac * dt
        if frame is TeachFrame.TOOL:
            offset = t[:3, :3] @ offset
        t[:3, 3] += offset
    else:
        angle = sign * JOG_MAX_ANGULAR * frac * dt
        rot = (rot_x, rot_y, rot_z)[axis - 3](angle)
        t[:3, :3] = t[:3, :3] @ rot if frame is TeachFrame.TOOL else rot @ t[:3, :3]
    q = kin.inverse(t, joints[:NUM_ROBOT_AXES])
    if q is None:
        return None
    moved = joints.copy()
    moved[:NUM_ROBOT_AXES] = q
    return moved

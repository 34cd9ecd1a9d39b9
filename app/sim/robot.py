"""State machine and motion of the simulated controller (pure Python, no sockets, no threads).

:class:`SimRobot` is driven by explicit :meth:`SimRobot.tick` calls and by one method per
controller command. Each command method returns the GV291 code it leaves behind (or a bool for
the commands that have no status). The server (:mod:`app.sim.server`) owns the registers, the
timing of GV291 publication and the locking; this module owns the behaviour.

Decisions the seed leaves open (see shared/PROTOCOL.md section 7), as implemented here:

* A motion command (0x40/0x41/0x42, go to zero, run program) is refused while another motion
  or program is under way (also while paused) or while teach mode is enabled: GV291 = 1
  (work-mode error) for the functions that report a status, a log line for the others.
* Alarms refuse motion: e-stop 2, servo 3, brake 4, encoder 8, algorithm 10 (teach: 6).
  Raising e-stop, servo or brake stops any motion (GV291 = that code) and disables teach.
* Switching to manual stops any motion (GV291 = 1) and disables teach.
* Stop (441) ends moves, programs, go-to-zero and an active jog; GV291 becomes 0.
* Program state (561) is RUNNING/PAUSED during function 1/3 moves and go-to-zero as well.
* 0x41 applies the J7..J11 offsets (GV236..240) in step with the Cartesian path.
* Orientation of a Cartesian move is interpolated with :func:`app.geometry.slerp_matrix`;
  for an arc the middle point's orientation is not used. Angular speed (deg/s) equals the
  linear speed number (mm/s), capped at :data:`MAX_ANGULAR_SPEED`.
* Speeds must be finite and > 0, else GV291 = 10; they are capped at
  :data:`MAX_JOINT_SPEED` / :data:`MAX_LINEAR_SPEED`. A joint target outside the limits or an
  unreachable / collinear Cartesian path is refused at the start with 10; an IK failure during
  the motion ends it with 11.
* Create point from GVs: GV202 must be an integer 0..94 (six GVs inside GV0..GV99), else 1.
* Tool frame (GV245) and user frame (GV241) are stored / accepted but carry no geometry:
  the TCP is the flange, the user frame is the base frame, the tool frame is the flange frame.
* Teach enable with an unknown frame (GV200 not 0..3) is refused with 1. A jog's axis and
  direction are latched when it starts (ratio 0 -> > 0); the frame is latched at enable.
"""

from __future__ import annotations

import enum
import logging
import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
from numpy.typing import NDArray

from app.geometry import abc_to_matrix, rot_x, rot_y, rot_z, rotation_angle_deg, slerp_matrix
from app.protocol.enums import (
    Alarm,
    CommandKind,
    ControllerMode,
    CreatePointStatus,
    MoveStatus,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    TeachStatus,
    WorkMode,
)
from app.protocol.registers import (
    GV_GENERAL_LAST,
    NUM_AXES_TOTAL,
    NUM_ROBOT_AXES,
    TEMP_POINT_ID_MAX,
    TEMP_POINT_ID_MIN,
)
from app.sim import kinematics as kin

log = logging.getLogger(__name__)

Vector = NDArray[np.float64]
Matrix = NDArray[np.float64]
Pose6 = tuple[float, float, float, float, float, float]

STATUS_INITIAL: Final = 0
STATUS_DONE: Final = 0xFF

MAX_JOINT_SPEED: Final = 600.0  # deg/s (100 rpm), cap for 0x40
MAX_LINEAR_SPEED: Final = 5000.0  # mm/s, cap for 0x41 / 0x42
MAX_ANGULAR_SPEED: Final = 360.0  # deg/s, orientation change of Cartesian moves
GO_ZERO_SPEED: Final = 90.0  # deg/s
JOG_MAX_LINEAR: Final = 250.0  # mm/s at ratio 100
JOG_MAX_ANGULAR: Final = 30.0  # deg/s at ratio 100 (Cartesian rotation)
JOG_MAX_JOINT: Final = 30.0  # deg/s at ratio 100
PROGRAM_LINEAR_SPEED: Final = 200.0  # mm/s at program speed ratio 100
PROGRAM_JOINT_SPEED: Final = 60.0  # deg/s at program speed ratio 100
CHECK_STEP_MM: Final = 5.0  # path sampling when checking reachability at the start
CHECK_STEP_DEG: Final = 2.0
CHECK_MAX_SAMPLES: Final = 400
TRACE_LENGTH: Final = 20000
COLLINEAR_TOL_MM: Final = 1e-3  # an arc whose middle point is closer than this to the chord line


class MotionKind(enum.Enum):
    STEP = "step"  # function 1 (0x40 / 0x41)
    POINT = "point"  # function 3 (0x42)
    ZERO = "zero"  # go to zero (445)
    PROGRAM = "program"  # built-in program (440 <- 0x01)


@dataclass(frozen=True)
class StoredPoint:
    pose: Pose6
    tool: int


@dataclass(frozen=True)
class TraceSample:
    t: float
    pose: Pose6
    joints: tuple[float, ...]


class _Motion:
    """One segment of motion; :meth:`advance` moves the robot and says when it is over."""

    def advance(self, robot: SimRobot, dt: float) -> bool | None:
        """True: finished; False: still running; None: failed (algorithm error)."""
        raise NotImplementedError


class _JointMotion(_Motion):
    """Synchronous joint interpolation of all 11 axes (the slowest axis sets the pace)."""

    def __init__(self, start: Vector, target: Vector, speed_deg_s: float) -> None:
        self.start = start.copy()
        self.delta = target - start
        biggest = float(np.max(np.abs(self.delta))) if self.delta.size else 0.0
        self.duration = biggest / speed_deg_s if speed_deg_s > 0 else 0.0
        self.elapsed = 0.0

    def advance(self, robot: SimRobot, dt: float) -> bool | None:
        self.elapsed += dt
        s = 1.0 if self.duration <= 0 else min(1.0, self.elapsed / self.duration)
        robot.set_joints(self.start + s * self.delta)
        return s >= 1.0


class _Geometry:
    """A position path p(s), s in [0, 1]."""

    length: float

    def point(self, s: float) -> Vector:
        raise NotImplementedError


class _Line(_Geometry):
    def __init__(self, p0: Vector, p1: Vector) -> None:
        self.p0, self.p1 = p0, p1
        self.length = float(np.linalg.norm(p1 - p0))

    def point(self, s: float) -> Vector:
        return np.asarray(self.p0 + s * (self.p1 - self.p0), dtype=np.float64)


class _Arc(_Geometry):
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
            2.0 * nn * nn)
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
        return np.asarray(self.centre + self.radius * (math.cos(th) * self.u + math.sin(th) * self.v),
                          dtype=np.float64)


class _CartesianMotion(_Motion):
    """Linear or circular TCP path at constant speed, orientation slerped, IK every tick.

    With ``via`` = (middle rotation, path fraction at the middle point) the orientation goes
    r0 -> middle -> r1, reaching the middle point's orientation at the middle point.
    """

    def __init__(self, geometry: _Geometry, r0: Matrix, r1: Matrix, speed: float,
                 ext0: Vector, ext1: Vector, via: tuple[Matrix, float] | None = None) -> None:
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

    def advance(self, robot: SimRobot, dt: float) -> bool | None:
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


# --- built-in programs -------------------------------------------------------------------
# A program is a list of segments; each segment builds a motion from the robot's state.
Segment = Callable[["SimRobot", float], "_Motion | None"]


def _joint_segment(offsets: dict[int, float]) -> Segment:
    def build(robot: SimRobot, ratio: float) -> _Motion | None:
        target = robot.joints.copy()
        for axis, off in offsets.items():
            target[axis] += off
        return _JointMotion(robot.joints, target, PROGRAM_JOINT_SPEED * ratio)

    return build


def _line_segment(dx: float, dy: float, dz: float) -> Segment:
    def build(robot: SimRobot, ratio: float) -> _Motion | None:
        t = robot.flange()
        p0 = t[:3, 3].copy()
        motion = _CartesianMotion(_Line(p0, p0 + np.array([dx, dy, dz])), t[:3, :3], t[:3, :3],
                                  PROGRAM_LINEAR_SPEED * ratio, robot.joints[NUM_ROBOT_AXES:].copy(),
                                  robot.joints[NUM_ROBOT_AXES:].copy())
        return motion if motion.check(robot.joints) else None

    return build


#: id -> (name, segments). 1: a 100 mm square in XY; 2: a joint wiggle of J1 and J4;
#: 3: an external-axis shuttle on J7.
PROGRAMS: Final[dict[int, tuple[str, tuple[Segment, ...]]]] = {
    1: ("square 100 mm in XY", (_line_segment(100, 0, 0), _line_segment(0, 100, 0),
                                _line_segment(-100, 0, 0), _line_segment(0, -100, 0))),
    2: ("joint wiggle J1/J4", (_joint_segment({0: 15.0}), _joint_segment({0: -15.0}),
                               _joint_segment({3: 20.0}), _joint_segment({3: -20.0}))),
    3: ("external axis J7 shuttle", (_joint_segment({6: 100.0}), _joint_segment({6: -100.0}))),
}


@dataclass
class _ProgramRun:
    program_id: int
    mode: ProgramMotionMode
    cycles: int  # 0 endless
    ratio: float
    index: int = 0
    cycle: int = 0
    segments_left: int = -1  # single step: 1


def _as_int(value: float) -> int | None:
    """An integral float as int, else None."""
    if not math.isfinite(value) or value != round(value):
        return None
    return round(value)


class SimRobot:
    """The controller's state and the arm's motion. Not thread-safe: callers lock."""

    def __init__(self, *, point_id_min: int = TEMP_POINT_ID_MIN, point_id_max: int = TEMP_POINT_ID_MAX,
                 work_mode: WorkMode = WorkMode.AUTO) -> None:
        self.point_id_min = point_id_min
        self.point_id_max = point_id_max
        self.joints: Vector = np.zeros(NUM_AXES_TOTAL)
        self.joints[:NUM_ROBOT_AXES] = kin.HOME_JOINTS
        self._flange = kin.forward(self.joints[:NUM_ROBOT_AXES])
        self._pose: Pose6 = kin.transform_to_pose6(self._flange)
        self.work_mode = work_mode
        self.alarms = Alarm.NONE
        self.command_status = STATUS_INITIAL
        self.last_kind: CommandKind | None = None
        self.points: dict[int, StoredPoint] = {}
        self.refused_points: set[int] = set()  # fault injection: create point answers 1 for these
        self.time = 0.0
        # motion
        self.motion: _Motion | None = None
        self.motion_kind: MotionKind | None = None
        self.paused = False
        self.program: _ProgramRun | None = None
        self._step_cursor: dict[int, int] = {}  # single-step position per program id
        # teach
        self.teach_enabled = False
        self.teach_frame = TeachFrame.BASE
        self.teach_ratio = 0.0
        self.jog_axis = 0
        self.jog_direction = 1
        self.jogging = False
        self._jog_blocked = False
        self.trace: deque[TraceSample] = deque(maxlen=TRACE_LENGTH)

    # --- state --------------------------------------------------------------------------
    def set_joints(self, joints: Vector) -> None:
        self.joints = np.asarray(joints, dtype=np.float64).copy()
        self._flange = kin.forward(self.joints[:NUM_ROBOT_AXES])
        self._pose = kin.transform_to_pose6(self._flange)

    def flange(self) -> Matrix:
        return self._flange.copy()

    @property
    def pose(self) -> Pose6:
        return self._pose

    @property
    def busy(self) -> bool:
        return self.motion is not None or self.program is not None

    @property
    def controller_mode(self) -> ControllerMode:
        if self.teach_enabled:
            return ControllerMode.MODBUS_TEACH
        return ControllerMode(int(self.work_mode))

    @property
    def program_state(self) -> ProgramState:
        if not self.busy:
            return ProgramState.STOPPED
        return ProgramState.PAUSED if self.paused else ProgramState.RUNNING

    # --- checks -------------------------------------------------------------------------
    def _move_refusal(self) -> int | None:
        if self.work_mode is WorkMode.MANUAL or self.teach_enabled or self.busy:
            return MoveStatus.WORK_MODE_ERROR
        for bit, code in ((Alarm.ESTOP, MoveStatus.ESTOP), (Alarm.SERVO, MoveStatus.SERVO_ALARM),
                          (Alarm.BRAKE, MoveStatus.BRAKE_ALARM),
                          (Alarm.ENCODER, MoveStatus.ENCODER_READ_ERROR),
                          (Alarm.ALGORITHM, MoveStatus.CALCULATION_ERROR)):
            if self.alarms & bit:
                return int(code)
        return None

    def _teach_refusal(self) -> int | None:
        if self.work_mode is WorkMode.MANUAL or self.busy:
            return TeachStatus.WORK_MODE_ERROR
        for bit, code in ((Alarm.ESTOP, TeachStatus.ESTOP), (Alarm.SERVO, TeachStatus.SERVO_ALARM),
                          (Alarm.BRAKE, TeachStatus.BRAKE_ALARM),
                          (Alarm.ALGORITHM, TeachStatus.ALGORITHM_ALARM)):
            if self.alarms & bit:
                return int(code)
        return None

    def _finish(self, code: int) -> int:
        self.command_status = int(code)
        return int(code)

    def _start_motion(self, motion: _Motion, kind: MotionKind) -> None:
        self.motion = motion
        self.motion_kind = kind
        self.paused = False
        self.trace.clear()
        self._record()

    # --- function 1: incremental moves ----------------------------------------------------
    def step_joint(self, offsets: Sequence[float], speed_rpm: float) -> int:
        """0x40: offsets of J1..J11 (degrees), synchronous, at ``speed_rpm`` x 6 deg/s."""
        self.last_kind = CommandKind.MOVE
        if (refusal := self._move_refusal()) is not None:
            return self._finish(refusal)
        offs = np.zeros(NUM_AXES_TOTAL)
        offs[: len(offsets)] = [float(v) for v in offsets[:NUM_AXES_TOTAL]]
        if not (math.isfinite(speed_rpm) and speed_rpm > 0) or not np.all(np.isfinite(offs)):
            return self._finish(MoveStatus.CALCULATION_ERROR)
        target = self.joints + offs
        lo, hi = kin.EXT_LIMITS
        ext = target[NUM_ROBOT_AXES:]
        if not kin.within_limits(target) or np.any(ext < lo) or np.any(ext > hi):
            log.info("joint step refused: target outside the joint limits")
            return self._finish(MoveStatus.CALCULATION_ERROR)
        speed = min(speed_rpm * 6.0, MAX_JOINT_SPEED)
        self._start_motion(_JointMotion(self.joints, target, speed), MotionKind.STEP)
        return self._finish(MoveStatus.MOVING)

    def step_base(self, offsets: Sequence[float], speed: float, ext_offsets: Sequence[float] = ()) -> int:
        """0x41: X Y Z (mm) and A B C (deg) offsets in the base frame, linear at ``speed`` mm/s."""
        self.last_kind = CommandKind.MOVE
        if (refusal := self._move_refusal()) is not None:
            return self._finish(refusal)
        values = [float(v) for v in offsets[:6]] + [0.0] * (6 - len(offsets[:6]))
        ext = np.zeros(NUM_AXES_TOTAL - NUM_ROBOT_AXES)
        ext[: len(ext_offsets)] = [float(v) for v in ext_offsets[: len(ext)]]
        if not (math.isfinite(speed) and speed > 0) or not all(map(math.isfinite, values)) \
                or not np.all(np.isfinite(ext)):
            return self._finish(MoveStatus.CALCULATION_ERROR)
        pose = self._pose
        target_pose = [pose[i] + values[i] for i in range(6)]
        p0 = self._flange[:3, 3].copy()
        p1 = np.array(target_pose[:3])
        r1 = abc_to_matrix(target_pose[3], target_pose[4], target_pose[5])
        ext0 = self.joints[NUM_ROBOT_AXES:].copy()
        motion = _CartesianMotion(_Line(p0, p1), self._flange[:3, :3].copy(), r1,
                                  min(speed, MAX_LINEAR_SPEED), ext0, ext0 + ext)
        if not motion.check(self.joints):
            log.info("base step refused: path unreachable")
            return self._finish(MoveStatus.CALCULATION_ERROR)
        self._start_motion(motion, MotionKind.STEP)
        return self._finish(MoveStatus.MOVING)

    # --- function 2: temp points ----------------------------------------------------------
    def create_point(self, point_id: float, pose: Sequence[float] | None, tool: float) -> int:
        """0xE0: store the current pose (``pose`` None) or ``pose`` under ``point_id``."""
        self.last_kind = CommandKind.CREATE_POINT
        pid = _as_int(point_id)
        if pid is None or not self.point_id_min <= pid <= self.point_id_max or pid in self.refused_points:
            log.info("create point refused: bad id %s", point_id)
            return self._finish(CreatePointStatus.BAD_POINT_ID)
        if pose is None:
            values = self._pose
        else:
            if len(pose) != 6 or not all(math.isfinite(float(v)) for v in pose):
                return self._finish(CreatePointStatus.BAD_POINT_ID)
            v = [float(x) for x in pose]
            values = (v[0], v[1], v[2], v[3], v[4], v[5])
        tool_id = _as_int(tool)
        self.points[pid] = StoredPoint(values, tool_id if tool_id is not None else 200)
        return self._finish(CreatePointStatus.DONE)

    @staticmethod
    def gv_source_ok(first_gv: float) -> int | None:
        """The first GV index of a pose passed in GVs (0..94), or None."""
        idx = _as_int(first_gv)
        if idx is None or not 0 <= idx <= GV_GENERAL_LAST - 5:
            return None
        return idx

    # --- function 3: move to temp point ---------------------------------------------------
    def move_to_point(self, via: float, end: float, orientation_changes: float, ignore_middle: float,
                      speed: float, tool: float = 200.0) -> int:
        """0x42: line (via = -1) or arc through point ``via`` to point ``end``.

        GV203 "ignore the middle point" (project decision, PROTOCOL.md leaves it open): the arc
        still passes through the middle point's position, but its orientation is ignored — the
        tool turns straight from the start to the end orientation. Without the flag (and with
        orientation changing) the tool reaches the middle point's orientation at the middle.
        """
        self.last_kind = CommandKind.MOVE
        if (refusal := self._move_refusal()) is not None:
            return self._finish(refusal)
        end_id = _as_int(end)
        if end_id is None or end_id not in self.points:
            log.info("move to point refused: no end point %s", end)
            return self._finish(MoveStatus.BAD_END_POINT)
        line = via == -1
        mid_id = _as_int(via)
        if not line and (mid_id is None or mid_id not in self.points):
            log.info("move to point refused: no middle point %s", via)
            return self._finish(MoveStatus.BAD_END_POINT)
        if not (math.isfinite(speed) and speed > 0):
            return self._finish(MoveStatus.CALCULATION_ERROR)
        end_pose = self.points[end_id].pose
        p0 = self._flange[:3, 3].copy()
        p_end = np.array(end_pose[:3])
        r0 = self._flange[:3, :3].copy()
        r1 = abc_to_matrix(*end_pose[3:]) if orientation_changes else r0
        geometry: _Geometry
        via_rotation: tuple[Matrix, float] | None = None
        if line:
            geometry = _Line(p0, p_end)
        else:
            assert mid_id is not None
            mid_pose = self.points[mid_id].pose
            try:
                arc = _Arc(p0, np.array(mid_pose[:3]), p_end)
            except ValueError as exc:
                log.info("move to point refused: %s", exc)
                return self._finish(MoveStatus.CALCULATION_ERROR)
            geometry = arc
            if orientation_changes and not ignore_middle:
                via_rotation = (abc_to_matrix(*mid_pose[3:]), arc.middle_fraction)
        ext = self.joints[NUM_ROBOT_AXES:].copy()
        motion = _CartesianMotion(geometry, r0, r1, min(speed, MAX_LINEAR_SPEED), ext, ext, via_rotation)
        if not motion.check(self.joints):
            log.info("move to point refused: path unreachable")
            return self._finish(MoveStatus.CALCULATION_ERROR)
        self._start_motion(motion, MotionKind.POINT)
        return self._finish(MoveStatus.MOVING)

    # --- function 4: teach -----------------------------------------------------------------
    def teach_enable(self, frame: float, ratio: float) -> int:
        """0x80: enable Modbus teach; the frame is latched now. Refused (7) unless ratio is 0."""
        self.last_kind = CommandKind.TEACH
        if (refusal := self._teach_refusal()) is not None:
            return self._finish(refusal)
        if ratio != 0:
            return self._finish(TeachStatus.RATIO_NOT_ZERO)
        fr = _as_int(frame)
        if fr is None or fr not in {f.value for f in TeachFrame}:
            log.info("teach enable refused: unknown frame %s", frame)
            return self._finish(TeachStatus.WORK_MODE_ERROR)
        self.teach_enabled = True
        self.teach_frame = TeachFrame(fr)
        self.teach_ratio = 0.0
        self.jogging = False
        return self._finish(TeachStatus.DONE)

    def teach_disable(self, ratio: float) -> int:
        """0x81: leave teach mode. Refused (7) unless the ratio is 0."""
        self.last_kind = CommandKind.TEACH
        if self.teach_enabled and ratio != 0:
            return self._finish(TeachStatus.RATIO_NOT_ZERO)
        self._teach_off()
        return self._finish(TeachStatus.DONE)

    def _teach_off(self) -> None:
        self.teach_enabled = False
        self.jogging = False
        self.teach_ratio = 0.0

    def set_teach_ratio(self, ratio: float, axis: float, direction: float) -> None:
        """GV203 written while teach is enabled: 0 stops the jog, > 0 starts or re-speeds it."""
        if not self.teach_enabled:
            return
        r = float(ratio) if math.isfinite(ratio) else 0.0
        r = min(100.0, max(0.0, r))
        self.teach_ratio = r
        if r <= 0:
            self.jogging = False
            return
        if not self.jogging:
            ax = _as_int(axis)
            limit = NUM_AXES_TOTAL if self.teach_frame is TeachFrame.JOINT else 6
            if ax is None or not 0 <= ax < limit:
                log.info("jog ignored: axis %s is not valid in the %s frame", axis, self.teach_frame.name)
                return
            self.jog_axis = ax
            self.jog_direction = 1 if direction else -1
            self.jogging = True
            self._jog_blocked = False
            self.trace.clear()

    def _jog(self, dt: float) -> None:
        frac = self.teach_ratio / 100.0
        sign = float(self.jog_direction)
        if self.teach_frame is TeachFrame.JOINT:
            joints = self.joints.copy()
            ax = self.jog_axis
            lo, hi = kin.JOINT_LIMITS[ax] if ax < NUM_ROBOT_AXES else kin.EXT_LIMITS
            joints[ax] = min(hi, max(lo, joints[ax] + sign * JOG_MAX_JOINT * frac * dt))
            if joints[ax] != self.joints[ax]:
                self.set_joints(joints)
            return
        t = self.flange()
        ax = self.jog_axis
        if ax < 3:
            direction = np.zeros(3)
            direction[ax] = sign * JOG_MAX_LINEAR * frac * dt
            if self.teach_frame is TeachFrame.TOOL:
                direction = t[:3, :3] @ direction
            t[:3, 3] += direction
        else:
            angle = sign * JOG_MAX_ANGULAR * frac * dt
            rot = (rot_x, rot_y, rot_z)[ax - 3](angle)
            t[:3, :3] = t[:3, :3] @ rot if self.teach_frame is TeachFrame.TOOL else rot @ t[:3, :3]
        q = kin.inverse(t, self.joints[:NUM_ROBOT_AXES])
        if q is None:
            if not self._jog_blocked:
                log.info("jog stopped at the workspace / joint limit")
                self._jog_blocked = True
            return
        self._jog_blocked = False
        joints = self.joints.copy()
        joints[:NUM_ROBOT_AXES] = q
        self.set_joints(joints)

    # --- plain commands ---------------------------------------------------------------------
    def stop(self) -> None:
        """441 <- 1: end any move, program, go-to-zero and jog; GV291 -> 0."""
        if self.busy:
            log.info("stopped %s", self.motion_kind.value if self.motion_kind else "program")
        self.motion = None
        self.motion_kind = None
        self.program = None
        self.paused = False
        self.jogging = False
        self.command_status = STATUS_INITIAL

    def pause(self) -> bool:
        if self.busy and not self.paused:
            self.paused = True
            return True
        return False

    def resume(self) -> bool:
        if self.busy and self.paused:
            self.paused = False
            return True
        return False

    def set_work_mode(self, mode: int) -> bool:
        try:
            new = WorkMode(mode)
        except ValueError:
            return False
        if new is WorkMode.MANUAL:
            self._abort(MoveStatus.WORK_MODE_ERROR)
            self._teach_off()
        self.work_mode = new
        return True

    def go_zero(self, axis: int) -> bool:
        """445: 0..10 one axis, 11 all, joint move at :data:`GO_ZERO_SPEED`."""
        self._teach_off()
        if not 0 <= axis <= NUM_AXES_TOTAL:
            log.info("go to zero refused: axis %s", axis)
            return False
        if self._move_refusal() is not None:
            log.info("go to zero refused: controller busy, manual or alarm")
            return False
        target = self.joints.copy()
        if axis == NUM_AXES_TOTAL:
            target[:] = 0.0
        else:
            target[axis] = 0.0
        self._start_motion(_JointMotion(self.joints, target, GO_ZERO_SPEED), MotionKind.ZERO)
        return True

    def run_program(self, program_id: int, mode: int, cycles: int, speed_ratio: int) -> bool:
        """440 <- 0x01: run a built-in program (:data:`PROGRAMS`); unknown ids are refused."""
        self._teach_off()
        if program_id not in PROGRAMS:
            log.warning("run program refused: no program %s (built-in: %s)", program_id, sorted(PROGRAMS))
            return False
        try:
            motion_mode = ProgramMotionMode(mode)
        except ValueError:
            log.warning("run program refused: motion mode %s", mode)
            return False
        if self._move_refusal() is not None:
            log.warning("run program refused: controller busy, manual or alarm")
            return False
        ratio = min(100, max(1, speed_ratio)) / 100.0
        segments = PROGRAMS[program_id][1]
        run = _ProgramRun(program_id, motion_mode, max(0, cycles), ratio)
        if motion_mode is ProgramMotionMode.SINGLE_STEP:
            run.index = self._step_cursor.get(program_id, 0) % len(segments)
            run.segments_left = 1
        self.program = run
        self.trace.clear()
        if not self._next_segment():
            self.program = None
            return False
        log.info("program %s (%s) started, mode %s", program_id, PROGRAMS[program_id][0], motion_mode.name)
        return True

    def _next_segment(self) -> bool:
        run = self.program
        assert run is not None
        segments = PROGRAMS[run.program_id][1]
        motion = segments[run.index](self, run.ratio)
        if motion is None:
            log.warning("program %s: segment %s unreachable, stopped", run.program_id, run.index)
            return False
        self.motion = motion
        self.motion_kind = MotionKind.PROGRAM
        self._record()
        return True

    def _segment_done(self) -> None:
        run = self.program
        assert run is not None
        segments = PROGRAMS[run.program_id][1]
        run.index += 1
        if run.mode is ProgramMotionMode.SINGLE_STEP:
            self._step_cursor[run.program_id] = run.index % len(segments)
            self.program = None
            return
        if run.index >= len(segments):
            run.index = 0
            run.cycle += 1
            if run.mode is ProgramMotionMode.SINGLE_RUN or (run.cycles and run.cycle >= run.cycles):
                self.program = None
                return
        if not self._next_segment():
            self.program = None

    # --- alarms and restart ---------------------------------------------------------------
    def set_alarm(self, bit: Alarm, on: bool) -> None:
        if on:
            self.alarms |= bit
        else:
            self.alarms &= ~bit
        if on and bit & (Alarm.ESTOP | Alarm.SERVO | Alarm.BRAKE):
            code = MoveStatus.ESTOP if bit & Alarm.ESTOP else (
                MoveStatus.SERVO_ALARM if bit & Alarm.SERVO else MoveStatus.BRAKE_ALARM)
            self._abort(code)
            self._teach_off()

    def _abort(self, code: int) -> None:
        """End the current motion because of ``code`` (reported if it was a 1/3 move)."""
        if self.motion_kind in (MotionKind.STEP, MotionKind.POINT):
            self.command_status = int(code)
        self.motion = None
        self.motion_kind = None
        self.program = None
        self.paused = False

    def restart(self) -> None:
        """The controller's system logs in again: points wiped, motion stopped, teach off."""
        self.stop()
        self._teach_off()
        self.points.clear()
        self._step_cursor.clear()
        self.command_status = STATUS_INITIAL
        self.last_kind = None

    # --- time -------------------------------------------------------------------------------
    def _record(self) -> None:
        self.trace.append(TraceSample(self.time, self._pose, tuple(float(v) for v in self.joints)))

    def tick(self, dt: float) -> None:
        """Advance the simulation by ``dt`` seconds."""
        self.time += dt
        if self.motion is not None and not self.paused:
            result = self.motion.advance(self, dt)
            self._record()
            if result is None:
                log.warning("motion failed: no inverse kinematics solution on the path")
                self._abort(MoveStatus.ALGORITHM_ERROR)
            elif result:
                kind = self.motion_kind
                self.motion = None
                if kind is MotionKind.PROGRAM and self.program is not None:
                    self._segment_done()
                    if self.program is None:
                        self.motion_kind = None
                else:
                    self.motion_kind = None
                    if kind in (MotionKind.STEP, MotionKind.POINT):
                        self.command_status = STATUS_DONE
        if self.teach_enabled and self.jogging and self.teach_ratio > 0:
            self._jog(dt)
            self._record()

    def trajectory(self) -> list[TraceSample]:
        return list(self.trace)


"""The controller's functions 1 to 4 (moves, temp points, move to point, teach and jog) of the
simulated controller: each checks its refusals, starts a motion or changes the teach state, and
returns the GV291 code it leaves behind. Mixed into :class:`~app.sim.robot.SimRobot`, which owns
the state machine (motion, programs, alarms, time); the decisions are listed there."""

from __future__ import annotations

import logging
import math
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np

from app.geometry import abc_to_matrix
from app.protocol.enums import (
    Alarm,
    CommandKind,
    CreatePointStatus,
    MoveStatus,
    TeachFrame,
    TeachStatus,
    WorkMode,
)
from app.protocol.registers import GV_GENERAL_LAST, NUM_AXES_TOTAL, NUM_ROBOT_AXES
from app.sim import kinematics as kin
from app.sim.motion import (
    Arc,
    CartesianMotion,
    Geometry,
    JointMotion,
    Line,
    Matrix,
    Motion,
    MotionKind,
    Pose6,
    TraceSample,
    Vector,
    jog_step,
)

log = logging.getLogger(__name__)

MAX_JOINT_SPEED: Final = 600.0  # deg/s (100 rpm), cap for 0x40
MAX_LINEAR_SPEED: Final = 5000.0  # mm/s, cap for 0x41 / 0x42


@dataclass(frozen=True)
class StoredPoint:
    pose: Pose6
    tool: int


def as_int(value: float) -> int | None:
    """An integral float as int, else None."""
    if not math.isfinite(value) or value != round(value):
        return None
    return round(value)


class ControllerCommands:
    """Functions 1..4. The state lives in :class:`~app.sim.robot.SimRobot`; declared here."""

    point_id_min: int
    point_id_max: int
    joints: Vector
    _flange: Matrix
    _pose: Pose6
    work_mode: WorkMode
    alarms: Alarm
    command_status: int
    last_kind: CommandKind | None
    points: dict[int, StoredPoint]
    refused_points: set[int]
    foreign_points: dict[int, StoredPoint]
    teach_enabled: bool
    teach_frame: TeachFrame
    teach_ratio: float
    jog_axis: int
    jog_direction: int
    jogging: bool
    _jog_blocked: bool
    trace: deque[TraceSample]

    @property
    def busy(self) -> bool:
        raise NotImplementedError

    def set_joints(self, joints: Vector) -> None:
        raise NotImplementedError

    def _start_motion(self, motion: Motion, kind: MotionKind) -> None:
        raise NotImplementedError

    # --- checks -------------------------------------------------------------------------
    def _move_refusal(self) -> int | None:
        if self.work_mode is WorkMode.MANUAL or self.teach_enabled or self.busy:
            return MoveStatus.WORK_MODE_ERROR
        for bit, code in (
            (Alarm.ESTOP, MoveStatus.ESTOP),
            (Alarm.SERVO, MoveStatus.SERVO_ALARM),
            (Alarm.BRAKE, MoveStatus.BRAKE_ALARM),
            (Alarm.ENCODER, MoveStatus.ENCODER_READ_ERROR),
            (Alarm.ALGORITHM, MoveStatus.CALCULATION_ERROR),
        ):
            if self.alarms & bit:
                return int(code)
        return None

    def _teach_refusal(self) -> int | None:
        if self.work_mode is WorkMode.MANUAL or self.busy:
            return TeachStatus.WORK_MODE_ERROR
        for bit, code in (
            (Alarm.ESTOP, TeachStatus.ESTOP),
            (Alarm.SERVO, TeachStatus.SERVO_ALARM),
            (Alarm.BRAKE, TeachStatus.BRAKE_ALARM),
            (Alarm.ALGORITHM, TeachStatus.ALGORITHM_ALARM),
        ):
            if self.alarms & bit:
                return int(code)
        return None

    def _finish(self, code: int) -> int:
        self.command_status = int(code)
        return int(code)

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
        self._start_motion(JointMotion(self.joints, target, speed), MotionKind.STEP)
        return self._finish(MoveStatus.MOVING)

    def step_base(self, offsets: Sequence[float], speed: float, ext_offsets: Sequence[float] = ()) -> int:
        """0x41: X Y Z (mm) and A B C (deg) offsets in the base frame, linear at ``speed`` mm/s."""
        self.last_kind = CommandKind.MOVE
        if (refusal := self._move_refusal()) is not None:
            return self._finish(refusal)
        values = [float(v) for v in offsets[:6]] + [0.0] * (6 - len(offsets[:6]))
        ext = np.zeros(NUM_AXES_TOTAL - NUM_ROBOT_AXES)
        ext[: len(ext_offsets)] = [float(v) for v in ext_offsets[: len(ext)]]
        if (
            not (math.isfinite(speed) and speed > 0)
            or not all(map(math.isfinite, values))
            or not np.all(np.isfinite(ext))
        ):
            return self._finish(MoveStatus.CALCULATION_ERROR)
        pose = self._pose
        target_pose = [pose[i] + values[i] for i in range(6)]
        p0 = self._flange[:3, 3].copy()
        p1 = np.array(target_pose[:3])
        r1 = abc_to_matrix(target_pose[3], target_pose[4], target_pose[5])
        ext0 = self.joints[NUM_ROBOT_AXES:].copy()
        motion = CartesianMotion(
            Line(p0, p1), self._flange[:3, :3].copy(), r1, min(speed, MAX_LINEAR_SPEED), ext0, ext0 + ext
        )
        if not motion.check(self.joints):
            log.info("base step refused: path unreachable")
            return self._finish(MoveStatus.CALCULATION_ERROR)
        self._start_motion(motion, MotionKind.STEP)
        return self._finish(MoveStatus.MOVING)

    # --- function 2: temp points ----------------------------------------------------------
    def create_point(self, point_id: float, pose: Sequence[float] | None, tool: float) -> int:
        """0xE0: store the current pose (``pose`` None) or ``pose`` under ``point_id``."""
        self.last_kind = CommandKind.CREATE_POINT
        pid = as_int(point_id)
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
        tool_id = as_int(tool)
        self.points[pid] = StoredPoint(values, tool_id if tool_id is not None else 200)
        foreign = self.foreign_points.get(pid)
        if foreign is not None:  # another master's create lands right after ours (fault injection)
            log.info("create point %d: overwritten at once by another master", pid)
            self.points[pid] = foreign
        return self._finish(CreatePointStatus.DONE)

    @staticmethod
    def gv_source_ok(first_gv: float) -> int | None:
        """The first GV index of a pose passed in GVs (0..94), or None."""
        idx = as_int(first_gv)
        if idx is None or not 0 <= idx <= GV_GENERAL_LAST - 5:
            return None
        return idx

    # --- function 3: move to temp point ---------------------------------------------------
    def move_to_point(
        self,
        via: float,
        end: float,
        orientation_changes: float,
        ignore_middle: float,
        speed: float,
        tool: float = 200.0,
    ) -> int:
        """0x42: line (via = -1) or arc through point ``via`` to point ``end``.

        GV203 "ignore the middle point" (project decision, PROTOCOL.md leaves it open): the arc
        still passes through the middle point's position, but its orientation is ignored — the
        tool turns straight from the start to the end orientation. Without the flag (and with
        orientation changing) the tool reaches the middle point's orientation at the middle.
        """
        self.last_kind = CommandKind.MOVE
        if (refusal := self._move_refusal()) is not None:
            return self._finish(refusal)
        end_id = as_int(end)
        if end_id is None or end_id not in self.points:
            log.info("move to point refused: no end point %s", end)
            return self._finish(MoveStatus.BAD_END_POINT)
        line = via == -1
        mid_id = as_int(via)
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
        geometry: Geometry
        via_rotation: tuple[Matrix, float] | None = None
        if line:
            geometry = Line(p0, p_end)
        else:
            assert mid_id is not None
            mid_pose = self.points[mid_id].pose
            try:
                arc = Arc(p0, np.array(mid_pose[:3]), p_end)
            except ValueError as exc:
                log.info("move to point refused: %s", exc)
                return self._finish(MoveStatus.CALCULATION_ERROR)
            geometry = arc
            if orientation_changes and not ignore_middle:
                via_rotation = (abc_to_matrix(*mid_pose[3:]), arc.middle_fraction)
        ext = self.joints[NUM_ROBOT_AXES:].copy()
        motion = CartesianMotion(geometry, r0, r1, min(speed, MAX_LINEAR_SPEED), ext, ext, via_rotation)
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
        fr = as_int(frame)
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
            ax = as_int(axis)
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
        moved = jog_step(
            self.joints,
            self._flange,
            self.teach_frame,
            self.jog_axis,
            self.jog_direction,
            self.teach_ratio,
            dt,
        )
        if moved is None:
            if not self._jog_blocked:
                log.info("jog stopped at the workspace / joint limit")
                self._jog_blocked = True
            return
        self._jog_blocked = False
        if not np.array_equal(moved, self.joints):
            self.set_joints(moved)

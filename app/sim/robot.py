"""State machine and motion of the simulated controller (pure Python, no sockets, no threads).

:class:`SimRobot` is driven by explicit :meth:`SimRobot.tick` calls and by one method per
controller command. Each command method returns the GV291 code it leaves behind (or a bool for
the commands that have no status). Functions 1..4 (moves, temp points, teach and jog) are in
:mod:`app.sim.commands`, the motion segments in :mod:`app.sim.motion`; this module keeps the
state machine: state, plain commands, built-in programs, alarms and time. The server
(:mod:`app.sim.server`) owns the registers, the timing of GV291 publication and the locking;
these modules own the behaviour.

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
  linear speed number (mm/s), capped at :data:`~app.sim.motion.MAX_ANGULAR_SPEED`.
* Speeds must be finite and > 0, else GV291 = 10; they are capped at
  :data:`~app.sim.commands.MAX_JOINT_SPEED` /
  :data:`~app.sim.commands.MAX_LINEAR_SPEED`. A joint target outside the limits or an
  unreachable / collinear Cartesian path is refused at the start with 10; an IK failure during
  the motion ends it with 11.
* Create point from GVs: GV202 must be an integer 0..94 (six GVs inside GV0..GV99), else 1.
* Tool frame (GV245) and user frame (GV241) are stored / accepted but carry no geometry:
  the TCP is the flange, the user frame is the base frame, the tool frame is the flange frame.
* Teach enable with an unknown frame (GV200 not 0..3) is refused with 1. A jog's axis and
  direction are latched when it starts (ratio 0 -> > 0); the frame is latched at enable.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Final

import numpy as np

from app.protocol.enums import (
    Alarm,
    CommandKind,
    ControllerMode,
    MoveStatus,
    ProgramMotionMode,
    ProgramState,
    TeachFrame,
    WorkMode,
)
from app.protocol.registers import (
    NUM_AXES_TOTAL,
    NUM_ROBOT_AXES,
    TEMP_POINT_ID_MAX,
    TEMP_POINT_ID_MIN,
)
from app.sim import kinematics as kin
from app.sim.commands import ControllerCommands, StoredPoint
from app.sim.motion import (
    CartesianMotion,
    JointMotion,
    Line,
    Matrix,
    Motion,
    MotionKind,
    Pose6,
    TraceSample,
    Vector,
)

log = logging.getLogger(__name__)

STATUS_INITIAL: Final = 0
STATUS_DONE: Final = 0xFF

GO_ZERO_SPEED: Final = 90.0  # deg/s
PROGRAM_LINEAR_SPEED: Final = 200.0  # mm/s at program speed ratio 100
PROGRAM_JOINT_SPEED: Final = 60.0  # deg/s at program speed ratio 100
TRACE_LENGTH: Final = 20000


# --- built-in programs -------------------------------------------------------------------
# A program is a list of segments; each segment builds a motion from the robot's state.
Segment = Callable[["SimRobot", float], "Motion | None"]


def _joint_segment(offsets: dict[int, float]) -> Segment:
    def build(robot: SimRobot, ratio: float) -> Motion | None:
        target = robot.joints.copy()
        for axis, off in offsets.items():
            target[axis] += off
        return JointMotion(robot.joints, target, PROGRAM_JOINT_SPEED * ratio)

    return build


def _line_segment(dx: float, dy: float, dz: float) -> Segment:
    def build(robot: SimRobot, ratio: float) -> Motion | None:
        t = robot.flange()
        p0 = t[:3, 3].copy()
        motion = CartesianMotion(
            Line(p0, p0 + np.array([dx, dy, dz])),
            t[:3, :3],
            t[:3, :3],
            PROGRAM_LINEAR_SPEED * ratio,
            robot.joints[NUM_ROBOT_AXES:].copy(),
            robot.joints[NUM_ROBOT_AXES:].copy(),
        )
        return motion if motion.check(robot.joints) else None

    return build


#: id -> (name, segments). 1: a 100 mm square in XY; 2: a joint wiggle of J1 and J4;
#: 3: an external-axis shuttle on J7.
PROGRAMS: Final[dict[int, tuple[str, tuple[Segment, ...]]]] = {
    1: (
        "square 100 mm in XY",
        (
            _line_segment(100, 0, 0),
            _line_segment(0, 100, 0),
            _line_segment(-100, 0, 0),
            _line_segment(0, -100, 0),
        ),
    ),
    2: (
        "joint wiggle J1/J4",
        (
            _joint_segment({0: 15.0}),
            _joint_segment({0: -15.0}),
            _joint_segment({3: 20.0}),
            _joint_segment({3: -20.0}),
        ),
    ),
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


class SimRobot(ControllerCommands):
    """The controller's state and the arm's motion. Not thread-safe: callers lock."""

    def __init__(
        self,
        *,
        point_id_min: int = TEMP_POINT_ID_MIN,
        point_id_max: int = TEMP_POINT_ID_MAX,
        work_mode: WorkMode = WorkMode.AUTO,
    ) -> None:
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
        # fault injection: another master writes its own copy of these points right after each of
        # our creates of them (the window between a host's create point and its move)
        self.foreign_points: dict[int, StoredPoint] = {}
        self.time = 0.0
        # motion
        self.motion: Motion | None = None
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
    def moving(self) -> bool:
        """The arm moves now: a motion not paused, or a jog at a ratio above 0."""
        running = self.motion is not None and not self.paused
        return running or (self.teach_enabled and self.jogging and self.teach_ratio > 0)

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

    def _start_motion(self, motion: Motion, kind: MotionKind) -> None:
        self.motion = motion
        self.motion_kind = kind
        self.paused = False
        self.trace.clear()
        self._record()

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
        self._start_motion(JointMotion(self.joints, target, GO_ZERO_SPEED), MotionKind.ZERO)
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
            code = (
                MoveStatus.ESTOP
                if bit & Alarm.ESTOP
                else (MoveStatus.SERVO_ALARM if bit & Alarm.SERVO else MoveStatus.BRAKE_ALARM)
            )
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

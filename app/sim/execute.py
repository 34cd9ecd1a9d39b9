"""Command execution of the simulated controller: what a host's write to the control registers
does (work mode, stop, pause, resume, go to zero, teach ratio, the 440 run command with its
parameters in GV200..GV205 and GV244..GV245, a write to GV291). Called by
:class:`~app.sim.server.SimController` under its lock, the written values already in ``regs``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass

from pymodbus.constants import ExcCodes

from app.protocol.enums import CommandKind, RunCommand, decode_status_registers
from app.protocol.registers import (
    GV_COMMAND_STATUS,
    GV_EXPECTED_SPEED,
    GV_EXT_OFFSET0,
    GV_PARAM0,
    GV_PARAM1,
    GV_PARAM2,
    GV_PARAM3,
    GV_TOOL_FRAME,
    NUM_EXTERNAL_AXES,
    REG_CYCLE_COUNT,
    REG_GO_ZERO,
    REG_PAUSE,
    REG_PROGRAM_ID,
    REG_PROGRAM_MODE,
    REG_PROGRAM_SPEED,
    REG_RESUME,
    REG_RUN_COMMAND,
    REG_STOP,
    REG_WORK_MODE,
    gv_reg,
)
from app.sim.config import SimConfig
from app.sim.register_image import RegisterImage
from app.sim.robot import SimRobot
from app.sim.status import StatusPublisher

log = logging.getLogger(__name__)

_STATUS_COMMANDS = frozenset(
    {
        RunCommand.STEP_JOINT,
        RunCommand.STEP_BASE,
        RunCommand.MOVE_TO_POINT,
        RunCommand.CREATE_POINT,
        RunCommand.TEACH_ENABLE,
        RunCommand.TEACH_DISABLE,
    }
)
_GV291_REGS = range(gv_reg(GV_COMMAND_STATUS), gv_reg(GV_COMMAND_STATUS) + 2)
_RATIO_REGS = range(gv_reg(GV_PARAM3), gv_reg(GV_PARAM3) + 2)
# the commands whose 0 a host must have read before GV291 moves on (classic profile)
_INSTANT_COMMANDS = frozenset({RunCommand.CREATE_POINT, RunCommand.TEACH_ENABLE, RunCommand.TEACH_DISABLE})
_MOVE_COMMANDS = frozenset({RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT})


def _touches(covered: range, regs: range) -> bool:
    """A write over ``covered`` reaches the first or the last register of ``regs`` (a float's two)."""
    return regs.start in covered or regs.stop - 1 in covered


@dataclass(frozen=True)
class _Params:
    """A run command's parameters, written beside it: GV200..GV205, the speed, the external axes'
    offsets, the tool frame."""

    p: list[float]
    speed: float
    ext: list[float]
    tool: float


#: The run commands the robot answers with a status from the parameters alone.
_ROBOT_COMMANDS: dict[RunCommand, Callable[[SimRobot, _Params], int]] = {
    RunCommand.STEP_JOINT: lambda robot, c: robot.step_joint(c.p + c.ext, c.speed),
    RunCommand.STEP_BASE: lambda robot, c: robot.step_base(c.p, c.speed, c.ext),
    RunCommand.MOVE_TO_POINT: lambda robot, c: robot.move_to_point(
        c.p[0], c.p[1], c.p[2], c.p[3], c.speed, c.tool
    ),
    RunCommand.TEACH_ENABLE: lambda robot, c: robot.teach_enable(c.p[0], c.p[3]),
    RunCommand.TEACH_DISABLE: lambda robot, c: robot.teach_disable(c.p[3]),
}


class CommandExecutor:
    """Turns writes into robot commands and GV291 holds.

    ``status_delay`` gives the pickup time of GV291 now (fault injection may change it);
    ``move_accepted`` is called when a move command was accepted (it starts once answered)."""

    def __init__(
        self,
        robot: SimRobot,
        config: SimConfig,
        image: RegisterImage,
        status: StatusPublisher,
        status_delay: Callable[[], float],
        move_accepted: Callable[[], None],
    ) -> None:
        self.robot = robot
        self.config = config
        self.image = image
        self.status = status
        self._status_delay = status_delay
        self._move_accepted = move_accepted

    def _hold(self, *, latency: bool, read_hold: bool) -> None:
        self.status.hold(
            time.monotonic(),
            self.robot.command_status,
            pickup=self._status_delay(),
            latency=latency,
            read_hold=read_hold,
        )

    def handle_write(self, regs: list[int], start: int, address: int, count: int) -> ExcCodes | None:
        """Act on the control registers a write covered (values already in ``regs``)."""
        covered = range(address, address + count)
        if _touches(covered, _GV291_REGS):
            refused = self._host_wrote_status(regs, start)
            if refused is not None:
                return refused

        def value(reg: int) -> int:
            return regs[reg - start]

        if REG_WORK_MODE in covered and not self._set_work_mode(value(REG_WORK_MODE)):
            return ExcCodes.ILLEGAL_VALUE
        self._press_buttons(covered, value)
        if self.robot.teach_enabled and _touches(covered, _RATIO_REGS):
            gv = self.image.gv
            self.robot.set_teach_ratio(
                gv(regs, start, GV_PARAM3), gv(regs, start, GV_PARAM1), gv(regs, start, GV_PARAM2)
            )
        if REG_RUN_COMMAND in covered:
            return self._run_command(regs, start, value(REG_RUN_COMMAND))
        return None

    def _set_work_mode(self, mode: int) -> bool:
        if not self.robot.set_work_mode(mode):
            return False
        log.info("work mode -> %s", self.robot.work_mode.name)
        return True

    def _press_buttons(self, covered: range, value: Callable[[int], int]) -> None:
        """The registers that act when written: stop, pause, resume (on a 1), go to zero (an axis)."""
        robot = self.robot
        if REG_STOP in covered and value(REG_STOP) == 1:
            self._hold(latency=False, read_hold=False)
            robot.stop()
            log.info("stop")
        if REG_PAUSE in covered and value(REG_PAUSE) == 1:
            log.info("pause%s", "" if robot.pause() else " (nothing to pause)")
        if REG_RESUME in covered and value(REG_RESUME) == 1:
            log.info("resume%s", "" if robot.resume() else " (nothing paused)")
        if REG_GO_ZERO in covered:
            axis = value(REG_GO_ZERO)
            log.info(
                "go to zero %s: %s",
                "all" if axis == 11 else f"J{axis + 1}",
                "started" if robot.go_zero(axis) else "refused",
            )

    def _run_command(self, regs: list[int], start: int, code: int) -> ExcCodes | None:
        try:
            command = RunCommand(code)
        except ValueError:
            log.warning("unknown run command 0x%02X refused", code)
            return ExcCodes.ILLEGAL_VALUE
        if command in _STATUS_COMMANDS:
            # moves show 6 (moving) as their own evidence; only the instant commands wait
            # for a host to have seen the 0 (classic profile)
            self._hold(latency=True, read_hold=command in _INSTANT_COMMANDS)
        params = _Params(
            p=self.image.gvs(regs, start, GV_PARAM0, 6),
            speed=self.image.gv(regs, start, GV_EXPECTED_SPEED),
            ext=self.image.gvs(regs, start, GV_EXT_OFFSET0, NUM_EXTERNAL_AXES),
            tool=self.image.gv(regs, start, GV_TOOL_FRAME),
        )
        if command is RunCommand.RUN_PROGRAM:
            self._run_program(regs, start)
            return None
        if command is RunCommand.CREATE_POINT:
            status = self._create_point(regs, start, params)
            if status is None:
                return None
        else:
            status = _ROBOT_COMMANDS[command](self.robot, params)
        if command in _MOVE_COMMANDS:
            self._move_accepted()
        log.info("%s -> status %s", command.name, status)
        return None

    def _run_program(self, regs: list[int], start: int) -> None:
        ok = self.robot.run_program(
            regs[REG_PROGRAM_ID - start],
            regs[REG_PROGRAM_MODE - start],
            regs[REG_CYCLE_COUNT - start],
            regs[REG_PROGRAM_SPEED - start],
        )
        log.info("run program %d: %s", regs[REG_PROGRAM_ID - start], "started" if ok else "refused")

    def _create_point(self, regs: list[int], start: int, c: _Params) -> int | None:
        """Create point ``c.p[0]`` from the current pose (GV201 = 0) or from six GVs (GV201 = 1,
        the first in GV202); its status, or None when the source was refused (status 1, said)."""
        robot = self.robot
        source = c.p[1]
        pose: list[float] | None = None
        if source == 1:
            first = robot.gv_source_ok(c.p[2])
            if first is None:
                self._refuse_create_point()
                log.info("create point %s refused: GV202 = %s is not a GV index 0..94", c.p[0], c.p[2])
                return None
            pose = self.image.gvs(regs, start, first, 6)
        elif source != 0:
            self._refuse_create_point()
            log.info("create point %s refused: GV201 = %s (0 current pose, 1 from GVs)", c.p[0], source)
            return None
        return robot.create_point(c.p[0], pose, c.tool)

    def _refuse_create_point(self) -> None:
        self.robot.last_kind = CommandKind.CREATE_POINT
        self.robot.command_status = 1

    def _host_wrote_status(self, regs: list[int], start: int) -> ExcCodes | None:
        """A host's write covered GV291: refuse it, keep it, or let the next refresh overwrite it."""
        mode = self.config.gv291
        if mode == "read-only":
            return ExcCodes.ILLEGAL_ADDRESS
        if mode == "writable":
            s = _GV291_REGS.start - start
            self.robot.command_status = decode_status_registers(regs[s : s + 2], self.config.word_order)
            self.status.release()  # the host's value shows at once
            log.info("host wrote GV291 = %d", self.robot.command_status)
        return None

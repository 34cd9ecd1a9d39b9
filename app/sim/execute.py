"""Command execution of the simulated controller: what a host's write to the control registers
does (work mode, stop, pause, resume, go to zero, teach ratio, the 440 run command with its
parameters in GV200..GV205 and GV244..GV245, a write to GV291). Called by
:class:`~app.sim.server.SimController` under its lock, the written values already in ``regs``.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable

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
        robot = self.robot
        if _GV291_REGS.start in covered or _GV291_REGS.stop - 1 in covered:
            refused = self._host_wrote_status(regs, start)
            if refused is not None:
                return refused

        def value(reg: int) -> int:
            return regs[reg - start]

        if REG_WORK_MODE in covered:
            if not robot.set_work_mode(value(REG_WORK_MODE)):
                return ExcCodes.ILLEGAL_VALUE
            log.info("work mode -> %s", robot.work_mode.name)
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
        ratio_regs = range(gv_reg(GV_PARAM3), gv_reg(GV_PARAM3) + 2)
        if robot.teach_enabled and (ratio_regs.start in covered or ratio_regs.stop - 1 in covered):
            gv = self.image.gv
            robot.set_teach_ratio(
                gv(regs, start, GV_PARAM3), gv(regs, start, GV_PARAM1), gv(regs, start, GV_PARAM2)
            )
        if REG_RUN_COMMAND in covered:
            return self._run_command(regs, start, value(REG_RUN_COMMAND))
        return None

    def _run_command(self, regs: list[int], start: int, code: int) -> ExcCodes | None:
        try:
            command = RunCommand(code)
        except ValueError:
            log.warning("unknown run command 0x%02X refused", code)
            return ExcCodes.ILLEGAL_VALUE
        robot = self.robot
        if command in _STATUS_COMMANDS:
            # moves show 6 (moving) as their own evidence; only the instant commands wait
            # for a host to have seen the 0 (classic profile)
            self._hold(
                latency=True,
                read_hold=command
                in (RunCommand.CREATE_POINT, RunCommand.TEACH_ENABLE, RunCommand.TEACH_DISABLE),
            )
        p = self.image.gvs(regs, start, GV_PARAM0, 6)
        speed = self.image.gv(regs, start, GV_EXPECTED_SPEED)
        ext = self.image.gvs(regs, start, GV_EXT_OFFSET0, NUM_EXTERNAL_AXES)
        tool = self.image.gv(regs, start, GV_TOOL_FRAME)
        status: int | None = None
        if command is RunCommand.RUN_PROGRAM:
            ok = robot.run_program(
                regs[REG_PROGRAM_ID - start],
                regs[REG_PROGRAM_MODE - start],
                regs[REG_CYCLE_COUNT - start],
                regs[REG_PROGRAM_SPEED - start],
            )
            log.info("run program %d: %s", regs[REG_PROGRAM_ID - start], "started" if ok else "refused")
            return None
        if command is RunCommand.STEP_JOINT:
            status = robot.step_joint(p + ext, speed)
        elif command is RunCommand.STEP_BASE:
            status = robot.step_base(p, speed, ext)
        elif command is RunCommand.MOVE_TO_POINT:
            status = robot.move_to_point(p[0], p[1], p[2], p[3], speed, tool)
        elif command is RunCommand.CREATE_POINT:
            source = p[1]
            pose: list[float] | None = None
            if source == 1:
                first = robot.gv_source_ok(p[2])
                if first is None:
                    robot.last_kind = CommandKind.CREATE_POINT
                    robot.command_status = 1
                    log.info("create point %s refused: GV202 = %s is not a GV index 0..94", p[0], p[2])
                    return None
                pose = self.image.gvs(regs, start, first, 6)
            elif source != 0:
                robot.last_kind = CommandKind.CREATE_POINT
                robot.command_status = 1
                log.info("create point %s refused: GV201 = %s (0 current pose, 1 from GVs)", p[0], source)
                return None
            status = robot.create_point(p[0], pose, tool)
        elif command is RunCommand.TEACH_ENABLE:
            status = robot.teach_enable(p[0], p[3])
        elif command is RunCommand.TEACH_DISABLE:
            status = robot.teach_disable(p[3])
        if command in (RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT):
            self._move_accepted()
        log.info("%s -> status %s", command.name, status)
        return None

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

"""The simulated controller's register image: GV floats in the configured word order, the
power-on values, and the live registers (pose, joints, mode, program state, alarms, clock,
GV291) refreshed from :class:`~app.sim.robot.SimRobot` before every answer. GV291 is a float32
by default, or the integer in register 582 (583 = 0) with ``status_encoding="int"``.

Project extension: joints J1..J6 in GV250..GV255 (registers 500..511).
"""

from __future__ import annotations

import datetime as dt

from app.protocol.codec import encode_floats, float_to_registers, registers_to_float
from app.protocol.datetime_regs import encode_clock
from app.protocol.registers import (
    GV_COMMAND_STATUS,
    GV_DATE,
    GV_EXPECTED_SPEED,
    GV_EXT_AXES,
    GV_JOINTS,
    GV_PARAM0,
    GV_POSE,
    GV_TOOL_FRAME,
    NUM_EXTERNAL_AXES,
    NUM_ROBOT_AXES,
    REG_ALARMS,
    REG_CONTROLLER_MODE,
    REG_CYCLE_COUNT,
    REG_PROGRAM_ID,
    REG_PROGRAM_MODE,
    REG_PROGRAM_SPEED,
    REG_PROGRAM_STATE,
    REG_WORK_MODE,
    gv_reg,
)
from app.sim.config import SimConfig
from app.sim.robot import SimRobot


class RegisterImage:
    """Reads and writes of the register block a request sees (``regs`` starts at ``start``)."""

    def __init__(self, config: SimConfig) -> None:
        self.config = config

    def init(self, regs: list[int]) -> None:
        """The power-on values of the control registers and parameter GVs."""
        regs[REG_PROGRAM_ID] = 1
        regs[REG_PROGRAM_MODE] = 1
        regs[REG_CYCLE_COUNT] = 1
        regs[REG_PROGRAM_SPEED] = 100
        regs[REG_WORK_MODE] = int(self.config.work_mode)
        self.put_floats(regs, 0, gv_reg(GV_EXPECTED_SPEED), [10.0])
        self.put_floats(regs, 0, gv_reg(GV_TOOL_FRAME), [200.0])
        self.put_floats(regs, 0, gv_reg(GV_PARAM0), [0.0] * 6)

    def put_floats(self, regs: list[int], start: int, address: int, values: list[float]) -> None:
        encoded = encode_floats(values, self.config.word_order)
        regs[address - start : address - start + len(encoded)] = encoded

    def gv(self, regs: list[int], start: int, n: int) -> float:
        a = gv_reg(n) - start
        return registers_to_float(regs[a : a + 2], self.config.word_order)

    def gvs(self, regs: list[int], start: int, n: int, count: int) -> list[float]:
        return [self.gv(regs, start, n + i) for i in range(count)]

    def refresh(self, regs: list[int], start: int, robot: SimRobot, status: int) -> None:
        """The live registers from ``robot``; ``status`` is GV291 as published now."""
        self.put_floats(regs, start, gv_reg(GV_POSE), list(robot.pose))
        joints = [float(v) for v in robot.joints]
        ext = joints[NUM_ROBOT_AXES : NUM_ROBOT_AXES + NUM_EXTERNAL_AXES]
        self.put_floats(regs, start, gv_reg(GV_EXT_AXES), ext)
        self.put_floats(regs, start, gv_reg(GV_JOINTS), joints[:NUM_ROBOT_AXES])
        regs[REG_CONTROLLER_MODE - start] = int(robot.controller_mode)
        regs[REG_PROGRAM_STATE - start] = int(robot.program_state)
        regs[REG_ALARMS - start] = int(robot.alarms) & 0xFFFF
        now = dt.datetime.now() + dt.timedelta(seconds=self.config.clock_offset)
        clock = encode_clock(now, self.config.datetime_layout)
        d = gv_reg(GV_DATE) - start
        regs[d : d + 4] = clock
        s = gv_reg(GV_COMMAND_STATUS) - start
        if self.config.status_encoding == "int":
            regs[s : s + 2] = [status & 0xFFFF, 0]
        else:
            regs[s : s + 2] = float_to_registers(float(status), self.config.word_order)

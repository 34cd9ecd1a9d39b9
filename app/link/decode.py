"""The controller's register blocks decoded into the core's dataclasses (pure functions)."""

from __future__ import annotations

from collections.abc import Sequence

from app.models import ControllerStatus, Pose
from app.protocol import registers
from app.protocol.codec import WordOrder, decode_floats
from app.protocol.datetime_regs import DateTimeLayout, decode_clock
from app.protocol.enums import Alarm, ControllerMode, ProgramState, decode_status_registers

__all__ = ["decode_pose", "decode_status"]

# looked up, not constructed, per status read (an Enum call is a few microseconds, every poll)
_MODES = {int(m): m for m in ControllerMode}
_STATES = {int(s): s for s in ProgramState}
_NO_ALARM = Alarm(0)


def decode_pose(regs: Sequence[int], order: WordOrder) -> Pose:
    """The pose block (GV206..GV255, registers 412..511): pose, external axes, joints."""

    def gvs(gv: int, count: int) -> list[float]:
        start = registers.gv_reg(gv) - registers.POSE_BLOCK_START
        return decode_floats(regs[start : start + 2 * count], order)

    x, y, z, a, b, c = gvs(registers.GV_POSE, 6)
    e = gvs(registers.GV_EXT_AXES, registers.NUM_EXTERNAL_AXES)
    joints = tuple(gvs(registers.GV_JOINTS, registers.NUM_ROBOT_AXES))
    return Pose(x, y, z, a, b, c, ext=(e[0], e[1], e[2], e[3], e[4]), joints=joints)


def decode_status(
    regs: Sequence[int], order: WordOrder, clock_layout: DateTimeLayout | None
) -> ControllerStatus:
    """Table 2 (560..583); the clock too when ``clock_layout`` is given."""
    base = registers.STATUS_BLOCK_START
    mode_raw = regs[registers.REG_CONTROLLER_MODE - base]
    state_raw = regs[registers.REG_PROGRAM_STATE - base]
    mode: ControllerMode | int = _MODES.get(mode_raw, mode_raw)  # an unknown value stays an int
    state: ProgramState | int = _STATES.get(state_raw, state_raw)
    alarms_raw = regs[registers.REG_ALARMS - base]
    st = registers.gv_reg(registers.GV_COMMAND_STATUS) - base
    code = decode_status_registers(regs[st : st + 2], order)
    clock = None
    if clock_layout is not None:
        cs = registers.gv_reg(registers.GV_DATE) - base
        clock = decode_clock(regs[cs : cs + 4], clock_layout)
    return ControllerStatus(mode, state, _NO_ALARM if alarms_raw == 0 else Alarm(alarms_raw), code, clock)

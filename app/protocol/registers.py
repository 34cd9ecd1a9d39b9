"""Register arithmetic and the register map of the controller.

A global variable ``GVn`` (float32) occupies holding registers ``2n`` (``GVn_L``) and
``2n + 1`` (``GVn_H``), whatever the word order (PROTOCOL.md section 1, erratum E10).
Addresses are 0-based PDU addresses.
"""

from __future__ import annotations

from typing import Final


def gv_reg(n: int) -> int:
    """First (``_L``) register of global variable ``GVn``."""
    if n < 0:
        raise ValueError(f"GV index must be >= 0, got {n}")
    return 2 * n


def gv_low(n: int) -> int:
    """Register of ``GVn_L``."""
    return gv_reg(n)


def gv_high(n: int) -> int:
    """Register of ``GVn_H``."""
    return gv_reg(n) + 1


def reg_to_gv(register: int) -> tuple[int, str]:
    """Map a register back to ``(n, "L"|"H")``."""
    if register < 0:
        raise ValueError(f"register must be >= 0, got {register}")
    return register // 2, ("L" if register % 2 == 0 else "H")


# --- Table 1: control registers (integers, written with 0x06) -------------------------
REG_RUN_COMMAND: Final = 440  # GV220_L
REG_STOP: Final = 441  # GV220_H
REG_PAUSE: Final = 442  # GV221_L
REG_RESUME: Final = 443  # GV221_H
REG_WORK_MODE: Final = 444  # GV222_L
REG_GO_ZERO: Final = 445  # GV222_H
REG_PROGRAM_ID: Final = 446  # GV223_L
REG_PROGRAM_MODE: Final = 447  # GV223_H
REG_CYCLE_COUNT: Final = 448  # GV224_L
REG_PROGRAM_SPEED: Final = 449  # GV224_H
GV_EXPECTED_SPEED: Final = 225  # regs 450-451, float: rpm (joint) or mm/s (linear)
REG_RESOURCE_TYPE: Final = 452  # GV226_L
REG_RESOURCE_PARAM: Final = 453  # GV226_H

# --- Parameter GVs (float32) ------------------------------------------------------------
GV_PARAM0: Final = 200  # GV200..GV205: offsets / point id / motion type / frame ...
GV_PARAM1: Final = 201
GV_PARAM2: Final = 202
GV_PARAM3: Final = 203  # teach speed ratio (function 4)
GV_PARAM5: Final = 205
GV_EXT_OFFSET0: Final = 236  # GV236..GV240: J7..J11 incremental offsets
GV_USER_FRAME: Final = 241
GV_TOOL_FRAME: Final = 245
TOOL_NONE: Final = 200  # GV245 = 200: no tool frame; N: tool frame N (PROTOCOL.md: the controller's tool N+1)

# --- Live values (read with 0x03) -------------------------------------------------------
GV_POSE: Final = 206  # GV206..GV211: X Y Z A B C, base frame
GV_EXT_AXES: Final = 212  # GV212..GV216: the external axes J7..J11 (PROTOCOL.md: EJ1..EJ5)
# Project extension (not in the seed): joint angles J1..J6 published in spare GVs.
GV_JOINTS: Final = 250  # GV250..GV255 (registers 500-511)

# --- Table 2: status registers (read only) ----------------------------------------------
REG_CONTROLLER_MODE: Final = 560  # GV280_L
REG_PROGRAM_STATE: Final = 561  # GV280_H
REG_ALARMS: Final = 562  # GV281_L
GV_DATE: Final = 288  # regs 576-577
GV_TIME: Final = 289  # regs 578-579
GV_COMMAND_STATUS: Final = 291  # regs 582-583

# General-purpose GVs the host may use to pass a pose (case 2.2).
GV_GENERAL_FIRST: Final = 0
GV_GENERAL_LAST: Final = 99

# --- The general-purpose GVs TeachPad takes for itself (a controller restart clears them) ---------
# Every one is named here and nowhere else.
POSE_GVS: Final = 6  # a pose passed in GVs: X Y Z A B C
UPLOAD_POSE_GV: Final = 0  # GV0..GV5: the pose of the point being created (case 2.2)
UPLOAD_STAGE_GV: Final = 6  # GV6..GV11: the next point's pose, written while the previous one is created
UPLOAD_STAGE_GV_MOVED: Final = 12  # GV12..GV17: the staging block when the restart canary is in GV6..GV11
CANARY_GV: Final = 99  # the restart canary (registers 198-199): a random token; a restart clears it


def stage_gv_for(canary_gv: int | None) -> int:
    """The upload's second pose block: GV6..GV11, or GV12..GV17 when the restart canary is there."""
    if canary_gv is not None and UPLOAD_STAGE_GV <= canary_gv < UPLOAD_STAGE_GV + POSE_GVS:
        return UPLOAD_STAGE_GV_MOVED
    return UPLOAD_STAGE_GV


# --- Read blocks used by the monitor -----------------------------------------------------
# One FC03 can read at most 125 registers.
MAX_READ_REGISTERS: Final = 125
MAX_WRITE_REGISTERS: Final = 123
POSE_BLOCK_START: Final = gv_reg(GV_POSE)  # 412
POSE_BLOCK_COUNT: Final = gv_reg(GV_JOINTS) + 12 - POSE_BLOCK_START  # 412..511 = 100
STATUS_BLOCK_START: Final = REG_CONTROLLER_MODE  # 560
STATUS_BLOCK_COUNT: Final = gv_reg(GV_COMMAND_STATUS) + 2 - STATUS_BLOCK_START  # 560..583 = 24

# Highest register the simulator serves (a little headroom above GV291).
REGISTER_SPACE: Final = 1024

# Temp points: 10000 on the controller; accepted range is a setting (PROTOCOL.md section 7).
TEMP_POINT_CAPACITY: Final = 10000
TEMP_POINT_ID_MIN: Final = 0
TEMP_POINT_ID_MAX: Final = 10000

NUM_ROBOT_AXES: Final = 6
NUM_EXTERNAL_AXES: Final = 5
NUM_AXES_TOTAL: Final = 11
GO_ZERO_ALL: Final = 0x0B

"""Register arithmetic and the register map (app/protocol/registers.py)."""

from __future__ import annotations

import pytest

from app.protocol import registers as r


@pytest.mark.parametrize(
    ("n", "low", "high"),
    [
        (0, 0, 1),
        (1, 2, 3),
        (200, 400, 401),
        (206, 412, 413),
        (220, 440, 441),
        (225, 450, 451),
        (245, 490, 491),
        (280, 560, 561),
        (291, 582, 583),
    ],
)
def test_gv_registers(n: int, low: int, high: int) -> None:
    assert r.gv_reg(n) == r.gv_low(n) == low
    assert r.gv_high(n) == high
    assert r.reg_to_gv(low) == (n, "L")
    assert r.reg_to_gv(high) == (n, "H")


@pytest.mark.parametrize(
    "call", [lambda: r.gv_reg(-1), lambda: r.gv_low(-1), lambda: r.gv_high(-1), lambda: r.reg_to_gv(-1)]
)
def test_negative_indexes_are_refused(call: object) -> None:
    assert callable(call)
    with pytest.raises(ValueError):
        call()


@pytest.mark.parametrize(
    ("register", "gv"),
    [
        (r.REG_RUN_COMMAND, (220, "L")),
        (r.REG_STOP, (220, "H")),
        (r.REG_PAUSE, (221, "L")),
        (r.REG_RESUME, (221, "H")),
        (r.REG_WORK_MODE, (222, "L")),
        (r.REG_GO_ZERO, (222, "H")),
        (r.REG_PROGRAM_ID, (223, "L")),
        (r.REG_PROGRAM_MODE, (223, "H")),
        (r.REG_CYCLE_COUNT, (224, "L")),
        (r.REG_PROGRAM_SPEED, (224, "H")),
        (r.REG_RESOURCE_TYPE, (226, "L")),
        (r.REG_RESOURCE_PARAM, (226, "H")),
        (r.REG_CONTROLLER_MODE, (280, "L")),
        (r.REG_PROGRAM_STATE, (280, "H")),
        (r.REG_ALARMS, (281, "L")),
    ],
)
def test_table_registers_are_the_documented_gv_halves(register: int, gv: tuple[int, str]) -> None:
    assert r.reg_to_gv(register) == gv


def test_table1_addresses() -> None:
    assert (r.REG_RUN_COMMAND, r.REG_STOP, r.REG_PAUSE, r.REG_RESUME) == (440, 441, 442, 443)
    assert (r.REG_WORK_MODE, r.REG_GO_ZERO, r.REG_PROGRAM_ID, r.REG_PROGRAM_MODE) == (444, 445, 446, 447)
    assert (r.REG_CYCLE_COUNT, r.REG_PROGRAM_SPEED) == (448, 449)
    assert r.gv_reg(r.GV_EXPECTED_SPEED) == 450
    assert (r.REG_RESOURCE_TYPE, r.REG_RESOURCE_PARAM) == (452, 453)


def test_parameter_and_live_gvs() -> None:
    assert [r.gv_reg(n) for n in (r.GV_PARAM0, r.GV_PARAM1, r.GV_PARAM2, r.GV_PARAM3, r.GV_PARAM5)] == [
        400,
        402,
        404,
        406,
        410,
    ]
    assert (r.gv_reg(r.GV_EXT_OFFSET0), r.gv_high(r.GV_EXT_OFFSET0 + 4)) == (472, 481)
    assert (r.gv_reg(r.GV_USER_FRAME), r.gv_reg(r.GV_TOOL_FRAME)) == (482, 490)
    assert r.TOOL_NONE == 200
    assert (r.gv_reg(r.GV_POSE), r.gv_high(r.GV_POSE + 5)) == (412, 423)  # erratum E3
    assert (r.gv_reg(r.GV_EXT_AXES), r.gv_high(r.GV_EXT_AXES + 4)) == (424, 433)
    assert (r.gv_reg(r.GV_JOINTS), r.gv_high(r.GV_JOINTS + 5)) == (500, 511)


def test_status_registers() -> None:
    assert (r.REG_CONTROLLER_MODE, r.REG_PROGRAM_STATE, r.REG_ALARMS) == (560, 561, 562)
    assert (r.gv_reg(r.GV_DATE), r.gv_high(r.GV_TIME)) == (576, 579)
    assert (r.gv_reg(r.GV_COMMAND_STATUS), r.gv_high(r.GV_COMMAND_STATUS)) == (582, 583)


def test_monitor_blocks_fit_one_read() -> None:
    assert (r.POSE_BLOCK_START, r.POSE_BLOCK_COUNT) == (412, 100)
    assert r.gv_high(r.GV_JOINTS + 5) == r.POSE_BLOCK_START + r.POSE_BLOCK_COUNT - 1
    assert (r.STATUS_BLOCK_START, r.STATUS_BLOCK_COUNT) == (560, 24)
    assert r.gv_high(r.GV_COMMAND_STATUS) == r.STATUS_BLOCK_START + r.STATUS_BLOCK_COUNT - 1
    assert max(r.POSE_BLOCK_COUNT, r.STATUS_BLOCK_COUNT) <= r.MAX_READ_REGISTERS == 125
    assert r.MAX_WRITE_REGISTERS == 123
    assert r.gv_high(r.GV_COMMAND_STATUS) < r.REGISTER_SPACE


def test_general_purpose_gvs_and_limits() -> None:
    assert (r.GV_GENERAL_FIRST, r.GV_GENERAL_LAST) == (0, 99)
    assert r.gv_high(r.GV_GENERAL_LAST) < r.gv_reg(r.GV_PARAM0)
    assert (r.TEMP_POINT_CAPACITY, r.TEMP_POINT_ID_MIN, r.TEMP_POINT_ID_MAX) == (10000, 0, 10000)
    assert (r.NUM_ROBOT_AXES, r.NUM_EXTERNAL_AXES, r.NUM_AXES_TOTAL) == (6, 5, 11)
    assert r.GO_ZERO_ALL == 0x0B

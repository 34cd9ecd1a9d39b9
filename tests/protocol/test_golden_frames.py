"""Golden frames: every Tx/Rx frame printed in the vendor's document (shared/seed/000_…txt).

Each frame is built byte for byte from the operation it performs (``write GV200 = 30.0``
with its transaction id), and decoded back into the right words. The seed's literal hex is
copied below as printed. Where the seed is wrong (PROTOCOL.md section 6) the tables hold the
corrected bytes, and each erratum has its own test quoting what the seed printed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import pytest

from app.protocol.codec import WordOrder, float_to_registers
from app.protocol.enums import RunCommand, WorkMode
from app.protocol.frames import DecodedFrame, FrameDecoder, decode_frame
from app.protocol.framing import FunctionCode, encode_request, encode_response, encode_write_gv
from app.protocol.naming import describe_registers
from app.protocol.registers import (
    GV_EXPECTED_SPEED,
    GV_PARAM0,
    GV_PARAM1,
    GV_PARAM2,
    GV_PARAM3,
    GV_POSE,
    GV_TOOL_FRAME,
    REG_RUN_COMMAND,
    REG_WORK_MODE,
    gv_high,
    gv_low,
    gv_reg,
    reg_to_gv,
)

FC03 = FunctionCode.READ_HOLDING_REGISTERS
FC06 = FunctionCode.WRITE_SINGLE_REGISTER
FC10 = FunctionCode.WRITE_MULTIPLE_REGISTERS


def h(text: str) -> bytes:
    """The seed's spaced hex (tabs and spaces alike) as bytes."""
    return bytes.fromhex(text)


# --- The semantic operations of the seed's cases --------------------------------------------


def work_mode_auto(tid: int) -> bytes:
    return encode_request(FC06, REG_WORK_MODE, [WorkMode.AUTO], transaction_id=tid)


def work_mode_auto_ack(tid: int) -> bytes:
    return encode_response(FC06, REG_WORK_MODE, [WorkMode.AUTO], transaction_id=tid)


def run_command(command: RunCommand, tid: int) -> bytes:
    return encode_request(FC06, REG_RUN_COMMAND, [command], transaction_id=tid)


def run_command_ack(command: RunCommand, tid: int) -> bytes:
    return encode_response(FC06, REG_RUN_COMMAND, [command], transaction_id=tid)


def write_gv(n: int, value: float | Sequence[float], tid: int) -> bytes:
    return encode_write_gv(n, value, transaction_id=tid)


def write_gv_ack(n: int, tid: int, gvs: int = 1) -> bytes:
    return encode_response(FC10, gv_reg(n), count=2 * gvs, transaction_id=tid)


@dataclass(frozen=True)
class Step:
    id: str
    tx: str  # as printed in the seed (corrected where an erratum says so)
    rx: str
    build_tx: Callable[[], bytes]
    build_rx: Callable[[], bytes]
    tx_summary: str  # decoded without knowing which function the parameters are for
    rx_summary: str
    tx_named: str  # decoded with the case's function (``params_for``)


def _mode(case: str, tid: int = 0) -> Step:
    return Step(
        f"{case}-mode-auto",
        "00 00 00 00\t00 06\t01 06 01 BC 00 01",
        "00 00 00 00\t00 06\t01 06 01 BC 00 01",
        lambda: work_mode_auto(tid),
        lambda: work_mode_auto_ack(tid),
        "work mode auto (444 ← 1)",
        "ack work mode auto (444 ← 1)",
        "work mode auto (444 ← 1)",
    )


# Case 1: incremental move of J1 by 30° (function 1, joint frame).
CASE_1 = [
    _mode("case1"),
    Step(
        "case1-step2-GV200=30",
        "00 01 00 00\t00 0B\t01 10 01 90 00 02 04 00 00 41 F0",
        "00 01 00 00\t00 06\t01 10 01 90 00 02",
        lambda: write_gv(GV_PARAM0, 30.0, 1),
        lambda: write_gv_ack(GV_PARAM0, 1),
        "write GV200 = 30.0",
        "ack write GV200 (400–401)",
        "write GV200 J1 offset = 30.0",
    ),
    Step(
        "case1-step3-GV225=100",
        "00 02 00 00\t00 0B\t01 10 01 C2 00 02 04 00 00 42 C8",
        "00 02 00 00\t00 06\t01 10 01 C2 00 02",
        lambda: write_gv(GV_EXPECTED_SPEED, 100.0, 2),
        lambda: write_gv_ack(GV_EXPECTED_SPEED, 2),
        "write GV225 speed = 100.0",
        "ack write GV225 (450–451)",
        "write GV225 speed = 100.0",
    ),
    Step(
        "case1-step4-440=0x40",
        "00 03 00 00\t00 06\t01 06 01 B8 00 40",
        "00 03 00 00\t00 06\t01 06 01 B8 00 40",
        lambda: run_command(RunCommand.STEP_JOINT, 3),
        lambda: run_command_ack(RunCommand.STEP_JOINT, 3),
        "incremental move (joint) (440 ← 0x40)",
        "ack incremental move (joint) (440 ← 0x40)",
        "incremental move (joint) (440 ← 0x40)",
    ),
]

# Case 2.1: create temp point 1 from the current pose (function 2).
CASE_2_1 = [
    _mode("case2.1"),
    Step(
        "case2.1-step2-GV200=1",
        "00 01 00 00\t00 0B\t01 10 01 90 00 02 04 00 00 3F 80",
        "00 01 00 00\t00 06\t01 10 01 90 00 02",
        lambda: write_gv(GV_PARAM0, 1.0, 1),
        lambda: write_gv_ack(GV_PARAM0, 1),
        "write GV200 = 1.0",
        "ack write GV200 (400–401)",
        "write GV200 point id = 1.0",
    ),
    Step(
        "case2.1-step3-GV201=0",
        "00 02 00 00\t00 0B\t01 10 01 92 00 02 04 00 00 00 00",
        "00 02 00 00\t00 06\t01 10 01 92 00 02",
        lambda: write_gv(GV_PARAM1, 0.0, 2),
        lambda: write_gv_ack(GV_PARAM1, 2),
        "write GV201 = 0.0",
        "ack write GV201 (402–403)",
        "write GV201 source = 0.0 (current pose)",
    ),
    # The seed numbers this step "3" again and reuses transaction id 2: both as printed.
    Step(
        "case2.1-step3b-GV245=0",
        "00 02 00 00\t00 0B\t01 10 01 EA 00 02 04 00 00 00 00",
        "00 02 00 00\t00 06\t01 10 01 EA 00 02",
        lambda: write_gv(GV_TOOL_FRAME, 0.0, 2),
        lambda: write_gv_ack(GV_TOOL_FRAME, 2),
        "write GV245 tool = 0.0 (tool 0)",
        "ack write GV245 (490–491)",
        "write GV245 tool = 0.0 (tool 0)",
    ),
    Step(
        "case2.1-step4-440=0xE0",
        "00 03 00 00\t00 06\t01 06 01 B8 00 E0",
        "00 03 00 00\t00 06\t01 06 01 B8 00 E0",
        lambda: run_command(RunCommand.CREATE_POINT, 3),
        lambda: run_command_ack(RunCommand.CREATE_POINT, 3),
        "create temp point (440 ← 0xE0)",
        "ack create temp point (440 ← 0xE0)",
        "create temp point (440 ← 0xE0)",
    ),
]

# Case 2.2: re-create cached points from GVs. Steps 1 and 5 carry placeholders: see below.
CASE_2_2 = [
    Step(
        "case2.2-step3-GV201=1",
        "00 01 00 00\t00 0B\t01 10 01 92 00 02 04 00 00 3F 80",
        "00 01 00 00\t00 06\t01 10 01 92 00 02",
        lambda: write_gv(GV_PARAM1, 1.0, 1),
        lambda: write_gv_ack(GV_PARAM1, 1),
        "write GV201 = 1.0",
        "ack write GV201 (402–403)",
        "write GV201 source = 1.0 (from GVs)",
    ),
    Step(
        "case2.2-step4-GV245=0",
        "00 02 00 00\t00 0B\t01 10 01 EA 00 02 04 00 00 00 00",
        "00 02 00 00\t00 06\t01 10 01 EA 00 02",
        lambda: write_gv(GV_TOOL_FRAME, 0.0, 2),
        lambda: write_gv_ack(GV_TOOL_FRAME, 2),
        "write GV245 tool = 0.0 (tool 0)",
        "ack write GV245 (490–491)",
        "write GV245 tool = 0.0 (tool 0)",
    ),
    Step(
        "case2.2-step6-GV202=0",
        "00 04 00 00\t00 0B\t01 10 01 94 00 02 04 00 00 00 00",
        "00 04 00 00\t00 06\t01 10 01 94 00 02",
        lambda: write_gv(GV_PARAM2, 0.0, 4),
        lambda: write_gv_ack(GV_PARAM2, 4),
        "write GV202 = 0.0",
        "ack write GV202 (404–405)",
        "write GV202 first GV = 0.0",
    ),
    Step(
        "case2.2-step7-GV200=1",
        "00 05 00 00\t00 0B\t01 10 01 90 00 02 04 00 00 3F 80",
        "00 05 00 00\t00 06\t01 10 01 90 00 02",
        lambda: write_gv(GV_PARAM0, 1.0, 5),
        lambda: write_gv_ack(GV_PARAM0, 5),
        "write GV200 = 1.0",
        "ack write GV200 (400–401)",
        "write GV200 point id = 1.0",
    ),
    Step(
        "case2.2-step8-440=0xE0",
        "00 06 00 00\t00 06\t01 06 01 B8 00 E0",
        "00 06 00 00\t00 06\t01 06 01 B8 00 E0",
        lambda: run_command(RunCommand.CREATE_POINT, 6),
        lambda: run_command_ack(RunCommand.CREATE_POINT, 6),
        "create temp point (440 ← 0xE0)",
        "ack create temp point (440 ← 0xE0)",
        "create temp point (440 ← 0xE0)",
    ),
]

# Case 3: move to temp point 1 along a line (function 3).
CASE_3 = [
    _mode("case3"),
    Step(
        "case3-step2-GV200=-1",
        "00 01 00 00\t00 0B\t01 10 01 90 00 02 04 00 00 BF 80",
        "00 01 00 00\t00 06\t01 10 01 90 00 02",
        lambda: write_gv(GV_PARAM0, -1.0, 1),
        lambda: write_gv_ack(GV_PARAM0, 1),
        "write GV200 = -1.0",
        "ack write GV200 (400–401)",
        "write GV200 motion = -1.0 (line)",
    ),
    Step(
        "case3-step3-GV201=1",
        "00 02 00 00\t00 0B\t01 10 01 92 00 02 04 00 00 3F 80",
        "00 02 00 00\t00 06\t01 10 01 92 00 02",
        lambda: write_gv(GV_PARAM1, 1.0, 2),
        lambda: write_gv_ack(GV_PARAM1, 2),
        "write GV201 = 1.0",
        "ack write GV201 (402–403)",
        "write GV201 end point = 1.0",
    ),
    Step(
        "case3-step4-GV202=1",
        "00 03 00 00\t00 0B\t01 10 01 94 00 02 04 00 00 3F 80",
        "00 03 00 00\t00 06\t01 10 01 94 00 02",
        lambda: write_gv(GV_PARAM2, 1.0, 3),
        lambda: write_gv_ack(GV_PARAM2, 3),
        "write GV202 = 1.0",
        "ack write GV202 (404–405)",
        "write GV202 orientation = 1.0 (changes)",
    ),
    Step(
        "case3-step4b-GV225=100",
        "00 04 00 00\t00 0B\t01 10 01 C2 00 02 04 00 00 42 C8",
        "00 04 00 00\t00 06\t01 10 01 C2 00 02",
        lambda: write_gv(GV_EXPECTED_SPEED, 100.0, 4),
        lambda: write_gv_ack(GV_EXPECTED_SPEED, 4),
        "write GV225 speed = 100.0",
        "ack write GV225 (450–451)",
        "write GV225 speed = 100.0",
    ),
    Step(
        "case3-step5-GV245=0",
        "00 05 00 00\t00 0B\t01 10 01 EA 00 02 04 00 00 00 00",
        "00 05 00 00\t00 06\t01 10 01 EA 00 02",
        lambda: write_gv(GV_TOOL_FRAME, 0.0, 5),
        lambda: write_gv_ack(GV_TOOL_FRAME, 5),
        "write GV245 tool = 0.0 (tool 0)",
        "ack write GV245 (490–491)",
        "write GV245 tool = 0.0 (tool 0)",
    ),
    Step(
        "case3-step6-440=0x42",
        "00 06 00 00\t00 06\t01 06 01 B8 00 42",
        "00 06 00 00\t00 06\t01 06 01 B8 00 42",
        lambda: run_command(RunCommand.MOVE_TO_POINT, 6),
        lambda: run_command_ack(RunCommand.MOVE_TO_POINT, 6),
        "move to temp point (440 ← 0x42)",
        "ack move to temp point (440 ← 0x42)",
        "move to temp point (440 ← 0x42)",
    ),
]

# Case 4: jog X+ in the base frame (function 4). Steps 2-4 use the corrected bytes (E4, E5).
CASE_4 = [
    _mode("case4"),
    Step(
        "case4-step2-GV200=0",
        "00 01 00 00 00 0B 01 10 01 90 00 02 04 00 00 00 00",
        "00 01 00 00 00 06 01 10 01 90 00 02",
        lambda: write_gv(GV_PARAM0, 0.0, 1),
        lambda: write_gv_ack(GV_PARAM0, 1),
        "write GV200 = 0.0",
        "ack write GV200 (400–401)",
        "write GV200 frame = 0.0 (base)",
    ),
    Step(
        "case4-step3-GV201=0",
        "00 02 00 00 00 0B 01 10 01 92 00 02 04 00 00 00 00",
        "00 02 00 00 00 06 01 10 01 92 00 02",
        lambda: write_gv(GV_PARAM1, 0.0, 2),
        lambda: write_gv_ack(GV_PARAM1, 2),
        "write GV201 = 0.0",
        "ack write GV201 (402–403)",
        "write GV201 axis = 0.0 (X or J1)",
    ),
    Step(
        "case4-step4-GV202=1",
        "00 03 00 00 00 0B 01 10 01 94 00 02 04 00 00 3F 80",
        "00 03 00 00 00 06 01 10 01 94 00 02",
        lambda: write_gv(GV_PARAM2, 1.0, 3),
        lambda: write_gv_ack(GV_PARAM2, 3),
        "write GV202 = 1.0",
        "ack write GV202 (404–405)",
        "write GV202 direction = 1.0 (positive)",
    ),
    Step(
        "case4-step5-GV203=0",
        "00 04 00 00 00 0B 01 10 01 96 00 02 04 00 00 00 00",
        "00 04 00 00 00 06 01 10 01 96 00 02",
        lambda: write_gv(GV_PARAM3, 0.0, 4),
        lambda: write_gv_ack(GV_PARAM3, 4),
        "write GV203 = 0.0",
        "ack write GV203 (406–407)",
        "write GV203 speed ratio = 0.0",
    ),
    Step(
        "case4-step6-440=0x80",
        "00 05 00 00 00 06 01 06 01 B8 00 80",
        "00 05 00 00 00 06 01 06 01 B8 00 80",
        lambda: run_command(RunCommand.TEACH_ENABLE, 5),
        lambda: run_command_ack(RunCommand.TEACH_ENABLE, 5),
        "teach enable (440 ← 0x80)",
        "ack teach enable (440 ← 0x80)",
        "teach enable (440 ← 0x80)",
    ),
    Step(
        "case4-step7-GV203=10",
        "00 06 00 00 00 0B 01 10 01 96 00 02 04 00 00 41 20",
        "00 06 00 00 00 06 01 10 01 96 00 02",
        lambda: write_gv(GV_PARAM3, 10.0, 6),
        lambda: write_gv_ack(GV_PARAM3, 6),
        "write GV203 = 10.0",
        "ack write GV203 (406–407)",
        "write GV203 speed ratio = 10.0",
    ),
    Step(
        "case4-step8-440=0x81",
        "00 07 00 00 00 06 01 06 01 B8 00 81",
        "00 07 00 00 00 06 01 06 01 B8 00 81",
        lambda: run_command(RunCommand.TEACH_DISABLE, 7),
        lambda: run_command_ack(RunCommand.TEACH_DISABLE, 7),
        "teach disable (440 ← 0x81)",
        "ack teach disable (440 ← 0x81)",
        "teach disable (440 ← 0x81)",
    ),
]

CASES: dict[str, tuple[list[Step], RunCommand]] = {
    "case1": (CASE_1, RunCommand.STEP_JOINT),
    "case2.1": (CASE_2_1, RunCommand.CREATE_POINT),
    "case2.2": (CASE_2_2, RunCommand.CREATE_POINT),
    "case3": (CASE_3, RunCommand.MOVE_TO_POINT),
    "case4": (CASE_4, RunCommand.TEACH_ENABLE),
}
STEPS = [(step, function) for steps, function in CASES.values() for step in steps]
STEP_IDS = [step.id for step, _ in STEPS]


@pytest.mark.parametrize(("step", "function"), STEPS, ids=STEP_IDS)
def test_request_is_encoded_byte_for_byte(step: Step, function: RunCommand) -> None:
    assert step.build_tx() == h(step.tx)


@pytest.mark.parametrize(("step", "function"), STEPS, ids=STEP_IDS)
def test_response_is_encoded_byte_for_byte(step: Step, function: RunCommand) -> None:
    assert step.build_rx() == h(step.rx)


@pytest.mark.parametrize(("step", "function"), STEPS, ids=STEP_IDS)
def test_request_decodes_to_its_operation(step: Step, function: RunCommand) -> None:
    frame = decode_frame(h(step.tx), transport="tcp", direction="tx")
    assert frame.errors == ()
    assert not frame.is_response
    assert frame.summary == step.tx_summary
    assert frame.hex == " ".join(step.tx.split())
    named = decode_frame(h(step.tx), transport="tcp", direction="tx", params_for=function)
    assert named.summary == step.tx_named


@pytest.mark.parametrize(("step", "function"), STEPS, ids=STEP_IDS)
def test_response_pairs_with_its_request(step: Step, function: RunCommand) -> None:
    decoder = FrameDecoder("tcp")
    request = decoder.decode(h(step.tx), "tx")
    response = decoder.decode(h(step.rx), "rx")
    assert response.errors == ()
    assert response.is_response
    assert response.request is request
    assert response.transaction_id == request.transaction_id
    assert response.summary == step.rx_summary
    assert decoder.pending == 0


@pytest.mark.parametrize(("step", "function"), STEPS, ids=STEP_IDS)
def test_the_same_operation_over_rtu(step: Step, function: RunCommand) -> None:
    """Unit + PDU of the TCP frame, then the CRC: same words, same summary."""
    tcp = h(step.tx)
    frame = FrameDecoder("rtu").decode(tcp[6:] + _crc(tcp[6:]), "tx")
    assert frame.errors == ()
    assert frame.summary == step.tx_summary
    assert frame.transaction_id is None


def _crc(body: bytes) -> bytes:
    from pymodbus.framer import FramerRTU  # independent CRC: the project's own is tested elsewhere

    return int(FramerRTU.compute_CRC(body)).to_bytes(2, "big")


@pytest.mark.parametrize("case", list(CASES))
def test_a_whole_case_as_a_conversation(case: str) -> None:
    """Fed without directions, the decoder tells requests from echoes and pairs them."""
    steps, function = CASES[case]
    decoder = FrameDecoder("tcp", params_for=function)
    for step in steps:
        request = decoder.decode(h(step.tx))
        response = decoder.decode(h(step.rx))
        assert (request.is_response, response.is_response) == (False, True), step.id
        assert request.errors == response.errors == (), step.id
        assert request.summary == step.tx_named
        assert response.summary == step.rx_summary
    assert decoder.pending == 0
    # GV291 now answers the case's last command (case 4 ends with teach disable).
    last = RunCommand.TEACH_DISABLE if function is RunCommand.TEACH_ENABLE else function
    assert decoder.last_command is last


# --- Section 2 of the seed: the bare function-code examples (unit + PDU, no MBAP, no CRC) ---

SEED_06H_TX = "01 06 00 01 00 03"
SEED_10H_TX = "01 10 00 01 00 02 04 00 0A 01 02"
SEED_03H_TX = "01 03 00 6B 00 03"
SEED_03H_RX = "01 03 06 00 6B 00 13 00 00"


def test_section2_fc06_example() -> None:
    frame = encode_request(FC06, 0x0001, [0x0003], transport="rtu")
    assert frame[:-2] == h(SEED_06H_TX)
    assert frame[-2:] == _crc(h(SEED_06H_TX))
    decoded = decode_frame(frame, transport="rtu", direction="tx")
    assert decoded.errors == ()
    assert (decoded.unit, decoded.function, decoded.address, decoded.values) == (1, 0x06, 1, (3,))
    assert decoded.summary == "write reg 1 (GV0_H) = 0x0003"


def test_section2_fc10_example() -> None:
    frame = encode_request(FC10, 0x0001, [0x000A, 0x0102], transport="rtu")
    assert frame[:-2] == h(SEED_10H_TX)
    decoded = decode_frame(frame, transport="rtu")
    assert decoded.errors == ()
    assert (decoded.address, decoded.count, decoded.values) == (1, 2, (0x000A, 0x0102))
    # Register 1 is GV0_H: an odd start is not a run of GVs, so the words stay raw.
    assert decoded.summary == "write regs 1–2 = 0x000A, 0x0102"
    # The same PDU over TCP, for good measure.
    tcp = encode_request(FC10, 0x0001, [0x000A, 0x0102], transaction_id=0)
    assert tcp == h("00 00 00 00 00 0B") + h(SEED_10H_TX)


def test_section2_fc03_example() -> None:
    request = encode_request(FC03, 0x006B, count=3, transport="rtu")
    response = encode_response(FC03, values=[0x006B, 0x0013, 0x0000], transport="rtu")
    assert request[:-2] == h(SEED_03H_TX)
    assert response[:-2] == h(SEED_03H_RX)
    decoder = FrameDecoder("rtu")
    assert decoder.decode(request).summary == "read regs 107–109"
    answer = decoder.decode(response)
    assert answer.errors == ()
    assert answer.summary == "regs 107–109 = 0x006B, 0x0013, 0x0000"


# --- Case 2.2 steps 1 and 5: the placeholders "xx yy zz aa bb cc" --------------------------

POSE = (412.5, -120.25, 630.0, 180.0, -0.5, 90.0)  # X Y Z A B C, stands for the seed's xx..cc
PLACEHOLDERS = ("xx", "yy", "zz", "aa", "bb", "cc")

SEED_2_2_STEP1_TX = "00 00 00 00\t00 06\t01 03 01 9C 00 18"  # E1: quantity 0x18
SEED_2_2_STEP1_RX = (
    "00 00 00 00\t00 18\t01 03 18 xx xx xx xx yy yy yy yy zz zz zz zz aa aa aa aa "
    "bb bb bb bb cc cc cc cc"
)  # E2: MBAP length 0x18
SEED_2_2_STEP5_TX = (
    "00 03 00 00\t00 1F\t01 10 00 00 00 0C 18 xx xx xx xx yy yy yy yy zz zz zz zz "
    "aa aa aa aa bb bb bb bb cc cc cc cc"
)
SEED_2_2_STEP5_RX = "00 03 00 00\t00 0B\t01 10 00 00 00 0C"  # E9: MBAP length 0x0B

CORRECT_2_2_STEP1_TX = "00 00 00 00 00 06 01 03 01 9C 00 0C"
CORRECT_2_2_STEP1_RX = SEED_2_2_STEP1_RX.replace("\t00 18\t", "\t00 1B\t")
CORRECT_2_2_STEP5_RX = "00 03 00 00 00 06 01 10 00 00 00 0C"


def pose_bytes(pose: Sequence[float], order: WordOrder = WordOrder.LOW_FIRST) -> list[bytes]:
    """Each value's four bytes as they go on the wire."""
    return [b"".join(r.to_bytes(2, "big") for r in float_to_registers(v, order)) for v in pose]


def fill(template: str, pose: Sequence[float]) -> bytes:
    """The seed's frame with its placeholders replaced by ``pose``, in wire order."""
    values = dict(zip(PLACEHOLDERS, pose_bytes(pose), strict=True))
    used = dict.fromkeys(PLACEHOLDERS, 0)
    out = bytearray()
    for token in template.split():
        if token in values:
            out.append(values[token][used[token]])
            used[token] += 1
        else:
            out += bytes.fromhex(token)
    assert all(n == 4 for n in used.values()), "each placeholder stands for one float32 (4 bytes)"
    return bytes(out)


def test_case2_2_step1_read_pose_layout() -> None:
    """Read GV206–GV211: 12 registers; the answer holds X..C as 6 × 4 bytes in that order."""
    request = encode_request(FC03, gv_reg(GV_POSE), count=12, transaction_id=0)
    assert request == h(CORRECT_2_2_STEP1_TX)
    values = [r for v in POSE for r in float_to_registers(v)]
    response = encode_response(FC03, values=values, transaction_id=0)
    assert response == fill(CORRECT_2_2_STEP1_RX, POSE)
    assert len(response) == 6 + 0x1B == 33
    assert response[8] == 0x18  # byte count: 24 bytes
    assert [response[9 + 4 * i : 13 + 4 * i] for i in range(6)] == pose_bytes(POSE)

    decoder = FrameDecoder("tcp")
    assert decoder.decode(request).summary == "read pose X..C (GV206–GV211)"
    answer = decoder.decode(response)
    assert answer.errors == ()
    assert answer.summary == "pose X..C (GV206–GV211): X=412.5, Y=-120.25, Z=630.0, A=180.0, B=-0.5, C=90.0"
    assert [item.value for item in answer.items] == list(POSE)


def test_case2_2_step5_write_pose_to_gv0_gv5_layout() -> None:
    request = encode_write_gv(0, POSE, transaction_id=3)
    assert request == fill(SEED_2_2_STEP5_TX, POSE)
    assert len(request) == 6 + 0x1F == 37
    assert request[12] == 0x18 and request[10:12] == b"\x00\x0c"  # 12 registers, 24 bytes
    response = encode_response(FC10, 0, count=12, transaction_id=3)
    assert response == h(CORRECT_2_2_STEP5_RX)

    decoder = FrameDecoder("tcp")
    tx = decoder.decode(request)
    assert tx.errors == ()
    assert tx.summary == "write GV0–GV5 = 412.5, -120.25, 630.0, 180.0, -0.5, 90.0"
    rx = decoder.decode(response)
    assert rx.errors == ()
    assert rx.summary == "ack write GV0–GV5 (0–11)"


def test_case2_2_high_word_first_swaps_only_the_words() -> None:
    order = WordOrder.HIGH_FIRST
    request = encode_write_gv(0, POSE, word_order=order, transaction_id=3)
    assert request[:13] == fill(SEED_2_2_STEP5_TX, POSE)[:13]
    assert [request[13 + 4 * i : 17 + 4 * i] for i in range(6)] == pose_bytes(POSE, order)
    assert pose_bytes([30.0], order) == [h("41 F0 00 00")]
    decoded = decode_frame(request, transport="tcp", word_order=order)
    assert decoded.summary == "write GV0–GV5 = 412.5, -120.25, 630.0, 180.0, -0.5, 90.0"


# --- Errata (PROTOCOL.md section 6): what the seed printed, and the corrected form ----------


def _pair(tx: bytes, rx: bytes) -> DecodedFrame:
    decoder = FrameDecoder("tcp")
    decoder.decode(tx, "tx")
    return decoder.decode(rx, "rx")


def test_E1_read_pose_quantity_is_12_not_24() -> None:
    seed = h(SEED_2_2_STEP1_TX)
    correct = h(CORRECT_2_2_STEP1_TX)
    assert (seed[-1], correct[-1]) == (0x18, 0x0C)
    assert seed[:-1] == correct[:-1]
    assert encode_request(FC03, gv_reg(GV_POSE), count=12) == correct
    # As printed, the request reads 24 registers: GV206..GV217, past the pose.
    printed = decode_frame(seed, transport="tcp")
    assert printed.errors == ()
    assert (printed.address, printed.count) == (412, 24)
    assert printed.summary == "read GV206–GV217 (412–435)"
    # The seed's own answer carries 0x18 bytes = 12 registers, which contradicts its request.
    answer = fill(CORRECT_2_2_STEP1_RX, POSE)
    assert answer[8] == 0x18 == 2 * 12
    assert _pair(seed, answer).errors == ("12 registers returned, 24 requested",)
    assert _pair(correct, answer).errors == ()


def test_E2_read_pose_response_mbap_length_is_0x1B() -> None:
    printed = fill(SEED_2_2_STEP1_RX, POSE)
    correct = fill(CORRECT_2_2_STEP1_RX, POSE)
    assert printed[4:6] == h("00 18") and correct[4:6] == h("00 1B")
    assert printed[:4] + printed[6:] == correct[:4] + correct[6:]
    assert 0x1B == 1 + 1 + 1 + 24  # unit, function, byte count, data
    decoded = decode_frame(printed, transport="tcp", direction="rx")
    assert decoded.errors == ("MBAP length 24, but 27 bytes follow it",)
    assert decode_frame(correct, transport="tcp", direction="rx").errors == ()


def test_E3_pose_registers_are_412_to_423() -> None:
    """The seed writes "GV206~GV211 (412~422)"; six GVs end at register 423."""
    assert (gv_low(206), gv_high(211)) == (412, 423)
    frame = decode_frame(h(CORRECT_2_2_STEP1_TX), transport="tcp")
    assert frame.address is not None and frame.count is not None
    assert frame.address + frame.count - 1 == 423
    items = describe_registers(412, [r for v in POSE for r in float_to_registers(v)])
    assert [(it.name, it.role, it.address, it.last) for it in items][-1] == ("GV211", "C", 422, 423)


SEED_CASE4_STEP2_TX = "00 01 00 00 00 0B 01 10 01 90 00 02 04 00 00 00"
SEED_CASE4_STEP3_TX = "00 02 00 00 00 0B 01 10 01 92 00 02 04 00 00 00"
SEED_CASE4_STEP4_TX = "00 03 00 00 00 0B 01 10 01 94 00 02 04 00 00 3F"


@pytest.mark.parametrize(
    ("printed", "corrected", "value", "named"),
    [
        (SEED_CASE4_STEP2_TX, CASE_4[1].tx, 0.0, "write GV200 frame = 0.0 (base)"),
        (SEED_CASE4_STEP3_TX, CASE_4[2].tx, 0.0, "write GV201 axis = 0.0 (X or J1)"),
    ],
    ids=["step2-GV200", "step3-GV201"],
)
def test_E4_case4_writes_of_zero_lack_a_byte(printed: str, corrected: str, value: float, named: str) -> None:
    seed, good = h(printed), h(corrected)
    assert len(seed) == 16 and len(good) == 17
    assert good == seed + b"\x00"
    short = decode_frame(seed, transport="tcp")
    assert short.errors == ("MBAP length 11, but 10 bytes follow it", "byte count 4, but 3 data bytes")
    assert short.summary.startswith("malformed write GV")
    fixed = decode_frame(good, transport="tcp", params_for=RunCommand.TEACH_ENABLE)
    assert fixed.errors == ()
    assert [item.value for item in fixed.items] == [value]
    assert fixed.summary == named


def test_E5_case4_step4_writes_1_0_as_3F_80() -> None:
    seed, good = h(SEED_CASE4_STEP4_TX), h(CASE_4[3].tx)
    assert good == seed + b"\x80"
    assert good[-4:] == h("00 00 3F 80")  # 1.0 = 0x3F800000, low word first
    short = decode_frame(seed, transport="tcp")
    assert "byte count 4, but 3 data bytes" in short.errors
    assert "MBAP length 11, but 10 bytes follow it" in short.errors
    fixed = decode_frame(good, transport="tcp")
    assert fixed.errors == ()
    assert fixed.items[0].value == 1.0
    assert fixed.summary == "write GV202 = 1.0"


def test_E6_run_command_register_is_GV220_L_not_GV200_L() -> None:
    """The seed's note says "GV200_L=0x40 / 0x41"; the command goes to GV220_L = register 440."""
    assert gv_low(220) == REG_RUN_COMMAND == 440
    assert reg_to_gv(440) == (220, "L")
    assert gv_low(200) == 400
    wrong = decode_frame(encode_request(FC06, gv_low(200), [0x40]), transport="tcp")
    assert wrong.summary == "write reg 400 (GV200_L) = 0x0040"
    assert wrong.command is None
    joint = decode_frame(h(CASE_1[3].tx), transport="tcp")
    assert joint.command is RunCommand.STEP_JOINT
    base = decode_frame(run_command(RunCommand.STEP_BASE, 3), transport="tcp")
    assert base.hex == "00 03 00 00 00 06 01 06 01 B8 00 41"
    assert base.summary == "incremental move (base) (440 ← 0x41)"


def test_E7_fc03_example_quantity_3_returns_3_registers() -> None:
    """The seed says "read two addresses" and labels 0x6B → 0013, 0x6C → 0000."""
    request = h(SEED_03H_TX)
    assert int.from_bytes(request[4:6], "big") == 3
    rtu = FrameDecoder("rtu")
    rtu.decode(request + _crc(request))
    answer = rtu.decode(h(SEED_03H_RX) + _crc(h(SEED_03H_RX)))
    assert answer.errors == ()
    assert answer.count == 3
    assert [(it.address, it.value) for it in answer.items] == [(0x6B, 0x006B), (0x6C, 0x0013), (0x6D, 0x0000)]


@pytest.mark.parametrize(("value", "meaning"), [(0.0, "kept"), (1.0, "changes"), (0.5, "?")])
def test_E8_orientation_flag_follows_the_values_not_the_step_list(value: float, meaning: str) -> None:
    """Step list: "whether orientation is kept"; values: 0 = kept, 1 = changes. The values win."""
    frame = decode_frame(write_gv(GV_PARAM2, value, 3), transport="tcp", params_for=RunCommand.MOVE_TO_POINT)
    assert frame.items[0].role == "orientation"
    assert frame.summary == f"write GV202 orientation = {value} ({meaning})"
    # Case 3 step 4 sets GV202 = 1: the orientation changes along the move.
    seed = decode_frame(h(CASE_3[3].tx), transport="tcp", params_for=RunCommand.MOVE_TO_POINT)
    assert seed.items[0].text == "1.0 (changes)"


def test_E9_create_from_gvs_response_mbap_length_is_6() -> None:
    printed, correct = h(SEED_2_2_STEP5_RX), h(CORRECT_2_2_STEP5_RX)
    assert printed[4:6] == h("00 0B") and correct[4:6] == h("00 06")
    assert printed[6:] == correct[6:] == h("01 10 00 00 00 0C")
    request = encode_write_gv(0, POSE, transaction_id=3)
    seed_pair = _pair(request, printed)
    assert seed_pair.errors == ("MBAP length 11, but 6 bytes follow it",)
    assert seed_pair.summary == "ack write GV0–GV5 (0–11)"
    assert _pair(request, correct).errors == ()


def test_E10_gv0_starts_at_register_0() -> None:
    """The preface maps address 0 → "GV1-L"; table 1 and case 2.2 put GV0 at 0 and 1."""
    assert (reg_to_gv(0), reg_to_gv(1), reg_to_gv(2)) == ((0, "L"), (0, "H"), (1, "L"))
    assert (gv_low(0), gv_high(0), gv_low(1)) == (0, 1, 2)
    items = describe_registers(0, float_to_registers(1.0) + float_to_registers(2.0))
    assert [(it.name, it.value) for it in items] == [("GV0", 1.0), ("GV1", 2.0)]
    step5 = decode_frame(encode_write_gv(0, POSE, transaction_id=3), transport="tcp")
    assert step5.address == 0 and step5.items[0].name == "GV0"


def test_E11_gv0_to_gv5_are_registers_0_to_11() -> None:
    """The seed writes "GV0~GV5 (0~10)"."""
    frame = decode_frame(encode_write_gv(0, POSE), transport="tcp")
    assert frame.address is not None and frame.count is not None
    assert (frame.address, frame.count, frame.address + frame.count - 1) == (0, 12, 11)
    assert frame.items[-1].name == "GV5" and (frame.items[-1].address, frame.items[-1].last) == (10, 11)

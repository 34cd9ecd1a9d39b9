"""The frame decoder beyond the seed's frames: malformed input, pairing, naming, encoders."""

from __future__ import annotations

import datetime as dt
import random

import pytest
from pymodbus.framer import FramerRTU

from app.protocol.codec import WordOrder, encode_floats, float_to_registers
from app.protocol.datetime_regs import DateTimeLayout, encode_clock
from app.protocol.enums import Alarm, RunCommand
from app.protocol.exceptions import MODBUS_EXCEPTION_TEXT, exception_text
from app.protocol.float_text import format_float32
from app.protocol.frames import FrameDecoder, decode_frame
from app.protocol.framing import (
    FunctionCode,
    crc16,
    encode_request,
    encode_response,
    encode_write_gv,
)
from app.protocol.naming import ItemKind, describe_registers
from app.protocol.registers import (
    GV_EXPECTED_SPEED,
    GV_PARAM0,
    GV_PARAM1,
    GV_PARAM2,
    GV_PARAM3,
    GV_TOOL_FRAME,
    GV_USER_FRAME,
    POSE_BLOCK_COUNT,
    POSE_BLOCK_START,
    REG_RUN_COMMAND,
    STATUS_BLOCK_COUNT,
    STATUS_BLOCK_START,
    gv_reg,
)
from app.protocol.summaries import range_label, single_write_text

FC03 = FunctionCode.READ_HOLDING_REGISTERS
FC06 = FunctionCode.WRITE_SINGLE_REGISTER
FC10 = FunctionCode.WRITE_MULTIPLE_REGISTERS

CLOCK = dt.datetime(2025, 3, 14, 15, 9, 26)


def status_registers(
    mode: int = 1,
    state: int = 0,
    alarms: int = 0,
    code: float = 255.0,
    *,
    int_status: bool = False,
    order: WordOrder = WordOrder.LOW_FIRST,
) -> list[int]:
    """Registers 560..583 as the controller would answer them."""
    regs = [0] * STATUS_BLOCK_COUNT
    regs[0:3] = [mode, state, alarms]
    regs[16:20] = encode_clock(CLOCK)
    regs[22:24] = [int(code), 0] if int_status else float_to_registers(code, order)
    return regs


# --- CRC ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "body", ["01 03 00 00 00 01", "01 06 01 B8 00 80", "01 10 01 90 00 02 04 00 00 41 F0", "", "FF"]
)
def test_crc16_agrees_with_pymodbus(body: str) -> None:
    data = bytes.fromhex(body)
    assert crc16(data).to_bytes(2, "little") == int(FramerRTU.compute_CRC(data)).to_bytes(2, "big")


def test_crc16_known_vector() -> None:
    assert crc16(bytes.fromhex("01 03 00 00 00 01")) == 0x0A84  # on the wire: 84 0A
    assert encode_request(FC03, 0, count=1, transport="rtu").hex(" ").upper() == "01 03 00 00 00 01 84 0A"


# --- RTU ------------------------------------------------------------------------------------


def test_rtu_bad_crc_is_reported_and_the_frame_still_decoded() -> None:
    good = encode_request(FC06, REG_RUN_COMMAND, [0x80], transport="rtu")
    bad = good[:-1] + bytes([good[-1] ^ 0xFF])
    frame = decode_frame(bad, transport="rtu")
    sent = int.from_bytes(bad[-2:], "little")
    assert frame.errors == (f"bad CRC 0x{sent:04X}, expected 0x{crc16(good[:-2]):04X}",)
    assert frame.summary == "teach enable (440 ← 0x80)"
    assert not frame.ok


@pytest.mark.parametrize("size", [0, 1, 2, 3])
def test_rtu_too_short(size: int) -> None:
    frame = decode_frame(b"\x01\x03\x00"[:size], transport="rtu")
    assert frame.errors == (f"truncated: {size} bytes, an RTU frame needs at least 4",)
    assert frame.summary == "truncated frame"
    assert frame.unit == (1 if size else None)


def test_rtu_exception_response() -> None:
    frame = decode_frame(encode_response(FC03, exception=2, transport="rtu"), transport="rtu")
    assert frame.errors == ()
    assert (frame.is_response, frame.is_exception) == (True, True)
    assert (frame.function_code, frame.function) == (0x83, 3)
    assert frame.summary == "exception 02 illegal data address"


def test_rtu_pairs_by_order() -> None:
    decoder = FrameDecoder("rtu")
    pose = decoder.decode(encode_request(FC03, 412, count=12, transport="rtu"))
    status = decoder.decode(encode_request(FC03, 560, count=24, transport="rtu"))
    assert decoder.pending == 2
    answer = decoder.decode(encode_response(FC03, values=encode_floats([1, 2, 3, 4, 5, 6]), transport="rtu"))
    assert answer.request is pose and answer.errors == ()
    answer = decoder.decode(encode_response(FC03, values=status_registers(), transport="rtu"))
    assert answer.request is status
    assert answer.summary.startswith("status (560–583): mode=auto")
    assert decoder.pending == 0


def test_rtu_drops_requests_older_than_the_one_answered() -> None:
    """Half-duplex: a request left without answer (timeout) is never answered later."""
    decoder = FrameDecoder("rtu")
    decoder.decode(encode_request(FC03, 412, count=12, transport="rtu"))  # timed out
    write = decoder.decode(encode_request(FC06, 444, [1], transport="rtu"), "tx")
    echo = decoder.decode(encode_response(FC06, 444, [1], transport="rtu"))
    assert echo.is_response and echo.request is write
    assert echo.summary == "ack work mode auto (444 ← 1)"
    assert decoder.pending == 0


def test_rtu_response_of_another_function_leaves_pending_requests() -> None:
    decoder = FrameDecoder("rtu")
    decoder.decode(encode_request(FC03, 560, count=3, transport="rtu"))
    ack = decoder.decode(encode_response(FC10, 400, count=2, transport="rtu"))
    assert ack.request is None and ack.summary == "ack write GV200 (400–401)"
    assert decoder.pending == 1
    decoder.reset()
    assert decoder.pending == 0


# --- TCP header -----------------------------------------------------------------------------


def test_hex_is_spaced_uppercase() -> None:
    frame = decode_frame(encode_write_gv(200, 30.0, transaction_id=1), transport="tcp")
    assert frame.hex == "00 01 00 00 00 0B 01 10 01 90 00 02 04 00 00 41 F0"


@pytest.mark.parametrize("size", range(7))
def test_tcp_shorter_than_the_mbap_header(size: int) -> None:
    data = encode_request(FC03, 560, count=24, transaction_id=0x1234)[:size]
    frame = decode_frame(data, transport="tcp")
    assert frame.errors == (f"truncated: {size} bytes, the MBAP header alone needs 7",)
    assert frame.summary == "truncated frame"
    assert frame.transaction_id == (0x1234 if size >= 2 else None)


def test_tcp_header_without_pdu() -> None:
    frame = decode_frame(bytes.fromhex("00 01 00 00 00 01 01"), transport="tcp")
    assert frame.errors == ("no PDU: the function code is missing",)
    assert frame.summary == "truncated frame"


def test_tcp_protocol_id_must_be_zero() -> None:
    data = bytearray(encode_request(FC03, 560, count=3))
    data[2:4] = b"\x12\x34"
    frame = decode_frame(bytes(data), transport="tcp")
    assert frame.errors == ("protocol id 4660, expected 0",)
    assert frame.summary == "read status (560–562)"


def test_tcp_length_field_shorter_than_the_frame() -> None:
    data = encode_request(FC03, 560, count=3) + b"\x00"
    frame = decode_frame(data, transport="tcp", direction="tx")
    assert frame.errors == ("MBAP length 6, but 7 bytes follow it", "1 extra bytes after the read request")


def test_unknown_function() -> None:
    frame = decode_frame(bytes.fromhex("00 01 00 00 00 06 01 05 00 01 FF 00"), transport="tcp")
    assert frame.errors == ("unknown function 0x05",)
    assert frame.summary == "function 0x05 (unsupported)"
    assert frame.function == 0x05 and frame.values == ()


# --- Exceptions -----------------------------------------------------------------------------


@pytest.mark.parametrize(("code", "text"), sorted(MODBUS_EXCEPTION_TEXT.items()))
def test_exception_texts(code: int, text: str) -> None:
    frame = decode_frame(encode_response(FC06, exception=code), transport="tcp")
    assert frame.summary == f"exception {code:02X} {text}"
    assert frame.exception_code == code and frame.is_exception and not frame.ok


def test_one_exception_table_covers_every_standard_code() -> None:
    # 0x01-0x0B of the Modbus standard; 0x09 is not assigned.
    assert sorted(MODBUS_EXCEPTION_TEXT) == [c for c in range(0x01, 0x0C) if c != 0x09]
    assert exception_text(0x07) == "negative acknowledge"
    assert exception_text(0x77) == "unknown exception"
    assert exception_text(0x77, "exception code 119") == "exception code 119"


def test_exception_unknown_code_and_missing_code() -> None:
    assert decode_frame(encode_response(FC03, exception=0x77), transport="tcp").summary == (
        "exception 77 unknown exception"
    )
    missing = decode_frame(bytes.fromhex("00 01 00 00 00 02 01 83"), transport="tcp")
    assert missing.summary == "exception (code missing)"
    assert missing.errors == ("truncated exception response: 0 of 1 data bytes",)


def test_exception_pairs_with_its_request() -> None:
    decoder = FrameDecoder()
    request = decoder.decode(encode_request(FC03, 2000, count=10, transaction_id=7))
    answer = decoder.decode(encode_response(FC03, exception=2, transaction_id=7))
    assert answer.request is request and answer.errors == ()
    assert answer.address is None


def test_exception_sent_as_request_is_flagged() -> None:
    frame = decode_frame(encode_response(FC03, exception=2), transport="tcp", direction="tx")
    assert frame.errors == ("an exception response sent as a request",)


def _mbap(body: bytes, tid: int = 1) -> bytes:
    return tid.to_bytes(2, "big") + b"\x00\x00" + len(body).to_bytes(2, "big")


# --- PDU layouts ----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("data", "is_response"),
    [
        (encode_request(FC03, 560, count=24), False),
        (encode_response(FC03, values=[1, 2]), True),
        (encode_request(FC10, 400, [0, 0x41F0]), False),
        (encode_response(FC10, 400, count=2), True),
        (encode_request(FC06, 444, [1]), False),  # an echo reads the same: a request
    ],
)
def test_direction_is_inferred_from_the_layout(data: bytes, is_response: bool) -> None:
    frame = decode_frame(data, transport="tcp")
    assert frame.is_response is is_response
    assert frame.direction == ("rx" if is_response else "tx")
    assert frame.errors == ()


def test_direction_given_against_the_layout() -> None:
    frame = decode_frame(encode_request(FC03, 560, count=24), transport="tcp", direction="rx")
    assert frame.is_response
    assert frame.errors == ("byte count 2, but 3 data bytes",)


@pytest.mark.parametrize(
    ("pdu", "errors"),
    [
        ("03 00 0A 00 00", ("quantity 0 outside 1..125",)),
        ("03 00 0A 00 7E", ("quantity 126 outside 1..125",)),
        ("03 FF FF 00 02", ("registers 65535+2 run past 65535",)),
        ("03 00 0A", ("truncated read request: 2 of at least 4 bytes",)),
        ("10 01 90 00 7C F8" + " 00" * 248, ("quantity 124 outside 1..123",)),
        ("10 01 90 00 02 03 00 00 41", ("byte count 3 for 2 registers (expected 4)",)),
        ("10 01 90 00 02 04 00 00 41 F0 00", ("byte count 4, but 5 data bytes",)),
        ("10 01 90 00 02", ("truncated write request: 4 of at least 5 bytes",)),
        ("06 01 B8 00", ("truncated write register request: 3 of 4 data bytes",)),
        ("06 01 B8 00 80 00", ("1 extra bytes after the write register request",)),
    ],
)
def test_malformed_requests(pdu: str, errors: tuple[str, ...]) -> None:
    body = bytes.fromhex("01 " + pdu)
    frame = decode_frame(_mbap(body) + body, transport="tcp", direction="tx")
    assert frame.errors == errors


@pytest.mark.parametrize(
    ("pdu", "errors"),
    [
        ("03", ("truncated read response: byte count missing",)),
        ("03 03 00 01 02", ("odd byte count 3",)),
        ("03 00", ("byte count 0",)),
        ("03 04 00 01", ("byte count 4, but 2 data bytes",)),
        ("10 01 90 00 02 00", ("1 extra bytes after the write response",)),
        ("10 01 90", ("truncated write response: 2 of at least 4 bytes",)),
    ],
)
def test_malformed_responses(pdu: str, errors: tuple[str, ...]) -> None:
    body = bytes.fromhex("01 " + pdu)
    frame = decode_frame(_mbap(body) + body, transport="tcp", direction="rx")
    assert frame.errors == errors


def _golden_frames() -> list[bytes]:
    return [
        encode_request(FC03, 412, count=12, transaction_id=1),
        encode_response(FC03, values=status_registers(), transaction_id=1),
        encode_write_gv(0, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], transaction_id=3),
        encode_response(FC10, 0, count=12, transaction_id=3),
        encode_request(FC06, REG_RUN_COMMAND, [0x80], transaction_id=5),
        encode_response(FC06, exception=4, transaction_id=5),
    ]


@pytest.mark.parametrize("transport", ["tcp", "rtu"])
def test_every_truncation_decodes_with_an_error(transport: str) -> None:
    for tcp in _golden_frames():
        full = tcp if transport == "tcp" else tcp[6:] + crc16(tcp[6:]).to_bytes(2, "little")
        assert decode_frame(full, transport=transport).errors == ()  # type: ignore[arg-type]
        for size in range(len(full)):
            for direction in (None, "tx", "rx"):
                frame = decode_frame(full[:size], transport=transport, direction=direction)  # type: ignore[arg-type]
                assert frame.errors, (full.hex(" "), size)
                assert isinstance(frame.summary, str) and frame.summary


def test_random_bytes_never_raise() -> None:
    rng = random.Random(20240601)
    decoders = [FrameDecoder("tcp"), FrameDecoder("rtu")]
    seeds = _golden_frames()
    for _ in range(3000):
        if rng.random() < 0.5:
            data = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))
        else:  # a golden frame with a few bytes flipped: deeper into the parser
            flipped = bytearray(rng.choice(seeds))
            for _ in range(rng.randrange(1, 4)):
                flipped[rng.randrange(len(flipped))] = rng.randrange(256)
            data = bytes(flipped)
        for decoder in decoders:
            frame = decoder.decode(data, rng.choice([None, "tx", "rx"]))
            assert isinstance(frame.summary, str)
            assert frame.hex == data.hex(" ").upper()


# --- Pairing (TCP) --------------------------------------------------------------------------


def test_responses_out_of_order_pair_by_transaction_id() -> None:
    decoder = FrameDecoder()
    pose = decoder.decode(encode_request(FC03, POSE_BLOCK_START, count=POSE_BLOCK_COUNT, transaction_id=10))
    status = decoder.decode(encode_request(FC03, 560, count=24, transaction_id=11))
    assert pose.summary == "read pose, ext axes, joints (412–511)"
    assert status.summary == "read status (560–583)"
    answer = decoder.decode(
        encode_response(FC03, values=status_registers(alarms=Alarm.ESTOP | Alarm.BRAKE), transaction_id=11)
    )
    assert answer.request is status
    assert answer.summary == (
        "status (560–583): mode=auto, program=stopped, "
        "alarms=emergency stop + brake alarm, "
        "clock=2025-03-14 15:09:26, GV291=done (0xFF)"
    )
    values = encode_floats([float(i) for i in range(POSE_BLOCK_COUNT // 2)])
    answer = decoder.decode(encode_response(FC03, values=values, transaction_id=10))
    assert answer.request is pose
    assert answer.summary == (
        "pose, ext axes, joints (412–511): X=0.0, Y=1.0, Z=2.0, A=3.0, B=4.0, C=5.0, J7=6.0, J8=7.0, … (+48)"
    )
    # The block spans table 1 (440..453): those registers are integers, not GVs.
    assert len(answer.items) == 14 + 10 + 1 + 2 + 29
    roles = {item.role: item.value for item in answer.items}
    assert roles["J1"] == 44.0 and roles["J6"] == 49.0  # GV250..GV255, registers 500..511
    assert decoder.pending == 0


def test_response_without_its_request_keeps_raw_values() -> None:
    frame = FrameDecoder().decode(encode_response(FC03, values=[0x006B, 0x0013, 0x0000], transaction_id=99))
    assert frame.request is None and frame.address is None and frame.items == ()
    assert frame.summary == "3 regs = 0x006B, 0x0013, 0x0000"
    assert frame.errors == ()


@pytest.mark.parametrize(
    ("request_frame", "response", "error"),
    [
        (
            encode_request(FC03, 560, count=24),
            encode_response(FC10, 560, count=24),
            "function 0x10 answers a request of function 0x03",
        ),
        (
            encode_request(FC03, 560, count=3, unit=2),
            encode_response(FC03, values=[1, 0, 0]),
            "unit 1 answers a request to unit 2",
        ),
        (
            encode_request(FC06, 444, [1]),
            encode_response(FC06, 444, [0]),
            "the echo differs from the request",
        ),
        (
            encode_write_gv(200, 1.0),
            encode_response(FC10, 402, count=2),
            "acknowledges 402+2, the request wrote 400+2",
        ),
    ],
    ids=["function", "unit", "echo", "ack"],
)
def test_a_response_that_does_not_answer_its_request(
    request_frame: bytes, response: bytes, error: str
) -> None:
    decoder = FrameDecoder()
    decoder.decode(request_frame, "tx")
    assert decoder.decode(response, "rx").errors == (error,)


def test_fc06_echo_is_told_from_a_new_request_by_its_pending_twin() -> None:
    decoder = FrameDecoder()
    request = encode_request(FC06, 444, [1], transaction_id=4)
    assert decoder.decode(request).direction == "tx"
    assert decoder.decode(request).direction == "rx"
    assert decoder.decode(request).direction == "tx"  # nothing pending: a new request
    assert decoder.decode(encode_request(FC06, 444, [0], transaction_id=4)).direction == "tx"


def test_pending_requests_are_bounded() -> None:
    decoder = FrameDecoder(max_pending=4)
    for tid in range(10):
        decoder.decode(encode_request(FC03, 560, count=3, transaction_id=tid))
    assert decoder.pending == 4
    assert decoder.decode(encode_response(FC03, values=[1, 0, 0], transaction_id=0)).request is None
    assert decoder.decode(encode_response(FC03, values=[1, 0, 0], transaction_id=9)).request is not None


# --- GV291 and the last command -------------------------------------------------------------


@pytest.mark.parametrize(
    ("command", "code", "text"),
    [
        (RunCommand.STEP_BASE, 7, "data length error (0x07)"),
        (RunCommand.MOVE_TO_POINT, 6, "moving (0x06)"),
        (RunCommand.CREATE_POINT, 1, "bad point id (0x01)"),
        (RunCommand.TEACH_ENABLE, 7, "teach speed ratio not zero: enable/disable refused (0x07)"),
        (RunCommand.TEACH_DISABLE, 0xFF, "success (0xFF)"),
    ],
)
@pytest.mark.parametrize("int_status", [False, True], ids=["float", "int"])
def test_gv291_is_decoded_for_the_last_command_sent(
    command: RunCommand, code: int, text: str, int_status: bool
) -> None:
    decoder = FrameDecoder()
    decoder.decode(encode_request(FC06, REG_RUN_COMMAND, [command], transaction_id=1))
    decoder.decode(encode_request(FC06, REG_RUN_COMMAND, [RunCommand.RUN_PROGRAM], transaction_id=2))
    assert decoder.last_command is command  # running a program is not a GV291 command
    decoder.decode(encode_request(FC03, STATUS_BLOCK_START, count=STATUS_BLOCK_COUNT, transaction_id=3))
    answer = decoder.decode(
        encode_response(FC03, values=status_registers(code=code, int_status=int_status), transaction_id=3)
    )
    assert answer.items[-1].kind is ItemKind.COMMAND_STATUS
    assert answer.items[-1].text == text
    assert answer.summary.endswith(f"GV291={text}")


def test_gv291_alone_with_high_word_first() -> None:
    order = WordOrder.HIGH_FIRST
    decoder = FrameDecoder(word_order=order, last_command=RunCommand.STEP_JOINT)
    decoder.decode(encode_request(FC03, gv_reg(291), count=2))
    answer = decoder.decode(encode_response(FC03, values=float_to_registers(13.0, order)))
    assert answer.summary == "command status GV291 (582–583): GV291=bad end point id (0x0D)"


def test_clock_layout_and_invalid_clock() -> None:
    packed = describe_registers(
        576, encode_clock(CLOCK, DateTimeLayout.PACKED32), clock_layout=DateTimeLayout.PACKED32
    )
    assert [(item.role, item.value) for item in packed] == [("clock", CLOCK)]
    bad = describe_registers(576, [2025, 0x0D01, 0, 0])
    assert bad[0].text == "invalid (07E9 0D01 0000 0000)" and bad[0].value is None


def test_status_spare_registers_are_items_but_not_summarised() -> None:
    items = describe_registers(STATUS_BLOCK_START, status_registers())
    spare = [item.address for item in items if item.kind is ItemKind.RAW]
    assert spare == [*range(563, 576), 580, 581]
    assert describe_registers(563, [5])[0].label == "reg 563 = 0x0005"


# --- Naming registers -----------------------------------------------------------------------


@pytest.mark.parametrize(
    ("address", "value", "text"),
    [
        (440, 0x01, "run program (440 ← 0x01)"),
        (440, 0x42, "move to temp point (440 ← 0x42)"),
        (440, 0x99, "unknown command 0x99 (440 ← 0x99)"),
        (441, 1, "stop (441 ← 1)"),
        (442, 1, "pause (442 ← 1)"),
        (443, 1, "resume (443 ← 1)"),
        (444, 0, "work mode manual (444 ← 0)"),
        (444, 7, "work mode unknown 7 (444 ← 7)"),
        (445, 0x02, "go to zero J3 (445 ← 0x02)"),
        (445, 0x0A, "go to zero J11 (445 ← 0x0A)"),
        (445, 0x0B, "go to zero all axes (445 ← 0x0B)"),
        (445, 0x0C, "go to zero unknown 0x0C (445 ← 0x0C)"),
        (446, 12, "program id 12 (446 ← 12)"),
        (447, 0, "program mode single step (447 ← 0)"),
        (447, 2, "program mode cycle (447 ← 2)"),
        (447, 9, "program mode unknown 9 (447 ← 9)"),
        (448, 0, "cycles endless (448 ← 0)"),
        (448, 3, "cycles 3 (448 ← 3)"),
        (449, 80, "program speed 80% (449 ← 80)"),
        (452, 2, "resource type 2 (452 ← 2)"),
        (453, 30, "resource params GV30 (453 ← 30)"),
        (401, 0x41F0, "write reg 401 (GV200_H) = 0x41F0"),
    ],
)
def test_single_register_writes(address: int, value: int, text: str) -> None:
    assert single_write_text(address, value) == text
    frame = decode_frame(encode_request(FC06, address, [value]), transport="tcp")
    assert frame.summary == text and frame.errors == ()


def test_program_setup_in_one_fc10() -> None:
    frame = decode_frame(encode_request(FC10, 446, [5, 2, 0, 100]), transport="tcp")
    assert frame.summary == "write program id=5, program mode=cycle, cycles=endless, program speed=100%"


def test_table1_read_mixes_integers_and_the_speed_float() -> None:
    values = [0x40, 0, 0, 0, 1, 0, 7, 1, 1, 50, *float_to_registers(25.5), 0, 0]
    items = describe_registers(440, values)
    assert [(item.address, item.kind, item.text) for item in items][:2] == [
        (440, ItemKind.INTEGER, "incremental move (joint)"),
        (441, ItemKind.INTEGER, "0"),
    ]
    speed = [item for item in items if item.kind is ItemKind.FLOAT]
    assert [(s.name, s.role, s.value) for s in speed] == [("GV225", "speed", 25.5)]
    assert len(items) == 13


@pytest.mark.parametrize(
    ("n", "value", "params_for", "label"),
    [
        (GV_PARAM0, -2.5, RunCommand.STEP_BASE, "GV200 X offset = -2.5"),
        (GV_PARAM0 + 5, 1.0, RunCommand.STEP_BASE, "GV205 C offset = 1.0"),
        (GV_PARAM0 + 5, 1.0, RunCommand.STEP_JOINT, "GV205 J6 offset = 1.0"),
        (236, 4.0, None, "GV236 J7 offset = 4.0"),
        (240, 4.0, None, "GV240 J11 offset = 4.0"),
        (GV_PARAM1, 1.0, RunCommand.CREATE_POINT, "GV201 source = 1.0 (from GVs)"),
        (GV_PARAM1, 2.0, RunCommand.CREATE_POINT, "GV201 source = 2.0 (?)"),
        (GV_PARAM2, 10.0, RunCommand.CREATE_POINT, "GV202 first GV = 10.0"),
        (GV_PARAM0, 5.0, RunCommand.MOVE_TO_POINT, "GV200 motion = 5.0 (arc via point 5)"),
        (GV_PARAM0, -3.0, RunCommand.MOVE_TO_POINT, "GV200 motion = -3.0 (?)"),
        (GV_PARAM3, 1.0, RunCommand.MOVE_TO_POINT, "GV203 ignore middle = 1.0 (yes)"),
        (GV_PARAM0, 3.0, RunCommand.TEACH_ENABLE, "GV200 frame = 3.0 (joint)"),
        (GV_PARAM1, 8.0, RunCommand.TEACH_ENABLE, "GV201 axis = 8.0 (J9)"),
        (GV_PARAM1, 11.0, RunCommand.TEACH_ENABLE, "GV201 axis = 11.0 (?)"),
        (GV_PARAM2, 0.0, RunCommand.TEACH_DISABLE, "GV202 direction = 0.0 (negative)"),
        (GV_PARAM2, 0.0, RunCommand.RUN_PROGRAM, "GV202 = 0.0"),
        (GV_TOOL_FRAME, 200.0, None, "GV245 tool = 200.0 (no tool)"),
        (GV_TOOL_FRAME, 3.0, None, "GV245 tool = 3.0 (tool 3)"),
        (GV_USER_FRAME, 2.0, None, "GV241 user frame = 2.0"),
        (GV_EXPECTED_SPEED, 0.1, None, "GV225 speed = 0.1"),
        (212, 0.0, None, "GV212 J7 = 0.0"),
        (99, 1e20, None, "GV99 = 1e+20"),
    ],
)
def test_gv_roles(n: int, value: float, params_for: RunCommand | None, label: str) -> None:
    (item,) = describe_registers(gv_reg(n), float_to_registers(value), params_for=params_for)
    assert item.label == label


def test_odd_starts_and_half_gvs_stay_raw() -> None:
    assert [item.kind for item in describe_registers(401, [1, 2, 3])] == [ItemKind.RAW] * 3
    items = describe_registers(400, [*float_to_registers(1.0), 7])
    assert [(item.kind, item.name) for item in items] == [
        (ItemKind.FLOAT, "GV200"),
        (ItemKind.RAW, "reg 402"),
    ]
    assert describe_registers(582, [0xFF])[0].kind is ItemKind.RAW  # half of GV291
    assert describe_registers(0, []) == ()
    with pytest.raises(ValueError):
        describe_registers(-1, [0])


@pytest.mark.parametrize(
    ("address", "count", "label"),
    [
        (412, 12, "pose X..C (GV206–GV211)"),
        (424, 10, "ext axes J7..J11 (GV212–GV216)"),
        (500, 12, "joints J1..J6 (GV250–GV255)"),
        (560, 3, "status (560–562)"),
        (576, 4, "clock (576–579)"),
        (400, 12, "GV200–GV205 (400–411)"),
        (450, 2, "GV225 (450–451)"),
        (440, 10, "regs 440–449"),
        (441, 1, "reg 441"),
        (107, 3, "regs 107–109"),
    ],
)
def test_range_labels(address: int, count: int, label: str) -> None:
    assert range_label(address, count) == label


def test_long_writes_are_cut_in_the_summary() -> None:
    frame = decode_frame(encode_write_gv(0, [float(i) for i in range(20)]), transport="tcp")
    assert frame.summary == "write GV0–GV19 = 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, … (+12)"
    assert len(frame.items) == 20


def test_write_of_mixed_roles_lists_each() -> None:
    frame = decode_frame(
        encode_write_gv(200, [-1.0, 2.0, 1.0, 0.0]), transport="tcp", params_for=RunCommand.MOVE_TO_POINT
    )
    assert frame.summary == (
        "write motion=-1.0 (line), end point=2.0, orientation=1.0 (changes), ignore middle=0.0 (no)"
    )


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (30.0, "30.0"),
        (-1.0, "-1.0"),
        (0.1, "0.1"),
        (-0.0, "-0.0"),
        (100000.0, "100000.0"),
        (1e20, "1e+20"),
        (123456789.0, "123456790.0"),
        (3.4028234663852886e38, "3.4028235e+38"),
        (1e-45, "1e-45"),
        (float("nan"), "nan"),
        (float("inf"), "inf"),
        (float("-inf"), "-inf"),
        (1e39, "1e+39"),
    ],
)
def test_format_float32(value: float, text: str) -> None:
    assert format_float32(value) == text


# --- Encoders -------------------------------------------------------------------------------


def test_encode_write_gv_scalar_and_sequence_agree() -> None:
    assert encode_write_gv(200, 30.0) == encode_write_gv(200, [30.0]) == encode_write_gv(200, 30)
    assert encode_write_gv(200, 30.0, word_order=WordOrder.HIGH_FIRST)[-4:] == bytes.fromhex("41 F0 00 00")


def test_encode_response_exception_and_rtu() -> None:
    assert encode_response(FC10, exception=3, transaction_id=2) == bytes.fromhex("00 02 00 00 00 03 01 90 03")
    frame = encode_response(FC03, values=[1], unit=7, transport="rtu")
    assert frame[:-2] == bytes.fromhex("07 03 02 00 01")
    assert crc16(frame[:-2]).to_bytes(2, "little") == frame[-2:]


@pytest.mark.parametrize(
    "call",
    [
        lambda: encode_request(FC03, 0),  # count missing
        lambda: encode_request(FC03, 0, [1], count=1),
        lambda: encode_request(FC03, 0, count=126),
        lambda: encode_request(FC03, 65535, count=2),
        lambda: encode_request(FC06, 0, [1, 2]),
        lambda: encode_request(FC06, 0, [0x10000]),
        lambda: encode_request(FC06, 0, [-1]),
        lambda: encode_request(FC10, 0, []),
        lambda: encode_request(FC10, 0, [0] * 124),
        lambda: encode_request(0x05, 0, [1]),
        lambda: encode_request(FC03, -1, count=1),
        lambda: encode_request(FC03, 0, count=1, transaction_id=0x10000),
        lambda: encode_request(FC03, 0, count=1, unit=256),
        lambda: encode_request(FC03, 0, count=1, transport="udp"),  # type: ignore[arg-type]
        lambda: encode_response(FC03, values=[]),
        lambda: encode_response(FC06, 0, []),
        lambda: encode_response(FC10, 0, count=0),
        lambda: encode_response(0x05, 0, [1]),
        lambda: encode_response(0x83, exception=2),
        lambda: encode_response(FC03, exception=256),
        lambda: decode_frame(b"", transport="udp"),  # type: ignore[arg-type]
        lambda: FrameDecoder("udp"),  # type: ignore[arg-type]
    ],
)
def test_encoders_refuse_bad_arguments(call: object) -> None:
    assert callable(call)
    with pytest.raises(ValueError):
        call()

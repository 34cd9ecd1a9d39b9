"""float32 <-> registers and the word order (app/protocol/codec.py)."""

from __future__ import annotations

import math
import struct

import pytest

from app.protocol.codec import (
    WordOrder,
    as_uint16,
    check_float32,
    decode_floats,
    encode_floats,
    float_to_registers,
    registers_to_float,
)

FLT_MAX = struct.unpack(">f", bytes.fromhex("7F7FFFFF"))[0]


def as_float32(value: float) -> float:
    return float(struct.unpack(">f", struct.pack(">f", value))[0])


@pytest.mark.parametrize(
    ("value", "low_first"),
    [
        (30.0, [0x0000, 0x41F0]),  # PROTOCOL.md section 1: GV200 = 30.0
        (100.0, [0x0000, 0x42C8]),
        (1.0, [0x0000, 0x3F80]),
        (-1.0, [0x0000, 0xBF80]),
        (10.0, [0x0000, 0x4120]),
        (0.0, [0x0000, 0x0000]),
        (-0.0, [0x0000, 0x8000]),
        (255.0, [0x0000, 0x437F]),
        (412.5, [0x4000, 0x43CE]),
        (0.1, [0xCCCD, 0x3DCC]),
    ],
)
def test_word_orders(value: float, low_first: list[int]) -> None:
    assert float_to_registers(value) == low_first
    assert float_to_registers(value, WordOrder.LOW_FIRST) == low_first
    assert float_to_registers(value, WordOrder.HIGH_FIRST) == low_first[::-1]
    assert registers_to_float(low_first) == as_float32(value)
    assert registers_to_float(low_first[::-1], WordOrder.HIGH_FIRST) == as_float32(value)


@pytest.mark.parametrize("order", list(WordOrder))
@pytest.mark.parametrize(
    "value",
    [
        0.0,
        1.0,
        -1.0,
        30.0,
        -30.0,
        0.1,
        -123.456,
        1e-3,
        1e-40,
        -1e-45,
        9999.75,
        -180.0,
        1e30,
        FLT_MAX,
        -FLT_MAX,
    ],
)
def test_round_trip(order: WordOrder, value: float) -> None:
    regs = float_to_registers(value, order)
    assert all(0 <= r <= 0xFFFF for r in regs) and len(regs) == 2
    assert registers_to_float(regs, order) == as_float32(value)


def test_round_trip_keeps_the_sign_of_zero_and_nan() -> None:
    assert math.copysign(1.0, registers_to_float(float_to_registers(-0.0))) == -1.0
    assert math.isnan(registers_to_float(float_to_registers(float("nan"))))
    assert registers_to_float(float_to_registers(float("-inf"))) == float("-inf")


def test_registers_are_masked_to_16_bits() -> None:
    assert registers_to_float([0x10000, 0x141F0]) == 30.0


@pytest.mark.parametrize("regs", [[], [0], [0, 0, 0]])
def test_a_float_needs_two_registers(regs: list[int]) -> None:
    with pytest.raises(ValueError):
        registers_to_float(regs)


def test_several_floats() -> None:
    values = [1.0, -1.0, 30.0]
    regs = encode_floats(values)
    assert regs == [0, 0x3F80, 0, 0xBF80, 0, 0x41F0]
    assert decode_floats(regs) == values
    high = encode_floats(values, WordOrder.HIGH_FIRST)
    assert high == [0x3F80, 0, 0xBF80, 0, 0x41F0, 0]
    assert decode_floats(high, WordOrder.HIGH_FIRST) == values
    assert encode_floats([]) == [] and decode_floats([]) == []
    with pytest.raises(ValueError):
        decode_floats([0, 0, 0])


@pytest.mark.parametrize("value", [0, 1, -1.5, 1e38, 3.4028234e38, -3.4028234e38, 10**30])
def test_check_float32_accepts(value: float) -> None:
    result = check_float32(value)
    assert result == float(value) and type(result) is float


@pytest.mark.parametrize(
    "value", [float("nan"), float("inf"), float("-inf"), 1e39, -1e39, 3.5e38, True, "1.0", None]
)
def test_check_float32_rejects(value: object) -> None:
    with pytest.raises(ValueError, match="speed"):
        check_float32(value, "speed")  # type: ignore[arg-type]


def test_check_float32_accepts_the_largest_float32() -> None:
    assert check_float32(FLT_MAX) == FLT_MAX


def test_check_float32_refuses_a_huge_int_with_value_error() -> None:
    with pytest.raises(ValueError):
        check_float32(10**400)


@pytest.mark.parametrize("value", [0, 1, 0xFFFF])
def test_as_uint16_accepts(value: int) -> None:
    assert as_uint16(value) == value


@pytest.mark.parametrize("value", [-1, 0x10000])
def test_as_uint16_rejects(value: int) -> None:
    with pytest.raises(ValueError):
        as_uint16(value)


@pytest.mark.parametrize(
    ("text", "order"),
    [
        ("low-first", WordOrder.LOW_FIRST),
        ("high-first", WordOrder.HIGH_FIRST),
        ("  LOW-FIRST ", WordOrder.LOW_FIRST),
        ("little", WordOrder.LOW_FIRST),
        ("low", WordOrder.LOW_FIRST),
        ("CDAB", WordOrder.LOW_FIRST),
        ("big", WordOrder.HIGH_FIRST),
        ("High", WordOrder.HIGH_FIRST),
        ("abcd", WordOrder.HIGH_FIRST),
    ],
)
def test_word_order_parse(text: str, order: WordOrder) -> None:
    assert WordOrder.parse(text) is order


@pytest.mark.parametrize("text", ["", "middle", "badc", "low first"])
def test_word_order_parse_rejects(text: str) -> None:
    with pytest.raises(ValueError, match="word order"):
        WordOrder.parse(text)


def test_word_order_values_round_trip_through_parse() -> None:
    for order in WordOrder:
        assert WordOrder.parse(order.value) is order


def test_check_float32_accepts_numpy_scalars() -> None:
    np = pytest.importorskip("numpy")
    assert check_float32(np.float32(1.5)) == 1.5
    assert check_float32(np.int64(3)) == 3.0

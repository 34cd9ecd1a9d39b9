"""Naming registers fast and the same: the float32 printer, the item caches, whole GV runs."""

from __future__ import annotations

import random
import struct

import pytest

from app.protocol import naming
from app.protocol.codec import WordOrder, encode_floats, float_to_registers
from app.protocol.enums import RunCommand
from app.protocol.float_text import _search_float32_text, format_float32
from app.protocol.naming import ItemKind, describe_registers
from app.protocol.registers import (
    GV_PARAM0,
    POSE_BLOCK_COUNT,
    POSE_BLOCK_START,
    REG_PROGRAM_SPEED,
    REG_RESOURCE_PARAM,
    REG_RESOURCE_TYPE,
    REG_RUN_COMMAND,
    gv_reg,
)
from app.protocol.summaries import summarize_registers

_F32 = struct.Struct(">f")


def _float32_of(bits: int) -> float:
    value: float = _F32.unpack(struct.pack(">I", bits & 0xFFFFFFFF))[0]
    return value


def _patterns() -> list[int]:
    rng = random.Random(20261124)
    patterns = [rng.getrandbits(32) for _ in range(4000)]
    # Powers of two and their neighbours: where the float32 spacing changes.
    for exponent in range(0, 255):
        for sign in (0, 0x80000000):
            base = sign | exponent << 23
            patterns += [base, base + 1, base + 2, base - 1, base - 2]
    patterns += [
        struct.unpack(">I", _F32.pack(round(rng.uniform(-2000, 2000), rng.randint(0, 5))))[0]
        for _ in range(2000)
    ]
    patterns += [struct.unpack(">I", _F32.pack(float(n)))[0] for n in range(-(1 << 25), 1 << 25, 99991)]
    return patterns


def test_format_float32_agrees_with_the_digit_search() -> None:
    """The fast paths (small integers, numpy's shortest float32 digits) print what the search
    for the fewest ``%g`` digits that read back would (the reference, still used beside
    powers of two)."""
    checked = 0
    for bits in _patterns():
        value = _float32_of(bits)
        if value != value or value in (float("inf"), float("-inf")):
            continue
        assert format_float32(value) == _search_float32_text(value, _F32.pack(value)), hex(bits)
        checked += 1
    assert checked > 5000


@pytest.mark.parametrize("value", [0.1, 0.123456789123, -3.3333333333, 1e-40, 2.5e38, 16777217.0])
def test_format_float32_of_a_value_that_is_not_a_float32(value: float) -> None:
    assert format_float32(value) == _search_float32_text(value, _F32.pack(value))


def test_the_pose_block_is_whole_gv_runs_around_table_1() -> None:
    words = [(7 * i) & 0xFFFF for i in range(POSE_BLOCK_COUNT)]
    items = describe_registers(POSE_BLOCK_START, words)
    kinds = {it.address: it.kind for it in items}
    integers = {*range(REG_RUN_COMMAND, REG_PROGRAM_SPEED + 1), REG_RESOURCE_TYPE, REG_RESOURCE_PARAM}
    assert [a for a, k in kinds.items() if k is ItemKind.INTEGER] == sorted(integers)
    floats = [a for a, k in kinds.items() if k is ItemKind.FLOAT]
    assert floats == [
        a
        for a in range(POSE_BLOCK_START, POSE_BLOCK_START + POSE_BLOCK_COUNT, 2)
        if a not in integers and a + 1 not in integers
    ]
    assert sum(it.count for it in items) == POSE_BLOCK_COUNT
    assert all(
        it.raw == tuple(words[it.address - POSE_BLOCK_START : it.last - POSE_BLOCK_START + 1]) for it in items
    )


def test_a_run_ending_in_half_a_gv_leaves_it_raw() -> None:
    items = describe_registers(400, [*encode_floats([1.0, 2.0]), 7])
    assert [(it.kind, it.text) for it in items] == [
        (ItemKind.FLOAT, "1.0"),
        (ItemKind.FLOAT, "2.0"),
        (ItemKind.RAW, "0x0007"),
    ]


def test_a_repeated_answer_reuses_its_items() -> None:
    words = encode_floats([400.0, -12.5, 300.0, 180.0, 0.0, 90.0]) + [0] * (POSE_BLOCK_COUNT - 12)
    first = describe_registers(POSE_BLOCK_START, words)
    moved = list(words)
    moved[:2] = float_to_registers(400.5)
    second = describe_registers(POSE_BLOCK_START, moved)
    assert second[0].text == "400.5" and first[0].text == "400.0"
    assert all(a is b for a, b in zip(first[1:], second[1:], strict=True))


def test_cached_items_follow_the_word_order_and_the_command() -> None:
    low = float_to_registers(3.0)
    assert describe_registers(gv_reg(GV_PARAM0), low)[0].label == "GV200 = 3.0"
    teach = describe_registers(gv_reg(GV_PARAM0), low, params_for=RunCommand.TEACH_ENABLE)
    assert teach[0].label == "GV200 frame = 3.0 (joint)"
    step = describe_registers(gv_reg(GV_PARAM0), low, params_for=RunCommand.STEP_JOINT)
    assert step[0].label == "GV200 J1 offset = 3.0"
    assert describe_registers(gv_reg(GV_PARAM0), low)[0].label == "GV200 = 3.0"
    high = describe_registers(gv_reg(GV_PARAM0), low, WordOrder.HIGH_FIRST)[0]
    assert high.value != 3.0 and high.raw == tuple(low)
    assert (
        describe_registers(
            gv_reg(GV_PARAM0), float_to_registers(3.0, WordOrder.HIGH_FIRST), WordOrder.HIGH_FIRST
        )[0].text
        == "3.0"
    )


def test_a_full_cache_starts_again(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(naming, "ITEM_CACHE_SIZE", 8)
    monkeypatch.setattr(naming, "_FLOAT_ITEMS", {})
    monkeypatch.setattr(naming, "_INT_ITEMS", {})
    for k in range(40):  # GV218, GV219, then registers 440 (run command) and 441 (stop)
        items = describe_registers(REG_RUN_COMMAND - 4, [*encode_floats([float(k), k + 0.5]), k, 1])
        assert [it.text for it in items] == [f"{float(k)}", f"{k + 0.5}", items[2].text, "1"]
        assert [it.value for it in items[2:]] == [k, 1]
        assert 0 < len(naming._FLOAT_ITEMS) <= 8 and 0 < len(naming._INT_ITEMS) <= 8


def test_words_beyond_16_bits_are_masked() -> None:
    items = describe_registers(REG_RUN_COMMAND + 2, [-1, 0x1_0005, True])
    assert [it.value for it in items] == [0xFFFF, 5, 1]


def test_a_summary_formats_only_what_it_shows() -> None:
    items = describe_registers(0, encode_floats([float(i) for i in range(20)]))
    assert summarize_registers(0, items) == (
        "GV0–GV19 (0–39) = 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, … (+12)"
    )
    assert summarize_registers(0, items[:8]) == "GV0–GV7 (0–15) = 0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0"

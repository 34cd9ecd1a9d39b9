"""The watch list's entries and read plan, without a controller: types, checks, blocks, lanes."""

from __future__ import annotations

import math

import pytest

from app.errors import InvalidInput
from app.protocol.codec import WordOrder
from app.protocol.registers import MAX_READ_REGISTERS
from app.watchlist import plan as budget
from app.watchlist.entry import Source, ValueType, WatchEntry, format_value, parse_spec
from app.watchlist.plan import ReadPlan, merge_blocks


def test_defaults_and_keys() -> None:
    gv, reg = WatchEntry.make("gv", 10), WatchEntry.make("reg", 562, "bits", "alarms")
    assert (gv.type, gv.address, gv.count, gv.key) == (ValueType.FLOAT32, 20, 2, "GV10")
    assert (reg.type, reg.address, reg.count, reg.key, reg.title) == (
        ValueType.BITS,
        562,
        1,
        "reg562.bits",
        "alarms",
    )
    assert WatchEntry.make(Source.REGISTER, 40).type is ValueType.INT16
    assert parse_spec(Source.GV, "11:int16=offset") == WatchEntry.make(
        Source.GV, 11, ValueType.INT16, "offset"
    )


@pytest.mark.parametrize("order", list(WordOrder))
def test_float32_in_both_word_orders_int16_negative_and_bits(order: WordOrder) -> None:
    gv = WatchEntry.make(Source.GV, 10)
    regs = gv.encode("30.0", order)
    assert regs == ([0x0000, 0x41F0] if order is WordOrder.LOW_FIRST else [0x41F0, 0x0000])
    assert gv.decode(regs, order) == 30.0
    i16 = WatchEntry.make(Source.REGISTER, 40)
    assert i16.encode(-2, order) == [0xFFFE] and i16.decode([0xFFFE], order) == -2
    bits = WatchEntry.make(Source.REGISTER, 41, ValueType.BITS)
    assert bits.encode("0b101", order) == [5] and format_value(bits, 5) == "0b0000 0000 0000 0101"


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (lambda: WatchEntry.make(Source.GV, 32768), "GV 32768 is out of range (0..32767)"),
        (lambda: WatchEntry.make(Source.GV, -1), "GV -1 is out of range"),
        (
            lambda: WatchEntry.make(Source.REGISTER, 65535, ValueType.FLOAT32),
            "register 65535 is out of range",
        ),
        (lambda: WatchEntry.make(Source.GV, 1, "double"), "unknown type 'double'"),
        (lambda: WatchEntry.make(Source.GV, 1, name="a\nb"), "one line"),
        (lambda: WatchEntry.make(Source.GV, 1).parse_value(math.nan), "not a finite number"),
        (lambda: WatchEntry.make(Source.GV, 1).parse_value("nan"), "not a finite number"),
        (lambda: WatchEntry.make(Source.GV, 1).parse_value(1e39), "does not fit a float32"),
        (lambda: WatchEntry.make(Source.REGISTER, 1).parse_value(32768), "out of range (-32768..32767)"),
        (lambda: WatchEntry.make(Source.REGISTER, 1, "bits").parse_value(-1), "out of range (0..65535)"),
        (lambda: WatchEntry.make(Source.REGISTER, 1).parse_value("1.5"), "not a number"),
    ],
)
def test_bad_input_is_refused_in_words(make: object, words: str) -> None:
    with pytest.raises(InvalidInput) as caught:
        make()  # type: ignore[operator]
    assert words in str(caught.value)


def test_blocks_merge_near_spans_and_stay_within_one_read() -> None:
    entries = [WatchEntry.make(Source.GV, n) for n in (10, 11, 13)]
    assert [(b.address, b.count) for b in merge_blocks(entries)] == [(20, 8)]
    far = [WatchEntry.make(Source.REGISTER, r) for r in range(0, 400, 4)]
    blocks = merge_blocks(far, gap=8)
    assert all(b.count <= MAX_READ_REGISTERS for b in blocks) and len(blocks) == 4


def test_the_first_entries_get_the_fast_lane_the_rest_the_slow_one() -> None:
    ten = tuple(WatchEntry.make(Source.GV, n) for n in range(10, 20))
    plan = ReadPlan.of(ten)
    assert plan.slow == () and plan.fast_entries() == ten
    spread = tuple(WatchEntry.make(Source.GV, n) for n in range(300, 800, 10))  # none in the poll's reads
    plan = ReadPlan.of(spread)
    assert len(plan.fast) == budget.FAST_READS and plan.fast_entries() == spread[:1]
    assert 0 < len(plan.slow) < len(spread) - 1  # the slow lane reads several GVs per request
    live = (WatchEntry.make(Source.GV, 206), WatchEntry.make(Source.REGISTER, 561))  # X, program state
    plan = ReadPlan.of((*live, *spread))
    assert plan.served == live and plan.fast_entries()[:3] == (*live, spread[0])
    assert ReadPlan.of(()).empty

"""Controller clock registers 576..579 (app/protocol/datetime_regs.py)."""

from __future__ import annotations

import datetime as dt

import pytest

from app.protocol.datetime_regs import ControllerClock, DateTimeLayout, decode_clock, encode_clock

WHEN = dt.datetime(2025, 3, 14, 15, 9, 26)


def test_split_words_layout() -> None:
    """576 = year, 577 = month<<8 | day, 578 = hour, 579 = minute<<8 | second."""
    regs = encode_clock(WHEN)
    assert regs == [2025, 0x030E, 15, 0x091A]
    assert encode_clock(WHEN, DateTimeLayout.SPLIT_WORDS) == regs
    clock = decode_clock(regs)
    assert clock.value == WHEN
    assert clock.raw == (2025, 0x030E, 15, 0x091A)
    assert clock.raw_hex == "07E9 030E 000F 091A"


def test_packed32_layout_puts_year_and_hour_in_the_high_words() -> None:
    """One 32-bit value per GV, year (hour) on top; low word first → year in 577."""
    regs = encode_clock(WHEN, DateTimeLayout.PACKED32)
    assert regs == [0x030E, 2025, 0x091A, 15]
    assert decode_clock(regs, DateTimeLayout.PACKED32).value == WHEN
    # Read with the wrong layout, the same words are not a date.
    assert decode_clock(regs, DateTimeLayout.SPLIT_WORDS).value is None


@pytest.mark.parametrize("layout", list(DateTimeLayout))
@pytest.mark.parametrize(
    "when",
    [
        dt.datetime(2000, 1, 1, 0, 0, 0),
        dt.datetime(2024, 2, 29, 23, 59, 59),
        dt.datetime(2099, 12, 31, 12, 30, 5),
    ],
)
def test_round_trip(layout: DateTimeLayout, when: dt.datetime) -> None:
    assert decode_clock(encode_clock(when, layout), layout).value == when


@pytest.mark.parametrize(
    "regs",
    [
        [0, 0, 0, 0],  # a controller that never set its clock
        [2025, 0x0D01, 0, 0],  # month 13
        [2025, 0x0200 | 30, 0, 0],  # 30 February
        [2025, 0x0101, 24, 0],  # hour 24
        [2025, 0x0101, 0, 0x3C00],  # minute 60
        [2025, 0x0101, 0, 0x003C],  # second 60
    ],
)
def test_invalid_words_keep_the_raw_values(regs: list[int]) -> None:
    clock = decode_clock(regs)
    assert clock.value is None
    assert clock.raw == tuple(regs)
    assert clock.raw_hex == " ".join(f"{w:04X}" for w in regs)


def test_words_are_masked_to_16_bits() -> None:
    assert decode_clock([0x10000 + 2025, 0x030E, 15, 0x091A]).raw[0] == 2025


@pytest.mark.parametrize("regs", [[], [2025, 0x0101, 0], [2025, 0x0101, 0, 0, 0]])
def test_four_registers_needed(regs: list[int]) -> None:
    with pytest.raises(ValueError):
        decode_clock(regs)


def test_layout_values_and_dataclass() -> None:
    assert {layout.value for layout in DateTimeLayout} == {"split-words", "packed32"}
    clock = ControllerClock((1, 2, 3, 4), None)
    assert clock.raw_hex == "0001 0002 0003 0004"

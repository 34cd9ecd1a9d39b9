"""Controller date/time registers GV288 (576-577) and GV289 (578-579).

The seed only says "year (2 bytes) + month (1) + day (1)". The layout is a profile
(PROTOCOL.md section 7): ``split-words`` (default) reads 576 = year, 577 = month<<8 | day,
578 = hour, 579 = minute<<8 | second; ``packed32`` reads each GV as one 32-bit value with the
year (hour) in the top 16 bits, which low-word-first puts in the second register.
"""

from __future__ import annotations

import datetime as dt
import enum
from collections.abc import Sequence
from dataclasses import dataclass


class DateTimeLayout(enum.Enum):
    SPLIT_WORDS = "split-words"
    PACKED32 = "packed32"


@dataclass(frozen=True)
class ControllerClock:
    """Decoded controller date/time and the raw words it came from."""

    raw: tuple[int, int, int, int]
    value: dt.datetime | None  # None when the words are not a valid date/time

    @property
    def raw_hex(self) -> str:
        return " ".join(f"{w:04X}" for w in self.raw)


def decode_clock(regs: Sequence[int], layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS) -> ControllerClock:
    """Decode registers 576..579."""
    if len(regs) != 4:
        raise ValueError("date/time needs registers 576..579")
    w = tuple(int(r) & 0xFFFF for r in regs)
    raw = (w[0], w[1], w[2], w[3])
    if layout is DateTimeLayout.SPLIT_WORDS:
        year, md, hour, ms = raw
    else:
        md, year, ms, hour = raw
    try:
        value: dt.datetime | None = dt.datetime(year, md >> 8, md & 0xFF, hour, ms >> 8, ms & 0xFF)
    except ValueError:
        value = None
    return ControllerClock(raw, value)


def encode_clock(when: dt.datetime, layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS) -> list[int]:
    """Registers 576..579 for ``when`` (used by the simulator)."""
    year, md = when.year, (when.month << 8) | when.day
    hour, ms = when.hour, (when.minute << 8) | when.second
    if layout is DateTimeLayout.SPLIT_WORDS:
        return [year, md, hour, ms]
    return [md, year, ms, hour]

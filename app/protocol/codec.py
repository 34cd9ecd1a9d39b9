"""float32 <-> register codec with selectable word order.

Inside one register the two bytes are big-endian (Modbus). The two registers of a float32
are ordered low word first by default (the seed's "little-endian mode"; PROTOCOL.md
section 1); a controller may be set to high word first.
"""

from __future__ import annotations

import enum
import math
import numbers
import struct
from collections.abc import Iterable, Sequence


class WordOrder(enum.Enum):
    """Order of the two 16-bit words of a float32."""

    LOW_FIRST = "low-first"  # seed default: GVn_L holds the low word (CDAB)
    HIGH_FIRST = "high-first"  # ABCD

    @classmethod
    def parse(cls, text: str) -> WordOrder:
        """Accept ``low-first``/``high-first`` (and ``little``/``big``)."""
        key = text.strip().lower()
        aliases = {
            "little": cls.LOW_FIRST,
            "low": cls.LOW_FIRST,
            "cdab": cls.LOW_FIRST,
            "big": cls.HIGH_FIRST,
            "high": cls.HIGH_FIRST,
            "abcd": cls.HIGH_FIRST,
        }
        for member in cls:
            if member.value == key:
                return member
        if key in aliases:
            return aliases[key]
        raise ValueError(f"unknown word order {text!r} (use low-first or high-first)")


def float_to_registers(value: float, order: WordOrder = WordOrder.LOW_FIRST) -> list[int]:
    """Encode one float32 into two registers."""
    (raw,) = struct.unpack(">I", struct.pack(">f", value))
    high, low = raw >> 16, raw & 0xFFFF
    return [low, high] if order is WordOrder.LOW_FIRST else [high, low]


def registers_to_float(regs: Sequence[int], order: WordOrder = WordOrder.LOW_FIRST) -> float:
    """Decode two registers into one float32 (as a Python float)."""
    if len(regs) != 2:
        raise ValueError(f"a float32 needs 2 registers, got {len(regs)}")
    first, second = (int(r) & 0xFFFF for r in regs)
    high, low = (second, first) if order is WordOrder.LOW_FIRST else (first, second)
    (value,) = struct.unpack(">f", struct.pack(">I", (high << 16) | low))
    return float(value)


def encode_floats(values: Iterable[float], order: WordOrder = WordOrder.LOW_FIRST) -> list[int]:
    """Encode consecutive float32 values into registers."""
    out: list[int] = []
    for v in values:
        out.extend(float_to_registers(v, order))
    return out


def decode_floats(regs: Sequence[int], order: WordOrder = WordOrder.LOW_FIRST) -> list[float]:
    """Decode an even number of registers into float32 values."""
    if len(regs) % 2:
        raise ValueError(f"odd register count {len(regs)} cannot hold float32 values")
    return [registers_to_float(regs[i : i + 2], order) for i in range(0, len(regs), 2)]


FLOAT32_MAX: float = struct.unpack(">f", b"\x7f\x7f\xff\xff")[0]


def check_float32(value: float, name: str = "value") -> float:
    """Refuse NaN, infinities and values a float32 cannot hold (numpy scalars are fine)."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise ValueError(f"{name} must be a number, got {value!r}")
    try:
        number = float(value)
    except OverflowError:
        raise ValueError(f"{name} {value} does not fit a float32") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {number}")
    if abs(number) > FLOAT32_MAX:
        raise ValueError(f"{name} {number} does not fit a float32")
    return number


def as_uint16(value: int) -> int:
    """Check an integer register value."""
    if not 0 <= value <= 0xFFFF:
        raise ValueError(f"register value {value} is outside 0..65535")
    return value

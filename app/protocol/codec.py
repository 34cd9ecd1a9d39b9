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

from app.enum_alias import parse_enum


class WordOrder(enum.Enum):
    """Order of the two 16-bit words of a float32."""

    LOW_FIRST = "low-first"  # seed default: GVn_L holds the low word (CDAB)
    HIGH_FIRST = "high-first"  # ABCD

    @classmethod
    def parse(cls, text: str) -> WordOrder:
        """Accept ``low-first``/``high-first`` (and ``little``/``big``)."""
        aliases = {cls.LOW_FIRST: ("little", "low", "cdab"), cls.HIGH_FIRST: ("big", "high", "abcd")}
        return parse_enum(cls, text, aliases, _unknown_word_order)


def _unknown_word_order(text: str) -> ValueError:
    return ValueError(f"unknown word order {text!r} (use low-first or high-first)")


# The two word orders as byte orders: a float32 packed little-endian reads, as little-endian
# 16-bit words, low word first (CDAB); packed and read big-endian, high word first (ABCD). One
# struct call per block instead of two per float (the upload writes a pose for every point).
# Compiled per block size, kept per word order (keyed by ``is``: an Enum hashes in Python).
_LOW_FIRST: dict[int, tuple[struct.Struct, struct.Struct]] = {}  # n -> (n floats, 2n registers)
_HIGH_FIRST: dict[int, tuple[struct.Struct, struct.Struct]] = {}


def _structs(n: int, order: WordOrder) -> tuple[struct.Struct, struct.Struct]:
    """(``n`` float32, ``2n`` registers) in ``order``, compiled once."""
    cache = _LOW_FIRST if order is WordOrder.LOW_FIRST else _HIGH_FIRST
    pair = cache.get(n)
    if pair is None:
        e = "<" if order is WordOrder.LOW_FIRST else ">"
        pair = cache[n] = (struct.Struct(f"{e}{n}f"), struct.Struct(f"{e}{2 * n}H"))
    return pair


def float_to_registers(value: float, order: WordOrder = WordOrder.LOW_FIRST) -> list[int]:
    """Encode one float32 into two registers."""
    (raw,) = struct.unpack(">I", struct.pack(">f", value))
    high, low = raw >> 16, raw & 0xFFFF
    return [low, high] if order is WordOrder.LOW_FIRST else [high, low]


def registers_to_float(regs: Sequence[int], order: WordOrder = WordOrder.LOW_FIRST) -> float:
    """Decode two registers into one float32 (as a Python float)."""
    if len(regs) != 2:
        raise ValueError(f"a float32 needs 2 registers, got {len(regs)}")
    floats, words = _structs(1, order)
    (value,) = floats.unpack(words.pack(int(regs[0]) & 0xFFFF, int(regs[1]) & 0xFFFF))
    return float(value)


def encode_floats(values: Iterable[float], order: WordOrder = WordOrder.LOW_FIRST) -> list[int]:
    """Encode consecutive float32 values into registers (as :func:`float_to_registers` each)."""
    items = values if isinstance(values, (list, tuple)) else list(values)
    floats, words = _structs(len(items), order)
    return list(words.unpack(floats.pack(*items)))


def decode_floats(regs: Sequence[int], order: WordOrder = WordOrder.LOW_FIRST) -> list[float]:
    """Decode an even number of registers into float32 values (as :func:`registers_to_float` each)."""
    n = len(regs)
    if n % 2:
        raise ValueError(f"odd register count {n} cannot hold float32 values")
    floats, words = _structs(n // 2, order)
    try:
        raw = words.pack(*regs)
    except struct.error:  # not plain 16-bit values: each masked, one by one, as before
        return [registers_to_float(regs[i : i + 2], order) for i in range(0, n, 2)]
    return list(floats.unpack(raw))


FLOAT32_MAX: float = struct.unpack(">f", b"\x7f\x7f\xff\xff")[0]


def check_float32(value: float, name: str = "value") -> float:
    """Refuse NaN, infinities and values a float32 cannot hold (numpy scalars are fine)."""
    if type(value) is float and -FLOAT32_MAX <= value <= FLOAT32_MAX:
        return value  # the common case, checked without the ABC test (NaN fails the comparison)
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

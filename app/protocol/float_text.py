"""float32 values as the shortest text that reads back as the same float32.

The traffic inspector shows every GV of every answer it decodes (a pose answer holds 50), so
this is on the GUI thread's path while streaming: keep it cheap.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable
from typing import Final

_FLOAT32: Final = struct.Struct(">f")
_EXACT_INTEGERS: Final = float(1 << 24)  # every integer below this is a float32
_numpy_float32: Callable[[float], object] | None = None  # numpy.float32, imported at first use


def _dragon4_text(value: float) -> str:
    """numpy's float32 text; numpy (0.1 s) is imported by the first value that needs it, not
    when the window starts (this module is on the start-up path through the audit trail)."""
    global _numpy_float32
    if _numpy_float32 is None:
        import numpy

        _numpy_float32 = numpy.float32
    return str(_numpy_float32(value))


def format_float32(value: float) -> str:
    """The shortest text that reads back as the same float32 (``30.0``, ``0.1``, ``-1.0``).

    It runs for every value the traffic inspector shows: small integers are their own repr,
    other float32 values take the shortest digits from numpy's float32 printer (Dragon4),
    which agrees with the digit search below except beside a power of two, where the
    float32 spacing changes and the search, the reference, is used.
    """
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    try:
        packed = _FLOAT32.pack(value)
    except OverflowError:
        return repr(value)
    if _FLOAT32.unpack(packed)[0] == value:  # a float32 itself (a decoded register pair)
        if value.is_integer() and -_EXACT_INTEGERS < value < _EXACT_INTEGERS:
            return repr(value)
        if packed[1] & 0x7F or packed[2] or packed[3]:  # mantissa bits: not a power of two
            return repr(float(_dragon4_text(value)))
    return _search_float32_text(value, packed)


def _search_float32_text(value: float, packed: bytes) -> str:
    """The fewest significant digits (``%g``) that read back as ``packed``, by search."""

    def shortened(digits: int) -> float | None:
        candidate = float(f"{value:.{digits}g}")
        try:
            return candidate if _FLOAT32.pack(candidate) == packed else None
        except OverflowError:
            return None

    # 9 significant digits always read back as the same float32; find the fewest that do.
    low, high = 1, 9
    best = shortened(high)
    while low < high:
        middle = (low + high) // 2
        candidate = shortened(middle)
        if candidate is None:
            low = middle + 1
        else:
            best, high = candidate, middle
    return repr(best if best is not None else value)


__all__ = ["format_float32"]

"""How a point's numbers read, the same in the points table, its cell editor and the CSV.

The controller holds every coordinate as a float32, so a value read back from it carries the
float32's binary noise (596.9028930664062). The rule, one place for every view:

* **Shortest float32 text**: a value that is a float32 (read from the controller) is written
  with the fewest digits that read back as the same float32
  (:func:`app.protocol.float_text.format_float32`): ``596.903``, ``400.0``; sending that text
  sends the same float32 the controller holds. Any other value (typed, computed) is written
  with the fewest digits that read back as itself (Python's ``repr``): nothing is lost.
* **Zero below the display resolution**: the table shows 3 decimals (0.001 mm / 0.001°); a value
  nearer 0 than half of that (``ZERO_BELOW``, e.g. -9.2e-06 after a teach at 0) reads ``0.0``,
  and ``-0.000`` reads ``0.000``.
* **+180°, not -180°**: A and C are angles whose ±180° is one orientation. A value that would
  show as -180.000 (within ``ZERO_BELOW`` of -180) reads as its +180 twin, so two points taught
  in the same orientation read the same. Only the text changes: the point keeps its value.
"""

from __future__ import annotations

import math
import struct
from typing import Final

from app.protocol.float_text import format_float32

__all__ = ["ANGLE_WRAP_FIELDS", "DISPLAY_DECIMALS", "ZERO_BELOW", "display_text", "shown_value", "value_text"]

DISPLAY_DECIMALS: Final = 3
ZERO_BELOW: Final = 0.5 * 10.0**-DISPLAY_DECIMALS  # nearer 0 than this: reads 0
ANGLE_WRAP_FIELDS: Final = frozenset({"a", "c"})  # angles whose -180 reads +180 (B spans ±90 only)
_FLOAT32: Final = struct.Struct("<f")


def shown_value(value: float, field: str = "") -> float:
    """``value`` as it reads: near 0 is 0.0 (never -0.0), an A or C near -180 is its +180 twin."""
    value = float(value)
    if not math.isfinite(value):
        return value
    if field in ANGLE_WRAP_FIELDS and abs(value + 180.0) < ZERO_BELOW:
        value += 360.0
    if abs(value) < ZERO_BELOW:
        return 0.0
    return value


def value_text(value: float, field: str = "") -> str:
    """The CSV's and the cell editor's text of :func:`shown_value`: the shortest float32 text
    of a float32, else the shortest text that reads back as the value."""
    shown = shown_value(value, field)
    return format_float32(shown) if _is_float32(shown) else repr(shown)


def _is_float32(value: float) -> bool:
    try:
        return bool(_FLOAT32.unpack(_FLOAT32.pack(value))[0] == value)
    except OverflowError:
        return False


def display_text(value: float, field: str = "", decimals: int = DISPLAY_DECIMALS) -> str:
    """The table's text: ``decimals`` places of :func:`shown_value` (never ``-0.000``)."""
    text = f"{shown_value(value, field):.{decimals}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text

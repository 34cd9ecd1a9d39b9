"""A number is shown whole or visibly not at all: never cut to another number.

A readout that right-aligns a number in a fixed room and draws what fits shows the digits on the
right: "-1000.000" in room for eight characters reads "1000.000", a garbled -6.1e29 reads
"1200.000". :func:`fit_number` gives the text to draw in a room: the number itself when it fits,
else :data:`OVERFLOW` ("######", fewer marks in a room too small even for those), and the widget
puts the whole value in its tooltip.

:func:`number_room` is the room a number of a given shape needs in a font: a sign, the widest
digit of that font in every place and the decimal point -- measured, never a character count
(digits are not equally wide in every font, and a fallback font is not always monospaced).
"""

from __future__ import annotations

from typing import Final

from PySide6.QtGui import QFontMetrics

__all__ = ["DIGITS", "OVERFLOW", "fit_number", "number_room", "number_text", "widest_digits"]

OVERFLOW: Final = "######"
DIGITS: Final = "0123456789"
_OVERFLOW_MARK: Final = "#"


def widest_digit(metrics: QFontMetrics) -> str:
    """The digit with the largest advance in this font (the first of equals)."""
    return max(DIGITS, key=metrics.horizontalAdvance)


def widest_digits(text: str, metrics: QFontMetrics) -> str:
    """``text`` with every digit written as the font's widest one: the room any number of that
    shape needs (a proportional font, or an italic that falls back to one, has unequal digits)."""
    digit = widest_digit(metrics)
    return "".join(digit if c in DIGITS else c for c in text)


def number_room(metrics: QFontMetrics, integer_digits: int, decimals: int, *, sign: bool = True) -> int:
    """Pixels for the widest number of ``integer_digits`` . ``decimals`` (with a minus sign) in the
    font of ``metrics``, e.g. ``-8888.888`` written with the font's widest digit."""
    digit = widest_digit(metrics)
    sample = ("-" if sign else "") + digit * max(1, integer_digits)
    if decimals > 0:
        sample += "." + digit * decimals
    return metrics.horizontalAdvance(sample) + 1  # a fractional advance rounds down


def number_text(value: float, decimals: int) -> str:
    """``value`` with ``decimals`` places, without a "-0.000" flicker around zero."""
    text = f"{value:.{decimals}f}"
    if text.startswith("-") and text.strip("-0.") == "":
        text = text[1:]
    return text


def fit_number(text: str, metrics: QFontMetrics, room: int) -> str:
    """``text`` when it fits in ``room`` pixels, else the overflow marks that do (at least one)."""
    if metrics.horizontalAdvance(text) <= room:
        return text
    marks = len(OVERFLOW)
    while marks > 1 and metrics.horizontalAdvance(_OVERFLOW_MARK * marks) > room:
        marks -= 1
    return _OVERFLOW_MARK * marks

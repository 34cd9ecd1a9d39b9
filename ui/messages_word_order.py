"""The word-order warning in the operator's language (:mod:`app.protocol.word_order_check`): what is
wrong and what to set, and the evidence (the pose read both ways) for the tooltip and the event log.

Numbers are written without letters in either language: a value far from a robot's scale reads
"2.4×10⁻⁴¹", never "2.4e-41"; one that is not a number (NaN, infinity) reads "—"."""

from __future__ import annotations

import math

from PySide6.QtCore import QCoreApplication

from app.protocol.codec import WordOrder
from app.protocol.enums import CARTESIAN_AXIS_NAMES
from app.protocol.word_order_check import WordOrderVerdict

__all__ = ["order_name", "value_text", "word_order_details", "word_order_text"]

_CONTEXT = "WordOrderWords"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


_ORDERS = {
    WordOrder.LOW_FIRST: QT_TRANSLATE_NOOP("WordOrderWords", "low word first (CDAB)"),
    WordOrder.HIGH_FIRST: QT_TRANSLATE_NOOP("WordOrderWords", "high word first (ABCD)"),
}
_WARNING = QT_TRANSLATE_NOOP(
    "WordOrderWords",
    "The controller's floats look word-swapped: set the register profile's word order to {order} "
    "(Safety → Register profile…), then connect again.",
)
_DETAILS = QT_TRANSLATE_NOOP(
    "WordOrderWords",
    "Until then every position and speed read or sent is wrong. Read {current}, the pose is {read}; "
    "read {other}, it is {swapped}.",
)
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def _tr(text: str) -> str:
    return QCoreApplication.translate(_CONTEXT, text)


def order_name(order: WordOrder) -> str:
    return _tr(_ORDERS[order])


def value_text(value: float) -> str:
    """``value`` without letters: plain from 0.001 to a million, else as a power of ten."""
    if not math.isfinite(value):
        return "—"
    size = abs(value)
    if value == 0.0 or 1e-3 <= size < 1e6:
        text = f"{value:.3f}".rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text
    exponent = math.floor(math.log10(size))
    mantissa = value / 10.0**exponent
    if abs(round(mantissa, 1)) >= 10.0:  # 9.96 rounds to 10.0: one power more
        mantissa, exponent = mantissa / 10.0, exponent + 1
    return f"{mantissa:.1f}×10{str(exponent).translate(_SUPERSCRIPT)}"


def word_order_text(verdict: WordOrderVerdict) -> str:
    """What is wrong and what to set, in one sentence (the banner, the status bar)."""
    return _tr(_WARNING).format(order=order_name(verdict.suggested))


def _pose(values: tuple[float, ...]) -> str:
    pairs = zip(CARTESIAN_AXIS_NAMES, values, strict=False)
    return "  ".join(f"{name} = {value_text(v)}" for name, v in pairs)


def word_order_details(verdict: WordOrderVerdict) -> str:
    """The evidence: the pose as read with the profile's order and with the other one."""
    return _tr(_DETAILS).format(
        current=order_name(verdict.order),
        read=_pose(verdict.read[:6]),
        other=order_name(verdict.suggested),
        swapped=_pose(verdict.other[:6]),
    )

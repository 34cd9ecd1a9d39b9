"""Another Modbus master's signs in the operator's language (app/link/foreign.py): the banner's
sentence and the plan run's pause say the same sign. The texts keep the ``MainWindow`` context they
had when the window said them (literal ``QCoreApplication.translate`` calls: lupdate collects only
those).

The banner is short (two lines in the control column at 1280×800, so the six jog rows keep their
room): another master, the sign in a few words, what to do. Why it matters and the sign in full are
its tooltip (:func:`foreign_master_details`), as the word-order banner keeps its evidence."""

from __future__ import annotations

from PySide6.QtCore import QCoreApplication

__all__ = ["foreign_master_details", "foreign_master_text", "foreign_sign_text"]


def _value(value: float) -> str:
    """A register number, a GV291 code or a token (whole numbers) without an exponent."""
    return f"{value:.0f}" if value.is_integer() else f"{value:g}"


def foreign_sign_text(what: str, value: float) -> str:
    """What was seen (``what``: "canary", "registers", "gv291"; the value), translated."""
    if what == "canary":
        sign = QCoreApplication.translate("MainWindow", "it wrote its own restart token ({value})")
    elif what == "registers":
        sign = QCoreApplication.translate(
            "MainWindow", "register {value} changed without a write of TeachPad"
        )
    else:
        sign = QCoreApplication.translate(
            "MainWindow", "a command result TeachPad did not cause (GV291 = {value})"
        )
    return sign.format(value=_value(value))


def _short_sign_text(what: str, value: float) -> str:
    """The sign in a few words, for the banner."""
    if what == "canary":
        sign = QCoreApplication.translate("MainWindow", "token {value}")
    elif what == "registers":
        sign = QCoreApplication.translate("MainWindow", "register {value}")
    else:
        sign = QCoreApplication.translate("MainWindow", "GV291 = {value}")
    return sign.format(value=_value(value))


def foreign_master_text(what: str, value: float) -> str:
    """The banner's sentence for a sign of another master, in the language in force."""
    return QCoreApplication.translate(
        "MainWindow", "Another Modbus master is on this controller ({sign}): check who else is connected."
    ).format(sign=_short_sign_text(what, value))


def foreign_master_details(what: str, value: float) -> str:
    """The banner's tooltip: the sign in full and why another master matters."""
    return QCoreApplication.translate(
        "MainWindow",
        "Seen: {sign}. Another master shares the parameter and command registers with TeachPad: "
        "its writes can change what ours do.",
    ).format(sign=foreign_sign_text(what, value))

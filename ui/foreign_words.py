"""Another Modbus master's signs in the operator's language (app/link/foreign.py): the banner's
sentence and the plan run's pause say the same sign. The texts keep the ``MainWindow`` context they
had when the window said them (literal ``QCoreApplication.translate`` calls: lupdate collects only
those)."""

from __future__ import annotations

from PySide6.QtCore import QCoreApplication

__all__ = ["foreign_master_text", "foreign_sign_text"]


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
    return sign.format(value=f"{value:g}")


def foreign_master_text(what: str, value: float) -> str:
    """The banner's sentence for a sign of another master, in the language in force."""
    return QCoreApplication.translate(
        "MainWindow",
        "Another Modbus master is on this controller: {sign}. It shares the parameter and "
        "command registers with TeachPad: its writes can change what ours do. "
        "Check who else is connected.",
    ).format(sign=foreign_sign_text(what, value))

"""The question before TeachPad lets go of a controller that may be moving (Disconnect, closing
the window): stop first, go ahead without stopping, or cancel.

One type and one default dialog; the window and tests replace the callable
(``window.link_guard.ask = lambda question: StopFirst.CANCEL``), as with
:mod:`ui.dialogs.confirm`.
"""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # dialogs: imported when one is shown, not at start-up
    from PySide6.QtWidgets import QAbstractButton, QMessageBox, QWidget

__all__ = ["AskStopFirst", "StopFirst", "StopFirstQuestion", "ask_stop_first", "stop_first_box"]


class StopFirst(enum.Enum):
    STOP = "stop"  # stop all motion, then go ahead
    LEAVE = "leave"  # go ahead, the robot goes on as it is
    CANCEL = "cancel"  # do nothing


@dataclass(frozen=True)
class StopFirstQuestion:
    """The texts, already translated: what is under way (``text``) and the two ways to go on."""

    title: str
    text: str
    stop_label: str  # "Stop, then disconnect"
    leave_label: str  # "Disconnect without stopping"


AskStopFirst = Callable[[StopFirstQuestion], StopFirst]


def stop_first_box(
    parent: QWidget | None, question: StopFirstQuestion
) -> tuple[QMessageBox, dict[QAbstractButton, StopFirst]]:
    """The question box (not shown) and what each of its buttons answers. Stop first is the
    default button (Enter); Escape and the window's close button cancel."""
    from PySide6.QtWidgets import QMessageBox

    box = QMessageBox(QMessageBox.Icon.Warning, question.title, question.text, parent=parent)
    stop = box.addButton(question.stop_label, QMessageBox.ButtonRole.AcceptRole)
    leave = box.addButton(question.leave_label, QMessageBox.ButtonRole.DestructiveRole)
    cancel = box.addButton(QMessageBox.StandardButton.Cancel)
    box.setDefaultButton(stop)
    box.setEscapeButton(cancel)
    return box, {stop: StopFirst.STOP, leave: StopFirst.LEAVE, cancel: StopFirst.CANCEL}


def ask_stop_first(parent: QWidget | None) -> AskStopFirst:
    """The default question: a modal box, cancel unless a way on was chosen."""

    def ask(question: StopFirstQuestion) -> StopFirst:
        box, answers = stop_first_box(parent, question)
        box.exec()
        clicked = box.clickedButton()
        answer = answers.get(clicked, StopFirst.CANCEL) if clicked is not None else StopFirst.CANCEL
        box.deleteLater()
        return answer

    return ask

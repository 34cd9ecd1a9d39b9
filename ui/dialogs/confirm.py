"""The operator's yes/no question before anything moves the arm or changes the controller.

One type and one default dialog for every panel that asks; tests and the main window replace
it with a callable (``window.confirm = lambda title, text: True``).
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtWidgets import QWidget

ConfirmFn = Callable[[str, str], bool]  # (title, question) -> go ahead?

__all__ = ["ConfirmFn", "ask_confirmation"]


def ask_confirmation(parent: QWidget) -> ConfirmFn:
    """The default confirmation: a Yes/Cancel question box, Cancel being the default."""

    def confirm(title: str, text: str) -> bool:
        from PySide6.QtWidgets import QMessageBox  # dialogs: imported when one is shown, not at start-up

        answer = QMessageBox.question(
            parent,
            title,
            text,
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.Cancel,
            QMessageBox.StandardButton.Cancel,
        )
        return answer == QMessageBox.StandardButton.Yes

    return confirm

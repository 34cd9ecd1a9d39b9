"""The soak's answers to every modal dialog the window opens (nobody sits at an offscreen window).

A timer in the GUI thread looks at :meth:`QApplication.activeModalWidget` every
:data:`LOOK_MS`; a dialog that has been up for its random reading time is answered, as an
operator would: a question box gets one of its buttons, a file dialog a file in the soak's
folder (or Cancel), any other dialog OK or Cancel. While the window closes (:attr:`closing`) the
answers are the ones that let it close (Discard, No). A dialog that is still up
:data:`STUCK_AFTER` s after its first answer is a failure (``stuck``).

An answer is posted (a zero timer), never given from the look itself: an answer may open the
next dialog (a file dialog's "replace it?"), whose own loop would then run inside the look, and
Qt does not fire a timer again while its slot runs -- nobody would answer that one.
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QObject, QTimer, Slot
from PySide6.QtWidgets import QApplication, QDialog, QFileDialog, QLineEdit, QMessageBox, QWidget

__all__ = ["LOOK_MS", "STUCK_AFTER", "Answerer"]

LOOK_MS = 100
STUCK_AFTER = 30.0  # s a dialog may stay up after it was answered
READ_TIME = (0.15, 1.5)  # s an operator looks at a dialog before answering (uniform)
_CLOSING_ROLES = (QMessageBox.ButtonRole.DestructiveRole, QMessageBox.ButtonRole.NoRole)


class Answerer(QObject):
    """Answers modal dialogs (see the module docstring); ``say`` logs each answer."""

    def __init__(
        self, rng: random.Random, folder: Path, say: Callable[[str], None], parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self._rng = rng
        self._folder = folder
        self._say = say
        self.closing = False
        self.answered = 0
        self.stuck: str | None = None
        self._current: QWidget | None = None
        self._answer_at = 0.0
        self._first_answer = 0.0
        self._files = 0
        self._timer = QTimer(self)
        self._timer.setInterval(LOOK_MS)
        self._timer.timeout.connect(self.look)
        self._timer.start()

    def stop(self) -> None:
        self._timer.stop()

    @Slot()
    def look(self) -> None:
        dialog = QApplication.activeModalWidget()
        now = time.monotonic()
        if dialog is None:
            self._current = None
            return
        if dialog is not self._current:
            self._current = dialog
            self._answer_at = now + self._rng.uniform(*READ_TIME)
            self._first_answer = 0.0
            return
        if now < self._answer_at:
            return
        if self._first_answer and now - self._first_answer > STUCK_AFTER:
            self.stuck = f"{type(dialog).__name__} {dialog.windowTitle()!r} still open after its answers"
            return
        self._first_answer = self._first_answer or now
        self._answer_at = now + 1.0  # once a second until it is gone
        self.answered += 1
        self._answer(dialog)

    def _answer(self, dialog: QWidget) -> None:
        if isinstance(dialog, QMessageBox):
            self._answer_box(dialog)
        elif isinstance(dialog, QFileDialog):
            self._answer_file(dialog)
        elif isinstance(dialog, QDialog):
            ok = not self.closing and self._rng.random() < 0.3
            self._say(f"dialog {type(dialog).__name__} {dialog.windowTitle()!r}: {'OK' if ok else 'Cancel'}")
            QTimer.singleShot(0, dialog, dialog.accept if ok else dialog.reject)
        else:
            self._say(f"modal {type(dialog).__name__}: closed")
            QTimer.singleShot(0, dialog, dialog.close)

    def _answer_box(self, box: QMessageBox) -> None:
        buttons = box.buttons()
        if not buttons:
            QTimer.singleShot(0, box, box.close)
            return
        button = self._rng.choice(buttons)
        if self.closing:
            preferred = [b for b in buttons if box.buttonRole(b) in _CLOSING_ROLES]
            button = preferred[0] if preferred else button
        self._say(f"question {box.windowTitle()!r} ({box.text()[:60]!r}): {button.text()!r}")
        QTimer.singleShot(0, button, button.click)

    def _answer_file(self, dialog: QFileDialog) -> None:
        saving = dialog.acceptMode() == QFileDialog.AcceptMode.AcceptSave
        name_field = dialog.findChild(QLineEdit, "fileNameEdit")  # Qt's own dialog (no native one offscreen)
        if self.closing or not saving or name_field is None or self._rng.random() < 0.2:
            self._say(f"file dialog {dialog.windowTitle()!r}: Cancel")
            QTimer.singleShot(0, dialog, dialog.reject)
            return
        self._files += 1
        suffix = dialog.defaultSuffix() or _suffix(dialog.nameFilters())
        name = f"soak-{self._files:04d}{suffix}"
        self._say(f"file dialog {dialog.windowTitle()!r}: {name}")
        dialog.setDirectory(str(self._folder))
        name_field.setText(name)  # typed (selectFile leaves the suggested name in a save dialog)
        QTimer.singleShot(0, dialog, dialog.accept)


def _suffix(filters: list[str]) -> str:
    """``.zip`` from ``Zip files (*.zip)``; "" when the first filter names no extension."""
    if filters and "(*." in filters[0]:
        ext = filters[0].split("(*.", 1)[1].split(")", 1)[0].split()[0]
        return "" if ext == "*" else f".{ext}"
    return ""

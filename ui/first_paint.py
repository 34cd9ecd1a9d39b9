"""Start-up work the window's first paint does not need runs on the loop turn after that paint.

:class:`AfterFirstPaint` watches a window for its first paint event and then runs a callback once,
when the loop is back: opening the last project (0.2 s for 10,000 points, a recovery question),
the simulator, a fresh install's envelope saved and audited (ui/controllers/safety.py) come after
the window is on screen.
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QEvent, QObject, QTimer
from PySide6.QtWidgets import QWidget


class AfterFirstPaint(QObject):
    """Runs ``callback`` once, on the event-loop turn after ``window``'s first paint."""

    def __init__(self, window: QWidget, callback: Callable[[], object]) -> None:
        super().__init__(window)
        self._window = window
        self._callback: Callable[[], object] | None = callback
        window.installEventFilter(self)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self._window and event.type() == QEvent.Type.Paint and self._callback is not None:
            self._window.removeEventFilter(self)
            QTimer.singleShot(0, self._run)
        return False

    def _run(self) -> None:
        callback, self._callback = self._callback, None
        if callback is not None:
            callback()

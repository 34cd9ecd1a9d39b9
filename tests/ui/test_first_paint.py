"""Start-up work that the first paint does not need runs after it (ui/first_paint.py)."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import QEvent, QObject
from PySide6.QtWidgets import QWidget

from ui.first_paint import AfterFirstPaint


class _Paints(QObject):
    def __init__(self) -> None:
        super().__init__()
        self.count = 0

    def eventFilter(self, _watched: QObject, event: QEvent) -> bool:
        if event.type() == QEvent.Type.Paint:
            self.count += 1
        return False


def test_the_callback_runs_once_after_the_first_paint(qtbot: Any) -> None:
    widget = QWidget()
    qtbot.addWidget(widget)
    paints = _Paints()
    widget.installEventFilter(paints)
    seen: list[int] = []
    AfterFirstPaint(widget, lambda: seen.append(paints.count))
    assert seen == []  # nothing before the window is shown
    widget.resize(200, 200)
    widget.show()
    qtbot.waitUntil(lambda: bool(seen), timeout=5000)
    assert seen[0] >= 1  # the window had painted when it ran
    widget.update()
    qtbot.waitUntil(lambda: paints.count > seen[0], timeout=5000)
    assert len(seen) == 1

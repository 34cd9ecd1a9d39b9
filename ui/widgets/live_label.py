"""A label for a value that changes while the robot streams (a count, a round trip, a clock).

``QLabel.setText`` asks its parent's layout to lay out again, and a layout that is activated
asks its own parent's (``QLayout::activate`` ends in ``updateGeometry``) -- up to the main
window, whose layout then re-places every dock and toolbar (creating a geometry animation for
each) and repaints what it covers. Qt stops that walk at a widget whose size is fixed. A
:class:`LiveLabel` keeps a fixed size: as wide as the widest text it was given up front
(``samples``) or has shown since. A new text repaints the label only; a wider one than ever
before grows it once (one re-layout), and it never shrinks, so nothing beside it moves back
and forth. Its style sheet is set only when it changes (``set_style``): setting one re-polishes
the widget even when the text is the same. ``opaque``: the label fills its own background (the
window colour), so its repaint does not repaint the widgets under it (a dock's title bar, the
status bar); only where the parent's background is the plain window colour.
"""

from __future__ import annotations

from collections.abc import Iterable

from PySide6.QtCore import QEvent
from PySide6.QtWidgets import QLabel, QWidget

__all__ = ["LiveLabel"]


class LiveLabel(QLabel):
    """A ``QLabel`` of fixed size that grows to fit a wider text and never shrinks."""

    def __init__(
        self,
        text: str = "",
        parent: QWidget | None = None,
        *,
        samples: Iterable[str] = (),
        opaque: bool = False,
    ) -> None:
        super().__init__(text, parent)
        self._style = ""
        self.setAutoFillBackground(opaque)
        self.setFixedSize(self.sizeHint())
        self.fit_texts(samples)

    def fit_texts(self, texts: Iterable[str]) -> None:
        """Make room for each of ``texts`` (e.g. the widest value, in every language) now."""
        shown = self.text()
        for text in texts:
            super().setText(text)
            self._grow()
        super().setText(shown)

    def setText(self, text: str) -> None:  # QLabel's name: the label's API
        if text != self.text():
            super().setText(text)  # fixed size: no re-layout above the label
            self._grow()

    def setMinimumHeight(self, height: int) -> None:  # QLabel's name
        super().setMinimumHeight(height)
        self._grow()

    def set_style(self, sheet: str) -> None:
        """``setStyleSheet``, skipped when ``sheet`` is the one already set."""
        if sheet != self._style:
            self._style = sheet
            self.setStyleSheet(sheet)

    def changeEvent(self, event: QEvent) -> None:
        super().changeEvent(event)
        if event.type() in (QEvent.Type.FontChange, QEvent.Type.StyleChange):
            self._grow()  # a font or a style (padding) may need more room

    def _grow(self) -> None:
        hint = self.sizeHint()
        width = max(self.maximumWidth(), hint.width())
        height = max(self.maximumHeight(), hint.height(), self.minimumHeight())
        if (width, height) != (self.maximumWidth(), self.maximumHeight()):
            self.setFixedSize(width, height)

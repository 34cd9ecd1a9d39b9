"""A label for a value that changes while the robot streams (a count, a round trip, a clock).

``QLabel.setText`` asks its parent's layout to lay out again, and a layout that is activated
asks its own parent's (``QLayout::activate`` ends in ``updateGeometry``) -- up to the main
window, whose layout then re-places every dock and toolbar (creating a geometry animation for
each) and repaints what it covers. Qt stops that walk at a widget whose size is fixed. A
:class:`LiveLabel` keeps a fixed size: as wide as the widest text it was given up front
(``samples``) or has shown since; the digits of a sample stand for any digit (room is made for
the widest digit of the font in use), and the samples are measured again when the font or the
style changes (an italic "stale" style may fall back to another font, with other widths). A new
text repaints the label only; a wider one than ever
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

from ui.widgets.number_text import widest_digits

__all__ = ["LiveLabel"]

# Room beyond a sample's measured width: a text of the same shape can round a pixel wider
# (fractional advances, kerning between other digits).
SAMPLE_SLACK_PX = 2


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
        self._samples: dict[str, None] = {}  # ordered, no repeats (retranslate adds them again)
        self.setAutoFillBackground(opaque)
        self.setFixedSize(self.sizeHint())
        self.fit_texts(samples)

    def fit_texts(self, texts: Iterable[str]) -> None:
        """Make room for each of ``texts`` (e.g. the widest value, in every language) now, and
        again whenever the font or the style changes; their digits stand for any digit."""
        self._samples.update(dict.fromkeys(texts))
        self._fit_samples()

    def _fit_samples(self) -> None:
        shown = self.text()
        metrics = self.fontMetrics()
        for text in self._samples:
            for sample in (text, widest_digits(text, metrics)):
                super().setText(sample)
                self._grow(SAMPLE_SLACK_PX)
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
            self._fit_samples()  # a font or a style (padding, italic) may need more room
            self._grow()

    def _grow(self, slack: int = 0) -> None:
        hint = self.sizeHint()
        width = max(self.maximumWidth(), hint.width() + slack)
        height = max(self.maximumHeight(), hint.height(), self.minimumHeight())
        if (width, height) != (self.maximumWidth(), self.maximumHeight()):
            self.setFixedSize(width, height)

"""A label of at most a few lines whose height never changes: a longer text ends in "…", the
whole of it in the tooltip (``elide=True`` for the layout check)."""

from __future__ import annotations

from PySide6.QtCore import QRect, Qt
from PySide6.QtGui import QFontMetrics, QResizeEvent
from PySide6.QtWidgets import QLabel, QWidget

__all__ = ["LinesLabel"]

# A Latin and a Chinese glyph: a line of it is as tall as the taller of the UI's two scripts. The
# Chinese glyphs come from a fallback font (Noto Sans CJK beside DejaVu Sans on a Debian desktop)
# whose lines are taller than the Latin font's (18 px against 14 at 9 pt): a height made of the
# widget font's line spacing cut every Chinese line, and a one-line label showed only "…". The
# height is the probe's, with no slack: where the lines are as tall in both scripts (Noto Sans with
# Noto Sans CJK) it is what the old ``lines x line spacing + 2`` was, and the touch layout at
# 1280x800 has no pixel to spare there.
_PROBE_LINE = "Ag \u4e2d"


def _lines_height(metrics: QFontMetrics, lines: int) -> int:
    """The height of ``lines`` wrapped lines of text in either of the UI's languages (px)."""
    probe = "\n".join([_PROBE_LINE] * lines)
    return metrics.boundingRect(QRect(0, 0, 10_000, 10_000), int(Qt.TextFlag.TextWordWrap), probe).height()


class LinesLabel(QLabel):
    """Wrapped text in at most ``lines`` lines: a longer text ends in "…" and the whole of it
    is in the tooltip. Its height never changes, so the box around it does not move."""

    def __init__(self, lines: int, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._lines = lines
        self._full = ""
        self.setProperty("elide", True)
        self.setWordWrap(True)
        self.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignTop)
        self.setFixedHeight(_lines_height(self.fontMetrics(), lines))  # (no slack: 1 px decides a layout)

    def text(self) -> str:
        """The whole text, also when the label shows it cut short."""
        return self._full

    def shown_text(self) -> str:
        return super().text()

    def setText(self, text: str) -> None:
        self._full = text
        self.setToolTip(text)
        self._fit()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._fit()

    def _fit(self) -> None:
        text = self._full
        metrics = self.fontMetrics()
        room = QRect(0, 0, max(1, self.width()), 10_000)
        flags = int(Qt.TextFlag.TextWordWrap)

        def fits(candidate: str) -> bool:
            return metrics.boundingRect(room, flags, candidate).height() <= self.height()

        if not fits(text):
            low, high = 0, len(text)
            while low < high:  # the longest prefix that fits with the ellipsis
                middle = (low + high + 1) // 2
                if fits(text[:middle].rstrip() + "…"):
                    low = middle
                else:
                    high = middle - 1
            text = text[:low].rstrip() + "…"
        super().setText(text)

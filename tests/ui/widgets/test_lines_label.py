"""LinesLabel (ui/widgets/lines_label.py): a few lines of text in a height that never changes.

Its lines are as tall as a line of either language: on a machine whose Chinese glyphs come from a
fallback font taller than the Latin one (DejaVu Sans with Noto Sans CJK, a Debian desktop with
fonts-noto-cjk: 18 px lines against 14), a height made of the Latin font's line spacing cut every
Chinese line, and a one-line label showed only "…" (`make test-fonts` runs these under that set)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QRect, Qt
from PySide6.QtGui import QFontMetrics

from ui.widgets.lines_label import LinesLabel

CHINESE = "路径全部在工作范围内"  # 10 glyphs
ENGLISH = "The path stays inside"


def _one_line_width(label: LinesLabel, text: str) -> int:
    return QFontMetrics(label.font()).horizontalAdvance(text)


def _shown_lines(label: LinesLabel) -> int:
    """The lines the label's shown text takes at its width (each as tall as the probe's)."""
    metrics = QFontMetrics(label.font())
    flags = int(Qt.TextFlag.TextWordWrap)
    room = QRect(0, 0, label.width(), 10_000)
    one = metrics.boundingRect(room, flags, label.shown_text()[:1] or "X").height()
    return round(metrics.boundingRect(room, flags, label.shown_text()).height() / one)


@pytest.mark.parametrize("text", [CHINESE, ENGLISH, f"{ENGLISH} {CHINESE}"], ids=["zh", "en", "mixed"])
def test_a_line_that_fits_the_width_is_shown_whole(qtbot: Any, text: str) -> None:
    label = LinesLabel(1)
    qtbot.addWidget(label)
    label.resize(_one_line_width(label, text) + 20, label.height())
    label.setText(text)
    assert label.shown_text() == text
    assert label.toolTip() == text


def test_two_wrapped_chinese_lines_are_shown_whole(qtbot: Any) -> None:
    label = LinesLabel(2)
    qtbot.addWidget(label)
    label.resize(_one_line_width(label, CHINESE) + 10, label.height())
    label.setText(f"{CHINESE}{CHINESE}")  # wraps once at this width
    assert label.shown_text() == f"{CHINESE}{CHINESE}"
    assert _shown_lines(label) == 2


def test_a_longer_text_ends_in_an_ellipsis_and_the_tooltip_has_all(qtbot: Any) -> None:
    label = LinesLabel(1)
    qtbot.addWidget(label)
    label.resize(_one_line_width(label, CHINESE) + 10, label.height())
    text = f"{CHINESE}{CHINESE}{CHINESE}"
    label.setText(text)
    shown = label.shown_text()
    assert shown.endswith("…") and len(shown) > 5, shown  # cut, yet most of a line is shown
    assert text.startswith(shown[:-1])
    assert label.text() == label.toolTip() == text


def test_its_height_does_not_change_with_the_text_or_the_language(qtbot: Any) -> None:
    label = LinesLabel(2)
    qtbot.addWidget(label)
    height = label.height()
    for text in (ENGLISH, CHINESE, f"{CHINESE}\n{ENGLISH}", "", ENGLISH * 10):
        label.setText(text)
        assert label.height() == height

"""The "another master" banner at 1280×800 and 1920×1080 (issue 21, the six jog rows): it says
what matters in at most two lines in either language -- another master is on the controller, the
sign, check who else is connected -- and the explanation (it shares the registers, its writes change
what ours do) is its tooltip, as the word-order banner's evidence is. With it up, connected, the
six jog rows show whole without a scroll bar."""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import pytest
from PySide6.QtWidgets import QLabel

from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
)
from tests.ui.test_layout import LANGUAGES, SIZES, make_window_fixture, settle  # noqa: F401 - fixture
from tests.ui.test_messages import assert_chinese
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SIGNS = (("gv291", 17279.0), ("canary", 8388607.0), ("registers", 1199.0))  # the longest values


def wrapped_lines(label: QLabel) -> int:
    """How many lines ``label``'s text wraps to at its width. The one-line height and the line
    height come from probes of the same style holding the label's own text unwrapped (once, then
    twice): a Chinese line is taller than the Latin font's line spacing when its glyphs come from a
    fallback font (DejaVu Sans with Noto Sans CJK: 18 px against 14), and counting it in the
    Latin font's lines saw three lines where two were shown."""

    def unwrapped(text: str) -> int:
        probe = QLabel(text)
        probe.setStyleSheet(label.styleSheet())
        probe.setFont(label.font())
        probe.setWordWrap(True)
        return probe.heightForWidth(100_000)

    one = unwrapped(label.text())
    line = unwrapped(label.text() + "\n" + label.text()) - one
    return 1 + round((label.heightForWidth(label.width()) - one) / line)


@pytest.mark.parametrize(
    ("line", "text"),
    [
        ("路径全部在工作范围", "路径全部在工作范围" * 3),
        ("alpha", "alpha alpha alpha"),
        ("中文 alpha", "中文 alpha 中文 alpha 中文 alpha"),
    ],
    ids=["zh", "en", "mixed"],
)
def test_wrapped_lines_counts_the_lines_shown(qtbot: Any, line: str, text: str) -> None:
    label = QLabel(text)  # ``line`` three times, as wide as ``line`` and its margins: three lines shown
    qtbot.addWidget(label)
    label.setWordWrap(True)
    label.setStyleSheet("padding: 4px; border: 1px solid")
    width = label.fontMetrics().horizontalAdvance(line) + 30  # (less than two lines' width)
    label.resize(width, label.heightForWidth(width))
    assert wrapped_lines(label) == 3


@pytest.mark.parametrize(("what", "value"), SIGNS, ids=[s[0] for s in SIGNS])
@pytest.mark.parametrize("size", SIZES, ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("language", LANGUAGES)
def test_the_jog_rows_fit_under_the_another_master_banner(
    make_window: Callable[..., MainWindow], language: str, size: tuple[int, int], what: str, value: float
) -> None:
    window = make_window(language, size)
    column = window.control_column
    jog = window.jog_panel
    assert column.show_foreign_master(what, value)
    settle()
    banner = column.foreign_banner
    assert banner.isVisible()
    if os.environ.get("TEACHPAD_SHOTS"):
        window.grab().save(
            os.path.join(os.environ["TEACHPAD_SHOTS"], f"foreign-{language}-{size[0]}-{what}.png")
        )
    assert wrapped_lines(banner) <= 2, (banner.text(), banner.height())
    assert banner.height() >= banner.heightForWidth(banner.width())  # shown whole
    bar = jog.axes_scroll.verticalScrollBar()
    assert not bar.isVisible(), (banner.text(), bar.maximum(), banner.height())
    for axis in range(6):
        for direction in (0, 1):
            button = jog.button(axis, direction)
            assert button.isVisible() and button.visibleRegion().boundingRect() == button.rect(), (
                axis,
                direction,
            )
    explanation = banner.toolTip()  # why it matters, where the word-order banner keeps its evidence
    assert explanation and explanation not in banner.text()
    if language == "zh_CN":
        assert_chinese(banner.text())
        assert_chinese(explanation)
    else:
        assert "check who else is connected" in banner.text()
        assert "command registers" in explanation

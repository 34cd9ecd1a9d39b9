"""The status dock's alarm lamps show their whole text at every dock width, lit or not, in both
languages (issue 21: "编码器角度报警" was cut by 4-6 px at 1280×800 and 1920×1080: the panel chose
two columns from a guessed margin, so a dock a few pixels short of two lamps cut both)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtWidgets import QApplication

from app.protocol.enums import Alarm
from tests.ui.layout_audit import clipped_texts
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.panels.status_panel import StatusPanel

WIDTHS = range(240, 440, 2)  # px: a narrow dock to one wide enough for two columns with room


def _clipped_lamps(panel: StatusPanel) -> list[str]:
    return [text for text in clipped_texts(panel) if "AlarmLamp" in text]


@pytest.mark.parametrize("language", ["en", "zh_CN"])
def test_every_alarm_lamp_fits_at_every_dock_width(qtbot: Any, translator: Any, language: str) -> None:
    assert translator.set_language(language)
    panel = StatusPanel()
    qtbot.addWidget(panel)
    panel.show()
    found: list[str] = []
    for width in WIDTHS:
        panel.setFixedWidth(width)
        for lit in (False, True):
            for lamp in panel._all_alarm_lamps():
                lamp.set_active(lit)
            QApplication.processEvents()  # the layout settles (no timer, no signal to wait for)
            found += [
                f"{width} px, {panel.alarm_columns} column(s), lit={lit}: {c}" for c in _clipped_lamps(panel)
            ]
    assert found == [], "\n".join(found[:8])
    encoder = panel.alarm_lamp_for(int(Alarm.ENCODER))
    assert encoder.text() == ("编码器角度报警" if language == "zh_CN" else encoder.text())


def _columns_of_a_fresh_panel(qtbot: Any, width: int) -> int:
    fresh = StatusPanel()
    qtbot.addWidget(fresh)
    fresh.show()
    fresh.setFixedWidth(width)
    QApplication.processEvents()
    return fresh.alarm_columns


@pytest.mark.parametrize("width", [300, 330])
def test_a_new_language_reflows_the_lamps(qtbot: Any, translator: Any, width: int) -> None:
    """Switching the language re-decides the columns for the new texts (no resize needed)."""
    panel = StatusPanel()
    qtbot.addWidget(panel)
    panel.show()
    panel.setFixedWidth(width)
    QApplication.processEvents()
    seen = []
    for language in ("zh_CN", "en"):
        assert translator.set_language(language)
        QApplication.processEvents()
        seen.append(panel.alarm_columns)
        assert panel.alarm_columns == _columns_of_a_fresh_panel(qtbot, width), language
    assert width != 300 or seen == [2, 1]  # 300 px: two columns of Chinese, one of English

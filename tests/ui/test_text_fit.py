"""Widths that fit every language (ui/text_fit.py): at start-up the languages not shown are
measured after the first paint, and the fits made meanwhile are made again then."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from PySide6.QtWidgets import QLabel, QWidget

from ui import text_fit
from ui.panels.control_bar import ControlBar
from ui.panels.pose_strip import PoseStrip
from ui.text_fit import (
    both_languages,
    defer_other_languages,
    fit_in_every_language,
    fit_width,
    measure_other_languages,
)


@pytest.fixture(autouse=True)
def measured_at_once() -> Iterator[None]:
    yield
    measure_other_languages(refit=False)  # as every other test expects it


def _widths(strip: PoseStrip, bar: ControlBar) -> list[int]:
    fixed: list[QWidget] = [
        strip.mode_chip,
        strip.program_chip,
        strip.freshness,
        strip.mode_caption,
        strip.program_caption,
    ]
    fixed += [*strip.units.values(), bar.stop_button, bar.mode_label]
    return [widget.maximumWidth() for widget in fixed]


def test_without_a_deferral_every_language_is_measured_at_once() -> None:
    assert both_languages("ControlBar", "STOP") == ["STOP", "停止"]
    calls: list[int] = []
    fit_in_every_language(lambda: calls.append(1))
    measure_other_languages()
    assert calls == [1]  # run once: nothing waited


def test_the_languages_not_shown_wait_and_the_fits_are_made_again_then(qtbot: Any) -> None:
    strip, bar = PoseStrip(), ControlBar()
    qtbot.addWidget(strip)
    qtbot.addWidget(bar)
    expected = _widths(strip, bar)

    defer_other_languages("en")
    assert both_languages("ControlBar", "STOP") == ["STOP"]  # Chinese (its fonts) not measured yet
    early_strip, early_bar = PoseStrip(), ControlBar()
    qtbot.addWidget(early_strip)
    qtbot.addWidget(early_bar)
    label = QLabel()
    qtbot.addWidget(label)
    # a text whose Chinese is the wider ("tool": 工具坐标系): the width grows once Chinese is measured
    fit_in_every_language(lambda: label.setFixedWidth(fit_width(label, both_languages("Protocol", "tool"))))
    assert label.maximumWidth() == fit_width(label, ["tool"])

    measure_other_languages()
    assert both_languages("ControlBar", "STOP") == ["STOP", "停止"]
    assert _widths(early_strip, early_bar) == expected  # the same as measured at once
    assert label.maximumWidth() == fit_width(label, ["工具坐标系"]) > fit_width(label, ["tool"])
    assert text_fit._waiting_fits == []  # made again once, not at every later call
    measure_other_languages()
    assert _widths(early_strip, early_bar) == expected


def test_the_language_shown_is_measured_at_once(qtbot: Any) -> None:
    defer_other_languages("zh_CN")  # a Chinese window: its texts are in its first paint
    assert both_languages("ControlBar", "STOP") == ["STOP", "停止"]


def test_a_window_gone_before_its_paint_leaves_no_fit_behind() -> None:
    calls: list[int] = []
    defer_other_languages("en")
    fit_in_every_language(lambda: calls.append(1))
    measure_other_languages(refit=False)
    assert calls == [1] and text_fit._waiting_fits == []
    assert both_languages("ControlBar", "STOP") == ["STOP", "停止"]  # measured at once from then on

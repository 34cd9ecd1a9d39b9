"""The shared export flow: a chosen path is written, a failed write is shown in words."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtGui import QFont, QFontMetrics, QPalette
from PySide6.QtWidgets import QFileDialog, QLabel, QMessageBox, QWidget

from ui import widgets_common
from ui.palette import COLOR_NEUTRAL
from ui.panels.jog_panel import JogPanel
from ui.panels.pose_strip import PoseStrip
from ui.widgets.number_text import number_room
from ui.widgets_common import NumericReadout, export_with_dialog, monospace_font


@pytest.fixture
def parent(qtbot: Any) -> QWidget:
    widget = QWidget()
    qtbot.addWidget(widget)
    return widget


def test_export_writes_the_chosen_path(
    parent: QWidget, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    target = tmp_path / "out.txt"
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a: (str(target), ""))
    export_with_dialog(parent, "Export", "x.txt", "*", lambda path: Path(path).write_text("ok"))
    assert target.read_text() == "ok"


def test_a_cancelled_dialog_exports_nothing(parent: QWidget, monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[str] = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a: ("", ""))
    export_with_dialog(parent, "Export", "x.txt", "*", calls.append)
    assert calls == []


def test_a_failed_write_is_shown_not_raised(
    parent: QWidget, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shown: list[tuple[str, str]] = []
    monkeypatch.setattr(QFileDialog, "getSaveFileName", lambda *a: (str(tmp_path / "no" / "x.txt"), ""))
    monkeypatch.setattr(QMessageBox, "warning", lambda _p, title, text: shown.append((title, text)))

    def export(path: str) -> None:
        Path(path).write_text("x")  # the folder does not exist: OSError

    export_with_dialog(parent, "Export log", "x.txt", "*", export)
    assert len(shown) == 1
    assert shown[0][0] == "Export log"
    assert shown[0][1].startswith(f"Could not write {tmp_path / 'no' / 'x.txt'}: ")


def test_readouts_of_one_shape_share_a_measure_that_is_the_fonts(
    qtbot: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    rooms: dict[tuple[str, int, int], int] = {}
    monkeypatch.setattr(widgets_common, "_number_rooms", rooms)
    x, y = NumericReadout("X", "mm"), NumericReadout("Y", "mm")
    j1 = NumericReadout("J1", "°", decimals=2, integer_digits=3)
    for readout in (x, y, j1):
        qtbot.addWidget(readout)
    for points in (8.0, 13.5, 22.0, 40.0):
        font = monospace_font(points, bold=True)
        for readout in (x, y, j1):
            readout.width_for(points)
        fresh = number_room(QFontMetrics(QFont(font)), 4, 3)  # measured now, not kept
        assert rooms[(font.key(), 4, 3)] == fresh
        assert rooms[(font.key(), 3, 2)] == number_room(QFontMetrics(QFont(font)), 3, 2)
    # one measure per shape and size (the readouts' own sizes, 22 pt, among them), not one per readout
    assert len(rooms) == 2 * 4
    assert x._number.minimumWidth() == rooms[(monospace_font(22.0, bold=True).key(), 4, 3)]


def test_captions_and_units_are_neutral_by_palette_in_every_state(qtbot: Any) -> None:
    """Captions and units take COLOR_NEUTRAL from their palette, not from a style sheet of their
    own (each such label was styled by Qt's style-sheet style in the window's first show): the
    readouts', the pose strip's, the jog panel's hints; disabled (stale) as enabled."""
    readout = NumericReadout("X", "mm")
    strip = PoseStrip()
    jog = JogPanel()
    for widget in (readout, strip, jog):
        qtbot.addWidget(widget)
    labels: list[QLabel] = [readout._caption, readout._unit, jog.external_caption, jog.keys_label]
    labels += [*strip.captions.values(), *strip.units.values(), strip.mode_caption, strip.program_caption]
    readout.setEnabled(False)
    strip.setEnabled(False)
    for label in labels:
        assert label.styleSheet() == "", label.text()
        for group in (QPalette.ColorGroup.Active, QPalette.ColorGroup.Inactive, QPalette.ColorGroup.Disabled):
            assert label.palette().color(group, QPalette.ColorRole.WindowText).name() == COLOR_NEUTRAL

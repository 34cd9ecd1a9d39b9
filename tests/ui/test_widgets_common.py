"""The shared export flow: a chosen path is written, a failed write is shown in words."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from PySide6.QtWidgets import QFileDialog, QMessageBox, QWidget

from ui.widgets_common import export_with_dialog


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

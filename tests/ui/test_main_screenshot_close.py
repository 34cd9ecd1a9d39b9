"""``teachpad --screenshot`` closes the window itself: that close is not an operator's, so it never
asks "Save changes?" (nobody would answer: the run would block). A project left dirty is not
written to its file; the changes stay in its autosave, which the next start offers."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtGui import QImage

from app.points.autosave import autosave_path
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    FakeProjectDialogs,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.waits import loop_deadline
from ui import main as teachpad
from ui.controllers.project_dialogs import ProjectDialogs
from ui.main_window import MainWindow

pytestmark = [pytest.mark.timeout(90), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

SAMPLE = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"


def _rename_first_point(window: MainWindow, name: str) -> None:
    model = window.project.points_model
    assert model.setData(model.index(0, 1), name)
    assert window.project.is_dirty


def _first_point_name(path: Path) -> str:
    return str(json.loads(path.read_text(encoding="utf-8"))["points"][0]["name"])


def test_a_screenshot_run_closes_a_dirty_project_without_asking(
    qtbot: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    project = tmp_path / "demo.teachpad.json"
    project.write_bytes(SAMPLE.read_bytes())
    monkeypatch.setattr(teachpad, "SCREENSHOT_SETTLE_MS", 50)
    asked: list[str] = []

    def ask_save_changes(_dialogs: ProjectDialogs, name: str) -> str:
        asked.append(name)
        return "cancel"  # what an unanswered box would mean: the window would stay open

    monkeypatch.setattr(ProjectDialogs, "ask_save_changes", ask_save_changes)
    real_save = teachpad._Screenshot._save

    def edit_then_save(shot: Any) -> None:  # the project is dirty when the run ends
        _rename_first_point(shot.window, "edited during the run")
        real_save(shot)

    monkeypatch.setattr(teachpad._Screenshot, "_save", edit_then_save)
    png = tmp_path / "shot.png"
    args = ["--sim", "--settings", str(tmp_path / "teachpad.ini"), "--lang", "en"]
    with loop_deadline("main()"):
        code = teachpad.main(
            [*args, "--project", str(project), "--screenshot", str(png), "--size", "800x600"]
        )
    assert code == 0 and not QImage(str(png)).isNull()
    assert asked == []  # no question
    assert project.read_bytes() == SAMPLE.read_bytes()  # the file is as the operator saved it
    assert _first_point_name(autosave_path(project)) == "edited during the run"  # nothing lost


def test_an_unattended_close_asks_nothing_and_keeps_the_changes(
    window: MainWindow, project_dialogs: FakeProjectDialogs, tmp_path: Path
) -> None:
    project = tmp_path / "demo.teachpad.json"
    project.write_bytes(SAMPLE.read_bytes())
    assert window.project.open_file(project)
    _rename_first_point(window, "renamed")
    project_dialogs.save_choice = "cancel"
    assert window.close_unattended()
    assert not window.isVisible() and not window.link.is_running
    assert project_dialogs.asked == []
    assert project.read_bytes() == SAMPLE.read_bytes()
    assert _first_point_name(autosave_path(project)) == "renamed"

"""The GUI's CSV import refuses, in words and before anything changes, an import whose project
could not be saved and opened again (issue 19 section 6); the read limit lowered here."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from app.points import atomic
from app.points.ledger_import import ImportMode
from app.points.project import load_project
from app.points.project_model import Project
from tests.ui.controllers.test_project_controller import FakeDialogs
from ui.controllers.project_controller import ProjectController

LIMIT = 20_000


@pytest.fixture
def controller(qtbot: Any, tmp_path: Path) -> Iterator[ProjectController]:
    target = tmp_path / "cell.teachpad.json"
    ctl = ProjectController(
        Project(name="cell"), target, dialogs=FakeDialogs(), autosave_dir=tmp_path / "user"
    )
    yield ctl
    ctl.close()


def test_an_import_too_large_to_be_read_back_is_refused_first(
    qtbot: Any, controller: ProjectController, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(atomic, "MAX_FILE_BYTES", LIMIT)
    dialogs: FakeDialogs = controller.dialogs  # type: ignore[assignment]
    csv = tmp_path / "many.csv"
    rows = [f"{i},P{i},{300 + i},{-i},400,180,0,0" for i in range(1, 401)]
    csv.write_text("\n".join(["id,name,x,y,z,a,b,c", *rows]) + "\n", encoding="utf-8")
    assert csv.stat().st_size < LIMIT
    assert not controller.import_csv(csv, ImportMode.REPLACE)
    title, text = dialogs.errors[-1]
    assert title == "Cannot import points"
    assert "more than TeachPad opens" in text and "nothing was changed or written" in text, text
    assert len(controller.project.ledger) == 0 and controller.undo_stack.count() == 0
    assert not controller.is_dirty
    small = tmp_path / "few.csv"
    small.write_text("\n".join(["id,name,x,y,z,a,b,c", *rows[:20]]) + "\n", encoding="utf-8")
    assert controller.import_csv(small, ImportMode.REPLACE) and len(controller.project.ledger) == 20
    assert controller.save()
    assert len(load_project(tmp_path / "cell.teachpad.json").ledger) == 20

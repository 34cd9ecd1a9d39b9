"""ProjectController: open / save / import / export with injected dialogs, dirty state,
autosave when dirty, recovery when the autosave is newer, malformed files refused."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from app.points.autosave import save_autosave
from app.points.ledger_import import ImportMode
from app.points.lock import live_owner, lock_path
from app.points.point import SyncState
from app.points.project import load_project
from tests.waits import kill_child, read_line, wait_child
from ui.controllers.project_controller import ProjectController
from ui.models.point_columns import COL_X

ROOT = Path(__file__).resolve().parents[3]
SAMPLES = ROOT / "resources" / "samples"


class FakeDialogs:
    """Answers the controller's questions from lists; records errors."""

    def __init__(self) -> None:
        self.errors: list[tuple[str, str]] = []
        self.paths: list[str | None] = []
        self.save_choice = "cancel"
        self.recover = True
        self.asked_recover: list[Path] = []
        self.import_mode: ImportMode | None = ImportMode.REPLACE
        self.empty_import_ok = False
        self.asked_empty: list[int] = []

    def open_path(self, title: str, filters: str) -> str | None:
        return self.paths.pop(0) if self.paths else None

    def save_path(self, title: str, filters: str, suggested: str) -> str | None:
        return self.paths.pop(0) if self.paths else None

    def error(self, title: str, text: str) -> None:
        self.errors.append((title, text))

    def ask_save_changes(self, name: str) -> str:
        return self.save_choice

    def ask_recover(self, autosave: Path, project_path: Path | None) -> bool:
        self.asked_recover.append(autosave)
        return self.recover

    def ask_import_mode(self) -> ImportMode | None:
        return self.import_mode

    def ask_empty_import(self, existing: int) -> bool:
        self.asked_empty.append(existing)
        return self.empty_import_ok


@pytest.fixture
def project_file(tmp_path: Path) -> Path:
    target = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", target)
    return target


@pytest.fixture
def dialogs() -> FakeDialogs:
    return FakeDialogs()


@pytest.fixture
def controller(
    qtbot: Any, project_file: Path, dialogs: FakeDialogs, tmp_path: Path
) -> Iterator[ProjectController]:
    ctl = ProjectController(
        load_project(project_file),
        project_file,
        dialogs=dialogs,
        autosave_interval=0.05,
        autosave_dir=tmp_path / "user",
    )
    yield ctl
    ctl.close()


def edit_something(controller: ProjectController) -> None:
    model = controller.points_model
    assert model.setData(model.index(0, COL_X), "401.5")


def test_dirty_tracking_and_title(qtbot: Any, controller: ProjectController) -> None:
    assert not controller.is_dirty and controller.title == "demo.teachpad.json"
    with qtbot.waitSignal(controller.dirtyChanged, check_params_cb=lambda dirty: dirty):
        edit_something(controller)
    assert controller.title == "demo.teachpad.json*"
    controller.plans_model.add_plan()
    assert controller.save()
    assert not controller.is_dirty
    reloaded = load_project(controller.path)  # type: ignore[arg-type]
    assert reloaded.ledger[0].x == 401.5 and len(reloaded.plans) == 3


def test_autosave_written_when_dirty_only(qtbot: Any, controller: ProjectController) -> None:
    auto = controller.autosave_file
    assert auto.name == "demo.teachpad.autosave.json"
    assert controller.autosave_timer.isActive()
    assert controller.autosave_now() is None  # clean: nothing written
    assert not auto.exists()
    edit_something(controller)
    with qtbot.waitSignal(controller.autosaved, timeout=5000) as saved:
        pass  # the timer fires
    assert saved.args == [str(auto)]
    assert load_project(auto).ledger[0].x == 401.5
    assert controller.autosave_now() is None  # nothing new since
    assert controller.save()
    assert not auto.exists()  # a save removes it
    controller.close()
    assert not controller.autosave_timer.isActive()


def test_recovery_offered_when_the_autosave_is_newer(
    qtbot: Any, project_file: Path, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    crashed = ProjectController(
        load_project(project_file), project_file, dialogs=dialogs, autosave_interval=0
    )
    edit_something(crashed)
    auto = crashed.autosave_now()
    assert auto is not None and crashed.wait_autosave()  # written by the autosave's own thread
    stamp = project_file.stat().st_mtime_ns
    os.utime(auto, ns=(stamp + 10**9, stamp + 10**9))
    # next start
    fresh = ProjectController(load_project(project_file), project_file, dialogs=dialogs, autosave_interval=0)
    assert fresh.check_recovery() == auto
    with qtbot.waitSignal(fresh.projectReplaced):
        assert fresh.offer_recovery()
    assert dialogs.asked_recover == [auto]
    assert fresh.project.ledger[0].x == 401.5
    assert fresh.is_dirty and fresh.path == project_file
    assert fresh.undo_stack.count() == 0


def test_recovery_declined_removes_the_autosave(qtbot: Any, project_file: Path, dialogs: FakeDialogs) -> None:
    ctl = ProjectController(load_project(project_file), project_file, dialogs=dialogs, autosave_interval=0)
    edit_something(ctl)
    auto = ctl.autosave_now()
    assert auto is not None and ctl.wait_autosave()
    stamp = project_file.stat().st_mtime_ns
    os.utime(auto, ns=(stamp + 10**9, stamp + 10**9))
    dialogs.recover = False
    fresh = ProjectController(load_project(project_file), project_file, dialogs=dialogs, autosave_interval=0)
    assert not fresh.offer_recovery()
    assert not auto.exists() and fresh.project.ledger[0].x == 400.0
    # an autosave older than the project is not offered
    edit_something(fresh)
    assert fresh.autosave_now() == auto and fresh.wait_autosave()
    os.utime(auto, ns=(stamp - 10**9, stamp - 10**9))
    assert fresh.check_recovery() is None


def test_untitled_project_autosaves_in_the_user_directory(
    qtbot: Any, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    ctl = ProjectController(dialogs=dialogs, autosave_interval=0, autosave_dir=tmp_path / "user")
    ctl.points_model.add_point()
    auto = ctl.autosave_now()
    assert auto == tmp_path / "user" / "untitled.autosave.json" and ctl.wait_autosave()
    fresh = ProjectController(dialogs=dialogs, autosave_interval=0, autosave_dir=tmp_path / "user")
    assert fresh.check_recovery() == auto
    assert fresh.offer_recovery() and len(fresh.project.ledger) == 1


def test_malformed_csv_leaves_the_table_as_it_was(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("id,name,x,y,z,a,b,c\n1,a,1,2,3,4,5,6\n2,b,1,abc,3,4,5,6\n", encoding="utf-8")
    before = controller.project.ledger.snapshot()
    model = controller.points_model
    with qtbot.assertNotEmitted(model.modelReset):
        assert not controller.import_csv(bad)
    text = dialogs.errors[-1][1]
    assert "row 3" in text and "column 'y'" in text and "'abc' is not a number" in text
    assert controller.project.ledger.snapshot() == before
    assert controller.undo_stack.count() == 0 and not controller.is_dirty


def test_import_and_export_csv(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    out = tmp_path / "out.csv"
    dialogs.paths.append(str(out))
    assert controller.export_csv()
    assert out.read_bytes().startswith(b"\xef\xbb\xbfid,name,")
    controller.points_model.remove_rows([0, 1])
    dialogs.import_mode = ImportMode.MERGE
    assert controller.import_csv(out)
    assert controller.project.ledger.ids() == [3, 4, 5, 6, 7, 8, 1, 2]
    controller.undo_stack.undo()
    assert controller.project.ledger.ids() == [3, 4, 5, 6, 7, 8]


def test_malformed_project_is_refused(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    bad = tmp_path / "bad.teachpad.json"
    text = (SAMPLES / "demo.teachpad.json").read_text(encoding="utf-8").replace('"x": 450.0', '"x": "abc"', 1)
    bad.write_text(text, encoding="utf-8")
    project = controller.project
    assert not controller.open_file(bad)
    assert "point 2 (id 2)" in dialogs.errors[-1][1] and "field 'x'" in dialogs.errors[-1][1]
    assert controller.project is project


def test_open_asks_to_save_changes(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    other = tmp_path / "other.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", other)
    edit_something(controller)
    dialogs.save_choice = "cancel"
    assert not controller.open_file(other)
    dialogs.save_choice = "discard"
    with qtbot.waitSignal(controller.pathChanged):
        assert controller.open_file(other)
    assert controller.path == other and not controller.is_dirty
    assert controller.project.ledger[0].x == 400.0 and controller.undo_stack.count() == 0
    assert controller.points_model.rowCount() == 8 and controller.plans_model.rowCount() == 2


def test_save_as_and_actions(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    target = tmp_path / "copy"
    dialogs.paths.append(str(target))
    controller.action_save_as.trigger()
    assert controller.path == tmp_path / "copy.teachpad.json" and controller.path.exists()
    assert [a.text() if a else None for a in controller.file_actions()][:4] == [
        "&New project",
        "&Open project…",
        "&Save project",
        "Save project &as…",
    ]
    edit_something(controller)
    assert controller.action_undo.isEnabled()
    controller.action_undo.trigger()
    assert controller.project.ledger[0].x == 400.0


# --- one instance per project ------------------------------------------------------------------


@pytest.fixture
def other_teachpad(project_file: Path) -> Iterator[subprocess.Popen[str]]:
    """Another TeachPad process with ``project_file`` open (it holds the project's lock)."""
    code = (
        "import sys; from app.points.lock import ProjectLock; lock = ProjectLock.acquire(sys.argv[1]); "
        "print('locked', flush=True); sys.stdin.read(); lock.release()"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", code, str(project_file)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    try:
        assert child.stdout is not None
        assert read_line(child.stdout, "the other TeachPad taking the lock").strip() == "locked"
        yield child
    finally:
        kill_child(child)


def test_a_second_teachpad_says_the_project_is_open_instead_of_offering_its_autosave(
    qtbot: Any, project_file: Path, dialogs: FakeDialogs, other_teachpad: subprocess.Popen[str]
) -> None:
    # the other TeachPad has unsaved edits in its (live) autosave, newer than the project
    live = save_autosave(load_project(project_file), project_file)
    stamp = project_file.stat().st_mtime_ns
    os.utime(live, ns=(stamp + 10**9, stamp + 10**9))

    second = ProjectController(dialogs=dialogs, autosave_interval=0)
    assert not second.open_file(project_file)
    assert second.path is None
    assert dialogs.errors and dialogs.errors[-1][0] == "Project in use"
    assert "is open in another TeachPad (process " + str(other_teachpad.pid) in dialogs.errors[-1][1]
    assert not second.save_as(project_file)  # nor overwrite it under the other one's feet

    # constructed on the path directly (e.g. from the command line): still no recovery offer
    direct = ProjectController(load_project(project_file), project_file, dialogs=dialogs, autosave_interval=0)
    assert direct.lock_owner is not None and direct.lock_owner.pid == other_teachpad.pid
    assert direct.check_recovery() is None
    assert not direct.offer_recovery()
    assert dialogs.asked_recover == [] and live.exists()
    assert "autosave belongs to that TeachPad" in dialogs.errors[-1][1]

    # the other TeachPad closes: the project is ours, and its lock too
    assert other_teachpad.stdin is not None
    other_teachpad.stdin.close()
    assert wait_child(other_teachpad, "the other TeachPad, its stdin closed") == 0
    assert direct.lock_owner is None
    assert live_owner(project_file) is None and lock_path(project_file).exists()
    direct.close()
    assert not lock_path(project_file).exists()


def test_the_lock_follows_the_open_project(
    qtbot: Any, controller: ProjectController, project_file: Path, tmp_path: Path
) -> None:
    assert lock_path(project_file).exists()
    other = tmp_path / "other.teachpad.json"
    assert controller.save_as(other)
    assert lock_path(other).exists() and not lock_path(project_file).exists()
    assert controller.new_project()
    assert not lock_path(other).exists()


def test_loaded_points_are_unknown(qtbot: Any, controller: ProjectController) -> None:
    assert all(p.sync is SyncState.UNKNOWN for p in controller.project.ledger)


def test_an_empty_csv_replaces_the_points_only_when_confirmed(
    qtbot: Any, controller: ProjectController, dialogs: FakeDialogs, tmp_path: Path
) -> None:
    empty = tmp_path / "empty.csv"
    empty.write_text("id,x,y,z,a,b,c\n", encoding="utf-8")
    count = len(controller.project.ledger)
    assert not controller.import_csv(empty, ImportMode.REPLACE)
    assert dialogs.asked_empty == [count] and len(controller.project.ledger) == count
    dialogs.empty_import_ok = True
    assert controller.import_csv(empty, ImportMode.REPLACE)
    assert len(controller.project.ledger) == 0
    controller.undo_stack.undo()
    assert len(controller.project.ledger) == count

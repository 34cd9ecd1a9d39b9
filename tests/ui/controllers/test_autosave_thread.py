"""The autosave off the GUI thread (issue 19 s6: a 58 MB project's autosave held the GUI thread for
1.2 s). The GUI thread only takes a snapshot; the file is written by the autosave's own thread, in
order (the newest content ends on disk, also when edits come during a slow write); a close waits
for the write under way; a failure reaches the operator in words.

The write is made slow with a hook that holds it until the test lets it go (no sleeps)."""

from __future__ import annotations

import errno
import shutil
import subprocess
import sys
import threading
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from app.points import autosave
from app.points.atomic import atomic_write_bytes
from app.points.project import load_project
from tests.ui.pendant_support import FakeProjectDialogs
from ui.controllers.project_controller import ProjectController
from ui.models.point_columns import COL_X

ROOT = Path(__file__).resolve().parents[3]
HOLD_LIMIT = 30.0  # s: a held write goes on by itself after this (a failing test must not hang)


class HeldWrites:
    """Replaces the autosave's atomic write: records which thread wrote what; a write outside the
    GUI thread waits for :attr:`gate` first."""

    def __init__(self, real: Callable[..., None]) -> None:
        self.real = real
        self.gate = threading.Event()
        self.entered = threading.Event()
        self.threads: list[threading.Thread] = []
        self.fail_with: OSError | None = None

    def __call__(self, path: Any, data: bytes, **kwargs: Any) -> None:
        self.threads.append(threading.current_thread())
        if threading.current_thread() is not threading.main_thread():
            self.entered.set()
            self.gate.wait(HOLD_LIMIT)
        if self.fail_with is not None:
            raise self.fail_with
        self.real(path, data, **kwargs)


@pytest.fixture
def held(monkeypatch: pytest.MonkeyPatch) -> HeldWrites:
    hook = HeldWrites(atomic_write_bytes)
    monkeypatch.setattr(autosave, "atomic_write_bytes", hook)
    return hook


@pytest.fixture
def controller(qtbot: Any, tmp_path: Path, held: HeldWrites) -> Iterator[ProjectController]:
    path = tmp_path / "demo.teachpad.json"
    shutil.copy(ROOT / "resources" / "samples" / "demo.teachpad.json", path)
    ctl = ProjectController(load_project(path), path, dialogs=FakeProjectDialogs(), autosave_interval=0)
    yield ctl
    held.gate.set()
    ctl.close()


def set_x(ctl: ProjectController, x: float) -> None:
    model = ctl.points_model
    assert model.setData(model.index(0, COL_X), str(x))


def x_on_disk(ctl: ProjectController) -> float:
    return load_project(ctl.autosave_file).ledger[0].x


def test_written_off_the_gui_thread_and_the_newest_edit_ends_on_disk(
    qtbot: Any, controller: ProjectController, held: HeldWrites
) -> None:
    set_x(controller, 401.5)
    assert controller.autosave_now() == controller.autosave_file  # returns with the write held
    qtbot.waitUntil(held.entered.is_set, timeout=5000)
    assert held.threads and held.threads[0] is not threading.main_thread()
    # edits while the first write is held; each is autosaved; the last one must win
    set_x(controller, 402.5)
    assert controller.autosave_now() is not None
    set_x(controller, 403.5)
    assert controller.autosave_now() is not None
    assert not controller.autosave_file.exists()  # still held: nothing written yet
    with qtbot.waitSignal(controller.autosaved, timeout=10_000):
        held.gate.set()
    assert controller.wait_autosave(10.0)
    assert x_on_disk(controller) == 403.5
    assert all(t is not threading.main_thread() for t in held.threads)
    assert len(held.threads) == 2  # the held write, then the newest (402.5 was superseded)
    assert controller.autosave_now() is None  # nothing new since


def test_a_close_waits_for_the_autosave_being_written(
    qtbot: Any, controller: ProjectController, held: HeldWrites, monkeypatch: pytest.MonkeyPatch
) -> None:
    set_x(controller, 404.5)
    controller.autosave_now()
    qtbot.waitUntil(held.entered.is_set, timeout=5000)
    flush = controller.autosaver.flush

    def let_go_then_flush(timeout: float) -> bool:  # the write goes on only once the close waits
        held.gate.set()
        return flush(timeout)

    monkeypatch.setattr(controller.autosaver, "flush", let_go_then_flush)
    assert controller.close()
    assert held.gate.is_set() and controller.autosaver.idle
    assert x_on_disk(controller) == 404.5


def test_a_save_or_a_discard_leaves_no_autosave_landing_after_it(
    qtbot: Any, controller: ProjectController, held: HeldWrites, monkeypatch: pytest.MonkeyPatch
) -> None:
    flush = controller.autosaver.flush

    def let_go_then_flush(timeout: float) -> bool:
        held.gate.set()
        return flush(timeout)

    monkeypatch.setattr(controller.autosaver, "flush", let_go_then_flush)
    set_x(controller, 406.5)
    controller.autosave_now()
    qtbot.waitUntil(held.entered.is_set, timeout=5000)
    set_x(controller, 407.5)
    controller.autosave_now()  # waiting behind the held one: dropped by the save
    assert controller.save()
    assert controller.autosaver.idle and not controller.autosave_file.exists()
    assert load_project(controller.path).ledger[0].x == 407.5  # type: ignore[arg-type]
    held.gate.clear()
    held.entered.clear()
    set_x(controller, 408.5)
    controller.autosave_now()
    qtbot.waitUntil(held.entered.is_set, timeout=5000)
    dialogs = controller.dialogs
    assert isinstance(dialogs, FakeProjectDialogs)
    dialogs.save_choice = "discard"
    assert controller.maybe_save()
    assert controller.autosaver.idle and not controller.autosave_file.exists()


def test_a_failed_autosave_is_said_in_words_and_tried_again(
    qtbot: Any, controller: ProjectController, held: HeldWrites
) -> None:
    held.gate.set()
    held.fail_with = OSError(errno.ENOSPC, "No space left on device")
    set_x(controller, 405.5)
    with qtbot.waitSignal(controller.statusMessage, timeout=10_000) as said:
        controller.autosave_now()
    assert said.args is not None
    text = said.args[0]
    assert text.startswith("Autosave failed:") and "Traceback" not in text
    assert held.threads[-1] is not threading.main_thread()
    held.fail_with = None
    with qtbot.waitSignal(controller.autosaved, timeout=10_000):
        assert controller.autosave_now() is not None  # the same revision again: it is not on disk
    assert x_on_disk(controller) == 405.5


def test_the_autosave_module_imports_alone() -> None:
    # it imported app.points.project, which imported it back (issue 22): ImportError when first
    done = subprocess.run(
        [sys.executable, "-c", "import app.points.autosave"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr[-400:]

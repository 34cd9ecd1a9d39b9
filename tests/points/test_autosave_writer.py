"""AutosaveWriter, the autosave's own thread (Qt-free): in order, the newest job wins, flush waits
for the report, a receiver that is gone does not stop the writer, close ends the thread."""

from __future__ import annotations

import threading
from pathlib import Path

from app.points.autosave import AutosaveDone, AutosaveWriter, write_autosave_file
from app.points.project_model import Project
from app.points.project_write import take_snapshot

HOLD_LIMIT = 30.0  # s: a held write goes on by itself (a failing test must not hang)


def test_jobs_in_order_the_newest_wins_and_flush_waits_for_the_report(tmp_path: Path) -> None:
    gate, entered = threading.Event(), threading.Event()
    written: list[int] = []
    reports: list[AutosaveDone] = []

    def write(target: Path, data: bytes) -> None:
        entered.set()
        gate.wait(HOLD_LIMIT)
        written.append(len(data))
        write_autosave_file(target, data)

    writer = AutosaveWriter(reports.append, write=write)
    project = Project("first")
    target = tmp_path / "p.autosave.json"
    writer.submit(take_snapshot(project), target)
    assert entered.wait(HOLD_LIMIT) and not writer.idle
    for name in ("second", "third"):
        project.name = name
        project.touch()
        writer.submit(take_snapshot(project), target)
    assert not writer.flush(0.01)  # held
    gate.set()
    assert writer.flush(HOLD_LIMIT) and writer.idle
    assert [r.error for r in reports] == [None, None] and len(written) == 2  # "second" superseded
    assert '"name": "third"' in target.read_text(encoding="utf-8")
    assert all(r.thread != threading.current_thread().name for r in reports)
    assert writer.close(HOLD_LIMIT)
    thread = writer._thread
    assert thread is not None and not thread.is_alive()


def test_a_receiver_that_is_gone_does_not_stop_the_writer(tmp_path: Path) -> None:
    def gone(_done: AutosaveDone) -> None:
        raise RuntimeError("Internal C++ object already deleted")

    writer = AutosaveWriter(gone)
    writer.submit(take_snapshot(Project()), tmp_path / "a.autosave.json")
    assert writer.flush(HOLD_LIMIT)
    writer.submit(take_snapshot(Project("b")), tmp_path / "b.autosave.json")
    assert writer.flush(HOLD_LIMIT) and (tmp_path / "b.autosave.json").exists()
    assert writer.close(HOLD_LIMIT)


def test_an_error_is_reported_not_raised(tmp_path: Path) -> None:
    reports: list[AutosaveDone] = []
    blocker = tmp_path / "a file"
    blocker.write_text("", encoding="utf-8")
    writer = AutosaveWriter(reports.append)
    writer.submit(take_snapshot(Project()), blocker / "inside" / "x.autosave.json")  # a file as folder
    assert writer.flush(HOLD_LIMIT) and writer.close(HOLD_LIMIT)
    assert len(reports) == 1 and isinstance(reports[0].error, OSError)

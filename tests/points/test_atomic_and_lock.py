"""Atomic saves survive ``kill -9`` (the file is always a whole old or new version, and the next
save removes the temp files a kill left), and one TeachPad per project (the lock file)."""

from __future__ import annotations

import json
import os
import random
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from app.points import atomic
from app.points.lock import LockOwner, ProjectLock, ProjectLocked, live_owner, lock_path
from app.points.point import make_point
from app.points.project import load_project, save_project
from app.points.project_model import Project
from app.points.project_write import project_to_json
from tests.waits import kill_child, read_line, wait_child

ROOT = Path(__file__).resolve().parents[2]
KILLS = 8

_SAVER = """
import sys
from app.points.atomic import atomic_write_bytes
target, a, b = sys.argv[1], open(sys.argv[2], "rb").read(), open(sys.argv[3], "rb").read()
n = 0
while True:
    atomic_write_bytes(target, a if n % 2 else b)
    n += 1
    print(n, flush=True)
"""


def _project(name: str, n: int) -> Project:
    project = Project(name=name, created="2025-01-01T00:00:00Z", modified="2025-01-01T00:00:00Z")
    for i in range(n):
        project.ledger.append(make_point(i + 1, f"{name} {i}", (i, 2.0 * i, 300, 180, 0, 0), note="n" * 200))
    return project


def _temp_files(directory: Path) -> list[str]:
    return sorted(p.name for p in directory.iterdir() if p.name.startswith(atomic.TEMP_PREFIX))


def test_kill_9_during_saves_leaves_a_whole_file_and_the_next_save_cleans_up(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    old, new = (project_to_json(_project(n, k)).encode("utf-8") for n, k in (("old", 400), ("new", 600)))
    (tmp_path / "a.bin").write_bytes(old)
    (tmp_path / "b.bin").write_bytes(new)
    work = tmp_path / "work"
    work.mkdir()
    target = work / "p.teachpad.json"
    target.write_bytes(old)
    rng = random.Random(1234)
    leftovers_seen = 0
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    for _ in range(KILLS):
        child = subprocess.Popen(
            [sys.executable, "-c", _SAVER, str(target), str(tmp_path / "a.bin"), str(tmp_path / "b.bin")],
            stdout=subprocess.PIPE,
            text=True,
            env=env,
        )
        try:
            assert child.stdout is not None
            for _line in range(rng.randint(1, 6)):  # let it finish a few saves, then kill mid-way
                assert read_line(child.stdout, "the saving child"), "the saving child died"
        finally:
            kill_child(child)  # SIGKILL, mid-save
        assert target.read_bytes() in (old, new)  # never a mix, never empty
        load_project(target)
        leftovers_seen += bool(_temp_files(work))
    # the next save (of our own process) removes every stale temp file of this target
    monkeypatch.setattr(atomic, "STALE_TEMP_AGE", 0.0)
    save_project(load_project(target), target)
    assert _temp_files(work) == [] and sorted(p.name for p in work.iterdir()) == [target.name]
    print(f"temp files left by {leftovers_seen} of {KILLS} kills")


def test_stale_temp_cleanup_takes_only_our_old_files(tmp_path: Path) -> None:
    target = tmp_path / "p.teachpad.json"
    ours_old = tmp_path / f"{atomic.TEMP_PREFIX}p.teachpad.json.0123456789ab{atomic.TEMP_SUFFIX}"
    ours_young = tmp_path / f"{atomic.TEMP_PREFIX}p.teachpad.json.ba9876543210{atomic.TEMP_SUFFIX}"
    other_target = tmp_path / f"{atomic.TEMP_PREFIX}q.teachpad.json.0123456789ab{atomic.TEMP_SUFFIX}"
    not_ours = tmp_path / f"{atomic.TEMP_PREFIX}p.teachpad.json.backup{atomic.TEMP_SUFFIX}"
    for path in (ours_old, ours_young, other_target, not_ours):
        path.write_bytes(b"partial")
    old = 1_000_000_000.0
    for path in (ours_old, other_target, not_ours):
        os.utime(path, (old, old))
    atomic.atomic_write_bytes(target, b"new")
    assert target.read_bytes() == b"new"
    assert not ours_old.exists()
    assert ours_young.exists()  # may be another process's save under way
    assert other_target.exists() and not_ours.exists()


# --- the lock -----------------------------------------------------------------------------------


@pytest.fixture
def other_teachpad(tmp_path: Path) -> Iterator[tuple[subprocess.Popen[str], Path]]:
    """Another process holding the lock of a project, until the test ends."""
    project = tmp_path / "shared.teachpad.json"
    save_project(_project("shared", 3), project)
    code = (
        "import sys; from app.points.lock import ProjectLock; lock = ProjectLock.acquire(sys.argv[1]); "
        "print('locked', flush=True); sys.stdin.read(); lock.release()"
    )
    child = subprocess.Popen(
        [sys.executable, "-c", code, str(project)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    try:
        assert child.stdout is not None
        assert read_line(child.stdout, "the other process taking the lock").strip() == "locked"
        yield child, project
    finally:
        kill_child(child)


def test_a_live_lock_of_another_process_is_respected_and_released(
    other_teachpad: tuple[subprocess.Popen[str], Path],
) -> None:
    child, project = other_teachpad
    owner = live_owner(project)
    assert owner is not None and owner.pid == child.pid and owner.host == socket.gethostname()
    with pytest.raises(ProjectLocked, match="open in another TeachPad") as info:
        ProjectLock.acquire(project)
    assert info.value.owner.pid == child.pid
    assert child.stdin is not None
    child.stdin.close()  # the other TeachPad closes the project
    assert wait_child(child, "the other process, its stdin closed") == 0
    assert not lock_path(project).exists() and live_owner(project) is None
    with ProjectLock.acquire(project) as lock:
        assert lock.held and json.loads(lock.path.read_text())["pid"] == os.getpid()
    assert not lock_path(project).exists()


def test_a_lock_of_a_killed_process_is_stale(other_teachpad: tuple[subprocess.Popen[str], Path]) -> None:
    child, project = other_teachpad
    os.kill(child.pid, signal.SIGKILL)
    wait_child(child, "the killed process")
    assert lock_path(project).exists() and live_owner(project) is None
    lock = ProjectLock.acquire(project)
    assert json.loads(lock.path.read_text())["pid"] == os.getpid()
    lock.release()


def test_lock_of_another_host_is_respected_and_a_corrupt_one_taken_over(tmp_path: Path) -> None:
    project = tmp_path / "p.teachpad.json"
    path = lock_path(project)
    path.write_text(json.dumps({"pid": 1, "host": "other-host.example", "started": "2025-01-01T00:00:00Z"}))
    assert live_owner(project) == LockOwner(1, "other-host.example", "2025-01-01T00:00:00Z")
    with pytest.raises(ProjectLocked, match=r"other-host\.example"):
        ProjectLock.acquire(project)
    path.write_bytes(b'{"pid": 4')  # a kill while the lock was being written
    assert live_owner(project) is None
    lock = ProjectLock.acquire(project)
    again = ProjectLock.acquire(project)  # the same process may open it again
    assert lock.held and again.held
    lock.release()
    assert not path.exists()


def test_the_cli_does_not_write_a_project_open_in_a_teachpad(
    other_teachpad: tuple[subprocess.Popen[str], Path], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import argparse

    from app.cli import points as cli_points
    from app.cli.context import CliContext
    from app.connection import ConnectionSettings

    _child, project = other_teachpad
    csv_path = tmp_path / "in.csv"
    csv_path.write_text("id,x,y,z,a,b,c\n9,1,2,3,0,0,0\n", encoding="utf-8")
    before = project.read_bytes()
    parser = argparse.ArgumentParser()
    cli_points.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(["points", "import", str(project), "--csv", str(csv_path), "--merge"])
    assert args.handler(CliContext(args, ConnectionSettings())) == cli_points.EXIT_FAILED
    assert "open in a TeachPad (process" in capsys.readouterr().err
    assert project.read_bytes() == before

"""Autosave next to the project, and recovery after a crash.

``demo.teachpad.json`` autosaves to ``demo.teachpad.autosave.json`` beside it (atomically, same
format); a project never saved goes to a per-user directory. :func:`find_autosave` offers an
autosave for recovery when it is newer than the project and differs from it. A live autosave
of another running TeachPad (see :mod:`app.points.lock`) is not a crash leftover: the GUI
checks the lock before it offers recovery.

:class:`AutosaveWriter` writes autosaves in a thread of its own (a 58 MB project took 1.2 s to
serialize and write: not on the GUI thread). The GUI thread hands it an immutable snapshot
(:func:`~app.points.project_write.take_snapshot`, milliseconds); the writer turns it into the
file's bytes and writes them. One thread, one job at a time, and a job waiting is replaced by a
newer one: a newer autosave is never overwritten by an older one finishing later. ``flush``
waits (bounded) for what is pending: a close, a save or a discard first lets it land.
"""

from __future__ import annotations

import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from app.points.atomic import atomic_write_bytes
from app.points.project_model import Project
from app.points.project_write import ProjectSnapshot, project_bytes
from app.user_dirs import state_dir

AUTOSAVE_SUFFIX = ".autosave.json"


def default_autosave_dir() -> Path:
    """Per-user directory for autosaves of projects that were never saved (app.user_dirs)."""
    return state_dir() / "autosave"


def autosave_path(project_path: str | os.PathLike[str] | None, *, user_dir: Path | None = None) -> Path:
    """Where to autosave: ``demo.teachpad.json`` -> ``demo.teachpad.autosave.json`` next to
    it; an unsaved project goes to ``<user_dir>/untitled.autosave.json``."""
    if project_path is None:
        return (user_dir or default_autosave_dir()) / f"untitled{AUTOSAVE_SUFFIX}"
    p = Path(project_path)
    stem = p.name[: -len(".json")] if p.name.endswith(".json") else p.name
    return p.with_name(stem + AUTOSAVE_SUFFIX)


def save_autosave(
    project: Project | ProjectSnapshot,
    project_path: str | os.PathLike[str] | None,
    *,
    user_dir: Path | None = None,
) -> Path:
    """Write the autosave (atomically; ``modified`` untouched); returns its path.
    :class:`~app.points.project.ProjectTooLarge` (nothing written) when it could not be read back."""
    data = project_bytes(project)
    target = autosave_path(project_path, user_dir=user_dir)
    write_autosave_file(target, data)
    return target


def find_autosave(
    project_path: str | os.PathLike[str] | None, *, user_dir: Path | None = None
) -> Path | None:
    """The autosave to offer for recovery: it exists, differs from the project and is newer
    (or the project file is gone). None otherwise."""
    auto = autosave_path(project_path, user_dir=user_dir)
    try:
        auto_stat = auto.stat()
    except FileNotFoundError:
        return None
    if project_path is None:
        return auto
    project = Path(project_path)
    try:
        project_stat = project.stat()
    except FileNotFoundError:
        return auto
    if auto_stat.st_mtime_ns <= project_stat.st_mtime_ns:
        return None
    try:
        if auto.read_bytes() == project.read_bytes():
            return None
    except OSError:
        return auto
    return auto


def discard_autosave(project_path: str | os.PathLike[str] | None, *, user_dir: Path | None = None) -> bool:
    """Remove the autosave (after a save, or when the user declines recovery)."""
    try:
        autosave_path(project_path, user_dir=user_dir).unlink()
    except FileNotFoundError:
        return False
    return True


@dataclass(frozen=True)
class AutosaveJob:
    snapshot: ProjectSnapshot
    target: Path


@dataclass(frozen=True)
class AutosaveDone:
    """One autosave's end: written (``error`` None), or why not (an ``OSError``, or
    :class:`~app.points.project_write.ProjectTooLarge`: nothing written)."""

    target: Path
    revision: int
    error: Exception | None = None
    thread: str = ""  # the thread that wrote (tests check it is not the caller's)


def write_autosave_file(target: Path, data: bytes) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(target, data)


class AutosaveWriter:
    """Writes :class:`AutosaveJob` s in its own thread, in order, newest last (module docstring).

    ``on_done`` is called in the writer's thread after each job, before :meth:`flush` returns and
    never after :meth:`close` (hand it on to your own thread: the GUI emits a signal). ``write``
    writes the bytes (tests slow it down). The thread starts with the first job; :meth:`close`
    ends it."""

    def __init__(
        self,
        on_done: Callable[[AutosaveDone], None],
        *,
        write: Callable[[Path, bytes], None] = write_autosave_file,
        name: str = "autosave",
    ) -> None:
        self.on_done = on_done
        self.write = write
        self._name = name
        self._cond = threading.Condition()
        self._pending: AutosaveJob | None = None
        self._busy = False
        self._closing = False
        self._thread: threading.Thread | None = None
        self._report_lock = threading.Lock()
        self._muted = False  # after close(): on_done's receiver may be gone

    def submit(self, snapshot: ProjectSnapshot, target: Path) -> None:
        """Queue an autosave; one still waiting (not yet begun) is dropped for this newer one."""
        with self._cond:
            if self._closing:
                raise RuntimeError("the autosave writer is closed")
            self._pending = AutosaveJob(snapshot, target)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name=self._name, daemon=True)
                self._thread.start()
            self._cond.notify_all()

    @property
    def idle(self) -> bool:
        with self._cond:
            return self._pending is None and not self._busy

    def cancel(self) -> None:
        """Drop the job still waiting (the one being written goes on: see :meth:`flush`)."""
        with self._cond:
            self._pending = None
            self._cond.notify_all()

    def flush(self, timeout: float) -> bool:
        """Wait until everything submitted is written (or failed); False when ``timeout`` (s)
        passed first."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while self._pending is not None or self._busy:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(left)
            return True

    def close(self, timeout: float) -> bool:
        """:meth:`flush`, then end the thread; False when the write still under way did not end
        within ``timeout`` (the thread is a daemon: the process may still exit; the write being
        atomic, the autosave on disk is then the previous one, whole)."""
        done = self.flush(timeout)
        with self._report_lock:
            self._muted = True
        with self._cond:
            self._closing = True
            self._cond.notify_all()
            thread = self._thread
        if done and thread is not None:
            thread.join(timeout)
        return done

    def _run(self) -> None:
        while True:
            with self._cond:
                while self._pending is None and not self._closing:
                    self._cond.wait()
                job = self._pending
                if job is None:  # closing, nothing left
                    return
                self._pending, self._busy = None, True
            done = self._write_job(job)
            with self._report_lock:  # reported before flush() returns; never after close()
                if not self._muted:
                    try:
                        self.on_done(done)
                    except RuntimeError:  # its receiver is gone (a deleted Qt object): nobody to tell
                        self._muted = True
            with self._cond:
                self._busy = False
                self._cond.notify_all()

    def _write_job(self, job: AutosaveJob) -> AutosaveDone:
        revision, thread = job.snapshot.revision, threading.current_thread().name
        try:
            self.write(job.target, project_bytes(job.snapshot))
        except Exception as exc:  # OSError, ProjectTooLarge: reported to the operator by on_done
            return AutosaveDone(job.target, revision, exc, thread)
        return AutosaveDone(job.target, revision, None, thread)

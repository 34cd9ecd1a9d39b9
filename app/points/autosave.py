"""Autosave next to the project, and recovery after a crash.

``demo.teachpad.json`` autosaves to ``demo.teachpad.autosave.json`` beside it (atomically, same
format); a project never saved goes to a per-user directory. :func:`find_autosave` offers an
autosave for recovery when it is newer than the project and differs from it. A live autosave
of another running TeachPad (see :mod:`app.points.lock`) is not a crash leftover: the GUI
checks the lock before it offers recovery.
"""

from __future__ import annotations

import os
from pathlib import Path

from app.points.atomic import atomic_write_bytes
from app.points.project import Project, project_bytes
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
    project: Project, project_path: str | os.PathLike[str] | None, *, user_dir: Path | None = None
) -> Path:
    """Write the autosave (atomically; ``modified`` untouched); returns its path.
    :class:`~app.points.project.ProjectTooLarge` (nothing written) when it could not be read back."""
    data = project_bytes(project)
    target = autosave_path(project_path, user_dir=user_dir)
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(target, data)
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

"""One TeachPad per project: a lock file next to the project.

``demo.teachpad.json`` is locked by ``demo.teachpad.json.lock``, a small JSON file with the
owner's pid, host name and start time, created with ``O_EXCL`` (so two instances cannot both
take it). A lock is *stale*, and is taken over, when it names this host and a pid that is no
longer running, or when it is unreadable (a kill while it was being written). A lock of
another host cannot be checked and is always respected: its owner must close the project, or
the operator removes the file by hand. The same process may take the same lock again.

A second instance that finds a live lock must not offer to recover the first one's autosave
(that autosave is the first instance's work in progress, not a crash leftover).
"""

from __future__ import annotations

import contextlib
import datetime as dt
import json
import os
import socket
import sys
from dataclasses import dataclass
from pathlib import Path

from app.errors import InvalidInput

LOCK_SUFFIX = ".lock"
_LOCK_MAX_BYTES = 4096


def lock_path(project_path: str | os.PathLike[str]) -> Path:
    p = Path(project_path)
    return p.with_name(p.name + LOCK_SUFFIX)


@dataclass(frozen=True)
class LockOwner:
    pid: int
    host: str
    started: str  # ISO time the owner took the lock

    @property
    def text(self) -> str:
        host = self.host or "an unknown host"
        return f"process {self.pid} on {host}, since {self.started or 'an unknown time'}"

    @property
    def is_this_process(self) -> bool:
        return self.pid == os.getpid() and self.host == _host()


class ProjectLocked(InvalidInput):
    """Another running TeachPad has the project open."""

    def __init__(self, project: Path, owner: LockOwner) -> None:
        self.project = project
        self.owner = owner
        super().__init__(
            f"{project}: the project is open in another TeachPad ({owner.text}); "
            f"close it there first (or remove {lock_path(project).name} if that TeachPad "
            "is gone)"
        )


def _host() -> str:
    return socket.gethostname()


def _pid_alive(pid: int) -> bool:
    if pid <= 0:
        return False
    if sys.platform == "win32":  # pragma: no cover - no os.kill(pid, 0) probe there
        import ctypes

        handle = ctypes.windll.kernel32.OpenProcess(0x1000, False, pid)
        if not handle:
            return False
        ctypes.windll.kernel32.CloseHandle(handle)
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # someone else's live process
    except OSError:
        return False
    return True


def _read_owner(path: Path) -> LockOwner | None:
    """The owner named by the lock file; None if it is missing or unreadable."""
    try:
        with path.open("rb") as f:
            raw = f.read(_LOCK_MAX_BYTES)
        data = json.loads(raw.decode("utf-8"))
        pid, host, started = data["pid"], data["host"], data.get("started", "")
        if (
            not isinstance(pid, int)
            or isinstance(pid, bool)
            or not isinstance(host, str)
            or not isinstance(started, str)
        ):
            return None
        return LockOwner(pid, host[:200], started[:40])
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _is_stale(owner: LockOwner | None) -> bool:
    if owner is None:
        return True
    return owner.host == _host() and not _pid_alive(owner.pid)


def live_owner(project_path: str | os.PathLike[str]) -> LockOwner | None:
    """Another live instance holding the project's lock; None when free, stale or ours."""
    path = lock_path(project_path)
    if not path.exists():
        return None
    owner = _read_owner(path)
    if owner is None or _is_stale(owner) or owner.is_this_process:
        return None
    return owner


class ProjectLock:
    """The lock of one project file, held by this process until :meth:`release`."""

    def __init__(self, project_path: str | os.PathLike[str]) -> None:
        self.project = Path(project_path)
        self.path = lock_path(self.project)
        self.held = False

    @classmethod
    def acquire(cls, project_path: str | os.PathLike[str]) -> ProjectLock:
        """Take the lock; :class:`ProjectLocked` when another live instance holds it.
        An ``OSError`` (e.g. a read-only directory) passes through: the caller decides."""
        lock = cls(project_path)
        lock._take()
        return lock

    def _take(self) -> None:
        me = LockOwner(
            os.getpid(),
            _host(),
            dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z"),
        )
        payload = json.dumps({"pid": me.pid, "host": me.host, "started": me.started, "app": "teachpad"})
        for _attempt in range(3):
            try:
                fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
            except FileExistsError:
                owner = _read_owner(self.path)
                if owner is not None and owner.is_this_process:
                    self.held = True
                    return
                if not _is_stale(owner):
                    assert owner is not None
                    raise ProjectLocked(self.project, owner) from None
                with contextlib.suppress(FileNotFoundError):
                    self.path.unlink()
                continue
            try:
                os.write(fd, payload.encode("utf-8"))
            finally:
                os.close(fd)
            self.held = True
            return
        owner = _read_owner(self.path)
        raise ProjectLocked(self.project, owner or LockOwner(0, "", ""))

    def release(self) -> None:
        """Remove the lock file if it is still ours."""
        if not self.held:
            return
        self.held = False
        owner = _read_owner(self.path)
        if owner is not None and owner.is_this_process:
            with contextlib.suppress(OSError):
                self.path.unlink()

    def __enter__(self) -> ProjectLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

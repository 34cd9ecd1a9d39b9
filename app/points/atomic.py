"""Atomic file replacement, and reading files with a size limit.

:func:`atomic_write_bytes` writes a temp file in the target's directory, fsyncs it and
``os.replace``-s it over the target, so a crash (even ``kill -9``) leaves either the old file or
the new one, never a mix. What a kill can leave is the temp file itself; its name is
recognisably ours (:data:`TEMP_PREFIX` + target name + a random part + :data:`TEMP_SUFFIX`), and
the next save of the same target removes such leftovers when they are older than
:data:`STALE_TEMP_AGE` seconds (a younger one may belong to a save under way in another
process; the instance lock of :mod:`app.points.lock` keeps that rare).
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import stat
import sys
import time
from pathlib import Path
from typing import Any

from app.errors import Reason, TeachPadError
from app.points.point import FileFormatError

TEMP_PREFIX = ".teachpad-tmp."
TEMP_SUFFIX = ".tmp"
#: A temp file of ours older than this (s) is a leftover of a killed save; tests may shrink it.
STALE_TEMP_AGE = 60.0
MAX_FILE_BYTES = 64 * 1024 * 1024  # refuse absurd files before reading them

_RANDOM = re.compile(r"[0-9a-f]{12}")


def temp_name(target: Path) -> Path:
    """A fresh temp file name for a save of ``target``."""
    return target.with_name(f"{TEMP_PREFIX}{target.name}.{os.urandom(6).hex()}{TEMP_SUFFIX}")


def stale_temp_files(target: str | os.PathLike[str], *, min_age: float | None = None) -> list[Path]:
    """Temp files a save of ``target`` left behind (exactly our pattern, older than ``min_age``)."""
    path = Path(target)
    age = STALE_TEMP_AGE if min_age is None else min_age
    head = f"{TEMP_PREFIX}{path.name}."
    found: list[Path] = []
    now = time.time()
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return []
    for entry in entries:
        name = entry.name
        if not (name.startswith(head) and name.endswith(TEMP_SUFFIX)):
            continue
        if not _RANDOM.fullmatch(name[len(head) : -len(TEMP_SUFFIX)]):
            continue
        try:
            if not entry.is_file(follow_symlinks=False) or now - entry.stat().st_mtime < age:
                continue
        except OSError:
            continue
        found.append(Path(entry.path))
    return found


def clean_stale_temp_files(target: str | os.PathLike[str], *, min_age: float | None = None) -> int:
    """Remove what :func:`stale_temp_files` finds; returns how many went."""
    removed = 0
    for leftover in stale_temp_files(target, min_age=min_age):
        with contextlib.suppress(OSError):
            leftover.unlink()
            removed += 1
    return removed


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes, *, mode: int | None = None) -> None:
    """Replace ``path`` with ``data`` so that a crash leaves the old file or the new, never a mix.

    Temp file in the same directory (same filesystem), written in full, fsynced, then
    ``os.replace``; the directory is fsynced afterwards where the OS allows it. On any error
    the temp file is removed and the old file is untouched. Keeps an existing file's mode, unless
    ``mode`` is given (e.g. ``0o600`` for a file with secrets): then the file has that mode from
    its creation on, before a byte is written (never readable by others, not even for a moment).
    Removes stale temp files of earlier, killed saves of the same target first.
    """
    target = Path(path)
    directory = target.parent
    clean_stale_temp_files(target)
    tmp = temp_name(target)
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    fd = os.open(tmp, flags, 0o666 if mode is None else mode)
    try:
        try:
            if mode is not None and hasattr(os, "fchmod"):
                os.fchmod(fd, mode)  # exactly this mode, whatever the umask
            view = memoryview(data)
            while view:
                written = os.write(fd, view)
                view = view[written:]
            os.fsync(fd)
        finally:
            os.close(fd)
        if mode is None:
            with contextlib.suppress(FileNotFoundError):
                os.chmod(tmp, stat.S_IMODE(os.stat(target).st_mode))
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(directory)


def _fsync_dir(directory: Path) -> None:
    # Makes the rename itself durable. Not possible on Windows, and some filesystems refuse
    # it; the data is already safe either way, so a refusal is not an error.
    if sys.platform == "win32":
        return
    with contextlib.suppress(OSError):
        dfd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


def read_limited(path: Path, limit: int | None = None) -> bytes:
    """The file's bytes; :class:`FileFormatError` for a missing, too large or unreadable file
    (``limit``: :data:`MAX_FILE_BYTES` as it is now)."""
    limit = MAX_FILE_BYTES if limit is None else limit
    try:
        size = path.stat().st_size
        if size > limit:
            raise FileFormatError(
                f"the file is too large ({size} bytes, at most {limit})",
                path=str(path),
                problem=Reason("file_too_large", {"size": size, "limit": limit}),
            )
        return path.read_bytes()
    except FileNotFoundError:
        raise FileFormatError(
            "the file does not exist", path=str(path), problem=Reason("no_such_file")
        ) from None
    except IsADirectoryError:
        raise FileFormatError(
            "is a directory, not a file", path=str(path), problem=Reason("is_a_directory")
        ) from None
    except PermissionError:
        raise FileFormatError(
            "cannot be read (permission denied)", path=str(path), problem=Reason("permission_denied")
        ) from None


def versioned_document(
    text: str, source: str, *, fmt: str, version: int, what: str, error: type[Exception]
) -> dict[str, Any]:
    """A settings file's JSON object, checked for its ``format`` name and a ``version`` this TeachPad
    reads; ``error`` naming ``source`` otherwise (``what``: "safety profile", "register profile")."""
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        where = {"what": what, "line": exc.lineno, "column": exc.colno}
        raise _coded(
            error, f"{source} is not valid JSON (line {exc.lineno}: {exc.msg})", "settings_not_json", where
        ) from None
    if not isinstance(doc, dict) or doc.get("format") != fmt:
        raise error(f"{source} is not a TeachPad {what}")
    found = doc.get("version")
    if not isinstance(found, int) or isinstance(found, bool):
        raise error(f"{source}: the format version is missing")
    if found > version:
        raise error(
            f"{source} was written by a newer TeachPad (format {found}; this one reads up to {version})"
        )
    return doc


def read_settings_text(path: Path, limit: int, what: str, error: type[Exception]) -> str:
    """A small settings file (a profile) as text: ``error`` naming ``what`` and the file when it is
    missing, too large, unreadable or not UTF-8."""
    try:
        data = read_limited(path, limit)
    except FileFormatError as exc:
        cause = exc.problem if exc.problem is not None else Reason("os_error")
        params = {"what": what, "file": path.name, "cause": cause.code, **cause.args}
        raise _coded(error, f"{what}: {exc}", "settings_unreadable", params) from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        params = {"what": what, "file": path.name}
        raise _coded(error, f"{what} {path.name} is not UTF-8 text", "settings_not_utf8", params) from None


def _coded(error: type[Exception], message: str, code: str, params: dict[str, Any]) -> Exception:
    """``error`` with ``message``, and with its code and arguments when it is a typed error (the
    GUI words it: ui/messages_profile.py; the English stays the message)."""
    if issubclass(error, TeachPadError):
        return error(message, code=code, params=params)
    return error(message)

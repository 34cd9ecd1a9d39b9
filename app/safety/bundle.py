"""The support bundle: one zip an operator sends to an integrator.

Contents (each only when given): ``versions.json`` (Python, the platform, TeachPad, pymodbus,
PySide6 and pyqtgraph when installed, numpy), ``settings.json`` (passwords, hashes, salts,
secrets and tokens removed: see :func:`redact`), ``project/<file>``, ``safety-profile.json``,
``register-profile.json`` (word order, unit id, completion rule... in force), ``audit/`` (the
audit files of the last ``days`` days), ``events.txt`` (the event log's lines),
``logs/`` (files of a log directory changed in the last ``days`` days), ``traffic.txt`` (recent
Modbus traffic), and ``manifest.json`` listing what is inside and what was left out, and why.

The role store (password hashes) is never included, whatever is passed. The zip is written
atomically (:func:`app.points.atomic.atomic_write_bytes`).
"""

from __future__ import annotations

import datetime as dt
import importlib.metadata
import io
import json
import os
import platform
import re
import sys
import zipfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import app
from app.errors import InvalidInput
from app.points.atomic import atomic_write_bytes
from app.safety.audit import audit_files
from app.safety.roles import STORE_FORMAT

DEFAULT_DAYS = 7
MAX_FILE_BYTES = 64 * 1024 * 1024  # a single file larger than this is left out (and said so)
_SECRET_KEY = re.compile(r"pass(word)?|pwd|hash|salt|secret|token|credential|api[_-]?key", re.IGNORECASE)
REMOVED = "<removed>"
_DISTRIBUTIONS = ("pymodbus", "PySide6-Essentials", "PySide6", "pyqtgraph", "numpy", "pyserial")


@dataclass
class BundleManifest:
    created: str
    files: list[str] = field(default_factory=list)
    left_out: list[str] = field(default_factory=list)  # "what: why"


def versions() -> dict[str, str]:
    """Versions of everything a bug report needs; packages found by their metadata (not imported)."""
    out = {
        "teachpad": app.__version__,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "machine": platform.machine(),
    }
    for dist in _DISTRIBUTIONS:
        try:
            out[dist] = importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
    return out


def redact(value: Any) -> Any:
    """A copy of a settings tree without anything that may be a secret (by key name)."""
    if isinstance(value, Mapping):
        return {str(k): (REMOVED if _SECRET_KEY.search(str(k)) else redact(v)) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [redact(v) for v in value]
    return value


def _is_role_store(data: bytes) -> bool:
    return STORE_FORMAT.encode() in data[:4096]


class _Writer:
    def __init__(self, zf: zipfile.ZipFile, manifest: BundleManifest) -> None:
        self.zf = zf
        self.manifest = manifest

    def text(self, name: str, text: str) -> None:
        self.zf.writestr(name, text.encode("utf-8"))
        self.manifest.files.append(name)

    def file(self, name: str, path: Path) -> None:
        try:
            size = path.stat().st_size
            if size > MAX_FILE_BYTES:
                self.manifest.left_out.append(f"{path.name}: too large ({size} bytes)")
                return
            data = path.read_bytes()
        except OSError as exc:
            self.manifest.left_out.append(f"{path.name}: cannot be read ({exc.strerror or exc})")
            return
        if _is_role_store(data):
            self.manifest.left_out.append(f"{path.name}: the role store (password hashes) is never included")
            return
        self.zf.writestr(name, data)
        self.manifest.files.append(name)


def build_support_bundle(
    *,
    settings: Mapping[str, Any] | None = None,
    project: Path | None = None,
    profile: Path | None = None,
    register_profile: Path | None = None,
    audit_dir: Path | None = None,
    events: Iterable[str] | None = None,
    log_dir: Path | None = None,
    traffic: Iterable[str] | None = None,
    days: int = DEFAULT_DAYS,
    now: dt.datetime | None = None,
) -> tuple[bytes, BundleManifest]:
    """The zip's bytes and its manifest."""
    if days < 1:
        raise InvalidInput("days must be at least 1")
    now = now or dt.datetime.now().astimezone()
    manifest = BundleManifest(now.isoformat(timespec="seconds"))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        w = _Writer(zf, manifest)
        w.text("versions.json", json.dumps(versions(), indent=2) + "\n")
        if settings is not None:
            text = json.dumps(redact(settings), indent=2, ensure_ascii=False, default=str)
            w.text("settings.json", text + "\n")
        if project is not None:
            w.file(f"project/{project.name}", project)
        if profile is not None:
            w.file("safety-profile.json", profile)
        if register_profile is not None:
            w.file("register-profile.json", register_profile)
        first_day = now.date() - dt.timedelta(days=days - 1)
        if audit_dir is not None:
            found = audit_files(audit_dir, first_day, now.date())
            for path in found:
                w.file(f"audit/{path.name}", path)
            if not found:
                manifest.left_out.append(f"audit trail: no records in the last {days} days")
        if events is not None:
            w.text("events.txt", "".join(line.rstrip("\n") + "\n" for line in events))
        if log_dir is not None:
            cutoff = (now - dt.timedelta(days=days)).timestamp()
            for path in sorted(p for p in log_dir.iterdir() if p.is_file()) if log_dir.is_dir() else []:
                if path.stat().st_mtime >= cutoff:
                    w.file(f"logs/{path.name}", path)
        if traffic is not None:
            w.text("traffic.txt", "".join(line.rstrip("\n") + "\n" for line in traffic))
        manifest.files.append("manifest.json")
        zf.writestr(
            "manifest.json",
            json.dumps(
                {
                    "created": manifest.created,
                    "days": days,
                    "files": manifest.files,
                    "left_out": manifest.left_out,
                },
                indent=2,
                ensure_ascii=False,
            )
            + "\n",
        )
    return buf.getvalue(), manifest


def write_support_bundle(out: str | os.PathLike[str], **kwargs: Any) -> BundleManifest:
    """Write the bundle to ``out`` atomically (arguments as :func:`build_support_bundle`)."""
    data, manifest = build_support_bundle(**kwargs)
    target = Path(out)
    if target.parent and not target.parent.is_dir():
        raise InvalidInput(f"the folder {str(target.parent)[:60]} does not exist")
    atomic_write_bytes(target, data)
    return manifest

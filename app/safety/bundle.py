"""The support bundle: one zip an operator sends to an integrator.

Contents (each only when given): ``versions.json`` (Python, the platform, TeachPad, pymodbus,
PySide6 and pyqtgraph when installed, numpy), ``settings.json`` (passwords, hashes, salts,
secrets and tokens removed by key name and by value: see :func:`redact`), ``project/<file>``,
``safety-profile.json``,
``register-profile.json`` (word order, unit id, completion rule... in force), ``audit/`` (the
audit files of the last ``days`` days), ``events.txt`` (the event log's lines),
``logs/`` (files of a log directory changed in the last ``days`` days), ``traffic.txt`` (recent
Modbus traffic), ``stopping.txt`` (measured stopping of the session: :mod:`app.safety.stopping`),
and ``manifest.json`` listing what is inside and what was left out, and why.

The role store (password hashes) is never included, whatever is passed. Logs, events and traffic
are redacted by value too (:func:`redact_text`); the audit files and the project go as they are
(the audit's chain of hashes must stay checkable). The zip is written atomically
(:func:`app.points.atomic.atomic_write_bytes`), owner-only (0600) from its creation on.
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
from app.safety.audit_read import audit_files
from app.safety.roles import STORE_FORMAT

DEFAULT_DAYS = 7
_NO_EVENTS = "event log: none given"
_NO_TRAFFIC = "Modbus traffic: none given (TeachPad records it; teachpad-cli takes a file with --traffic)"
_TRAFFIC_EMPTY = "Modbus traffic: no frames recorded (no connection to a controller since TeachPad started)"
_NO_STOPPING = "measured stopping: nothing measured in this session"
MAX_FILE_BYTES = 64 * 1024 * 1024  # a single file larger than this is left out (and said so)
_SECRET_WORDS = (
    r"pass(?:word|wd|phrase)?|pwd|hash|salt|secret|token|credential|api[_-]?key|private[_-]?key"
    r"|auth(?!ors?(?![a-z]))|cookie|licen[cs]e|session[_-]?id|(?<![a-z])pin(?:code)?(?![a-z])"
)
_SECRET_KEY = re.compile(_SECRET_WORDS, re.IGNORECASE)
REMOVED = "<removed>"
# Secrets found by their value, wherever they are (settings values, log lines, events, traffic):
_VALUE_PATTERNS = (
    # user:password@ of a URL (http://user:pw@host, mqtt://token@host ...)
    (re.compile(r"\b([a-z][a-z0-9+.-]*://)[^/\s@\"']+@", re.IGNORECASE), rf"\1{REMOVED}@"),
    # a PEM private key, whole
    (
        re.compile(r"-----BEGIN [A-Z ]*PRIVATE KEY-----.*?(?:-----END [A-Z ]*PRIVATE KEY-----|$)", re.DOTALL),
        REMOVED,
    ),
    # the credentials of an HTTP Authorization header
    (re.compile(r"\b(Bearer|Basic|Digest|Token)\s+[A-Za-z0-9._~+/=-]{6,}", re.IGNORECASE), rf"\1 {REMOVED}"),
    # a Cookie / Set-Cookie header: all of its line
    (re.compile(r"\b((?:set-)?cookie\s*:\s*)[^\r\n]+", re.IGNORECASE), rf"\1{REMOVED}"),
    # key=value, key: value, "key": "value" with a key named like a secret
    (
        re.compile(
            rf"""(?P<key>[\w.-]*(?:{_SECRET_WORDS})[\w.-]*["']?\s*[:=]\s*["']?)(?P<value>[^\s"',;&]+)""",
            re.IGNORECASE,
        ),
        rf"\g<key>{REMOVED}",
    ),
)
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
    """A copy of a settings tree without anything that may be a secret: by key name (passwords,
    tokens, keys, auth, PINs, licences, cookies ...) and by value (:func:`redact_text`)."""
    if isinstance(value, Mapping):
        return {str(k): (REMOVED if _SECRET_KEY.search(str(k)) else redact(v)) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [redact(v) for v in value]
    if isinstance(value, str):
        return redact_text(value)
    return value


def redact_text(text: str) -> str:
    """``text`` without the secrets found by their value: a URL's credentials, a private key, an
    Authorization header's credentials, ``key=value`` where the key is named like a secret."""
    for pattern, replacement in _VALUE_PATTERNS:
        text = pattern.sub(replacement, text)
    return text


def _is_role_store(data: bytes) -> bool:
    return STORE_FORMAT.encode() in data[:4096]


class _Writer:
    def __init__(self, zf: zipfile.ZipFile, manifest: BundleManifest) -> None:
        self.zf = zf
        self.manifest = manifest

    def text(self, name: str, text: str) -> None:
        self.zf.writestr(name, redact_text(text).encode("utf-8"))
        self.manifest.files.append(name)

    def file(self, name: str, path: Path, *, redacted: bool = False) -> None:
        """``path`` as it is (``redacted``: a text file, secrets removed by value: logs)."""
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
        if redacted:
            data = redact_text(data.decode("utf-8", errors="replace")).encode("utf-8")
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
    stopping: Iterable[str] | None = None,
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
        _add_settings(w, settings)
        _add_inputs(w, project, profile, register_profile)
        _add_audit(w, audit_dir, now.date(), days)
        _add_lines(w, "events.txt", events, _NO_EVENTS, f"event log: no events in the last {days} days")
        _add_logs(w, log_dir, (now - dt.timedelta(days=days)).timestamp())
        _add_lines(w, "traffic.txt", traffic, _NO_TRAFFIC, _TRAFFIC_EMPTY)
        if stopping is not None:  # the GUI's session (teachpad-cli has none to give)
            _add_lines(w, "stopping.txt", stopping, _NO_STOPPING, _NO_STOPPING)
        manifest.files.append("manifest.json")
        zf.writestr("manifest.json", _manifest_json(manifest, days))
    return buf.getvalue(), manifest


def _add_settings(w: _Writer, settings: Mapping[str, Any] | None) -> None:
    """The settings, every secret removed."""
    if settings is not None:
        text = json.dumps(redact(settings), indent=2, ensure_ascii=False, default=str)
        w.text("settings.json", text + "\n")


def _add_inputs(
    w: _Writer, project: Path | None, profile: Path | None, register_profile: Path | None
) -> None:
    """The files the operator works with: the project, the safety profile, the register profile."""
    if project is not None:
        w.file(f"project/{project.name}", project)
    for name, path in (("safety-profile.json", profile), ("register-profile.json", register_profile)):
        if path is not None:
            w.file(name, path)


def _add_audit(w: _Writer, audit_dir: Path | None, last_day: dt.date, days: int) -> None:
    """The audit trail's day files of the last ``days`` days (said when there are none)."""
    if audit_dir is None:
        return
    found = audit_files(audit_dir, last_day - dt.timedelta(days=days - 1), last_day)
    for path in found:
        w.file(f"audit/{path.name}", path)
    if not found:
        w.manifest.left_out.append(f"audit trail: no records in the last {days} days")


def _add_lines(w: _Writer, name: str, lines: Iterable[str] | None, none_given: str, empty: str) -> None:
    """A text of lines (the event log, the Modbus traffic); the manifest says why it is missing:
    ``none_given`` when there was none to give, ``empty`` when it had no lines."""
    given = None if lines is None else list(lines)
    if given:
        w.text(name, "".join(line.rstrip("\n") + "\n" for line in given))
    else:
        w.manifest.left_out.append(none_given if given is None else empty)


def _add_logs(w: _Writer, log_dir: Path | None, cutoff: float) -> None:
    """The log files changed since ``cutoff`` (a timestamp), secrets removed."""
    if log_dir is None:
        return
    for path in sorted(p for p in log_dir.iterdir() if p.is_file()) if log_dir.is_dir() else []:
        if path.stat().st_mtime >= cutoff:
            w.file(f"logs/{path.name}", path, redacted=True)


def _manifest_json(manifest: BundleManifest, days: int) -> str:
    document = {
        "created": manifest.created,
        "days": days,
        "files": manifest.files,
        "left_out": manifest.left_out,
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def write_support_bundle(out: str | os.PathLike[str], **kwargs: Any) -> BundleManifest:
    """Write the bundle to ``out`` atomically (arguments as :func:`build_support_bundle`)."""
    data, manifest = build_support_bundle(**kwargs)
    target = Path(out)
    if target.parent and not target.parent.is_dir():
        raise InvalidInput(f"the folder {str(target.parent)[:60]} does not exist")
    atomic_write_bytes(target, data, mode=0o600)  # owner-only: it holds the site's settings and logs
    return manifest

"""The project file: points, plans and a little metadata, saved atomically as JSON.

Format (version 1; docs/PROJECT_FORMAT.md is the reference)::

    {
      "format": "teachpad-project",
      "version": 1,
      "name": "demo",
      "description": "",
      "created": "2025-01-31T08:00:00Z",
      "modified": "2025-01-31T09:30:00Z",
      "points": [
        {"id": 1, "name": "原点", "x": 400.0, "y": 0.0, "z": 400.0, "a": 180.0, "b": 0.0, "c": 0.0,
         "e1": 0.0, "e2": 0.0, "e3": 0.0, "e4": 0.0, "e5": 0.0, "tool": 200, "note": "",
         "sync": "unknown", "sync_error": ""}
      ],
      "plans": [
        {"name": "square", "loops": 1, "segments": [
          {"type": "line", "end": 2, "speed": 100.0, "orientation": "changes",
           "ignore_middle": false, "tool": 200},
          {"type": "arc", "via": 3, "end": 4, "speed": 50.0, "orientation": "kept",
           "ignore_middle": false, "tool": 200}
        ]}
      ]
    }

A point's keys are the CSV columns plus ``sync`` (``unknown`` / ``on-controller`` /
``changed`` / ``failed``) and ``sync_error``. Unknown keys are ignored; a different
``format`` or ``version`` is refused. Loading parses and validates everything before it
returns, so a bad file never half-replaces what the caller holds; errors are
:class:`~app.points.ledger.FileFormatError` naming the item and field
(``points[6] (id 12), field 'x': 'abc' is not a number``).

Saving writes a temp file in the same directory, fsyncs it and ``os.replace``-s it over the
target, so a crash leaves either the old file or the new one. The GUI autosaves next to the
project (:func:`autosave_path`) and offers recovery when :func:`find_autosave` sees an
autosave newer than the project.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import json
import os
import stat
import sys
import uuid
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from app.errors import InvalidInput
from app.plan.segments import (
    Plan,
    Segment,
    SegmentKind,
    parse_kind,
    parse_orientation,
    validate_loops,
    validate_plan_name,
)
from app.points.ledger import (
    DEFAULT_LIMITS,
    EXT_FIELDS,
    POSE_FIELDS,
    FieldError,
    FileFormatError,
    PointLedger,
    PointLimits,
    SyncState,
    TempPoint,
    decode_text,
    parse_points_csv,
    point_from_fields,
    points_to_csv,
)

FORMAT_NAME = "teachpad-project"
FORMAT_VERSION = 1
PROJECT_SUFFIX = ".teachpad.json"
AUTOSAVE_SUFFIX = ".autosave.json"
MAX_FILE_BYTES = 64 * 1024 * 1024  # refuse absurd files before parsing them

__all__ = [
    "FORMAT_NAME", "FORMAT_VERSION", "FileFormatError", "Project", "atomic_write_bytes",
    "autosave_path", "default_autosave_dir", "discard_autosave", "find_autosave", "load_project",
    "parse_project", "project_from_dict", "project_to_dict", "read_points_csv", "save_autosave",
    "save_project", "write_points_csv",
]


def _now_iso() -> str:
    return dt.datetime.now(dt.UTC).replace(microsecond=0).isoformat().replace("+00:00", "Z")


@dataclass(eq=False)
class Project:
    """Points, plans and metadata. Plan names are unique (compared after stripping)."""

    name: str = "untitled"
    ledger: PointLedger = field(default_factory=PointLedger)
    plans: list[Plan] = field(default_factory=list)
    description: str = ""
    created: str = field(default_factory=_now_iso)
    modified: str = ""
    _revision: int = field(default=0, init=False, repr=False)

    def __post_init__(self) -> None:
        names = [p.name for p in self.plans]
        for name in names:
            if names.count(name) > 1:
                raise InvalidInput(f"two plans are named {name!r}")

    @property
    def revision(self) -> int:
        """Changes whenever the project, its ledger or a plan changes (dirty tracking)."""
        return self._revision + self.ledger.revision + sum(p.revision for p in self.plans)

    def touch(self) -> None:
        """Count a metadata change."""
        self._revision += 1

    # --- plans
    def plan_names(self) -> list[str]:
        return [p.name for p in self.plans]

    def plan(self, name: str) -> Plan:
        for p in self.plans:
            if p.name == name.strip():
                return p
        raise InvalidInput(f"no plan named {name!r} (plans: {', '.join(self.plan_names()) or 'none'})")

    def add_plan(self, plan: Plan, row: int | None = None) -> int:
        if plan.name in self.plan_names():
            raise InvalidInput(f"a plan named {plan.name!r} already exists")
        row = len(self.plans) if row is None else max(0, min(row, len(self.plans)))
        self.plans.insert(row, plan)
        self._revision += 1
        return row

    def remove_plan(self, row: int) -> Plan:
        plan = self.plans.pop(row)
        self._revision += 1
        return plan

    def rename_plan(self, row: int, name: str) -> str:
        new = validate_plan_name(name)
        if any(p.name == new for i, p in enumerate(self.plans) if i != row):
            raise InvalidInput(f"a plan named {new!r} already exists")
        return self.plans[row].rename(new)

    def unique_plan_name(self, base: str = "plan") -> str:
        names = set(self.plan_names())
        if base not in names:
            return base
        k = 2
        while f"{base} {k}" in names:
            k += 1
        return f"{base} {k}"

    # --- cross references
    def references(self, point_id: int) -> list[tuple[str, int]]:
        """``(plan name, segment index)`` of every segment that uses ``point_id``."""
        return [
            (p.name, i) for p in self.plans for i, seg in enumerate(p.segments) if point_id in seg.point_ids
        ]

    def renumber_point(self, row: int, new_id: int) -> list[tuple[str, list[int]]]:
        """Change a point's id and follow it in every plan; returns ``(plan, rows)`` changed."""
        old_id = self.ledger[row].id
        self.ledger.set_field(row, "id", new_id)
        changed: list[tuple[str, list[int]]] = []
        for p in self.plans:
            rows = p.replace_point_id(old_id, new_id)
            if rows:
                changed.append((p.name, rows))
        return changed


# --- JSON ------------------------------------------------------------------------------------


def _point_to_dict(p: TempPoint) -> dict[str, Any]:
    d: dict[str, Any] = {"id": p.id, "name": p.name}
    d.update(zip(POSE_FIELDS, p.xyzabc, strict=True))
    d.update(zip(EXT_FIELDS, p.ext, strict=True))
    d.update({"tool": p.tool, "note": p.note, "sync": p.sync.value, "sync_error": p.sync_error})
    return d


def _segment_to_dict(s: Segment) -> dict[str, Any]:
    d: dict[str, Any] = {"type": s.kind.value}
    if s.is_arc:
        d["via"] = s.via_id
    d.update({"end": s.end_id, "speed": s.speed, "orientation": s.orientation,
              "ignore_middle": s.ignore_middle, "tool": s.tool})
    return d


def project_to_dict(project: Project) -> dict[str, Any]:
    return {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "name": project.name,
        "description": project.description,
        "created": project.created,
        "modified": project.modified,
        "points": [_point_to_dict(p) for p in project.ledger],
        "plans": [
            {"name": p.name, "loops": p.loops, "segments": [_segment_to_dict(s) for s in p.segments]}
            for p in project.plans
        ],
    }


def _dumps(value: object) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False)


def _json_list(items: list[str], indent: str) -> str:
    if not items:
        return "[]"
    return "[\n" + ",\n".join(indent + "  " + item for item in items) + "\n" + indent + "]"


def project_to_json(project: Project) -> str:
    """The file's text: plain JSON laid out one point and one segment per line (readable,
    and a changed point is a one-line diff)."""
    doc = project_to_dict(project)
    lines = [f"  {_dumps(k)}: {_dumps(v)}" for k, v in doc.items() if k not in ("points", "plans")]
    lines.append(f'  "points": {_json_list([_dumps(p) for p in doc["points"]], "  ")}')
    plans = []
    for plan in doc["plans"]:
        head = ", ".join(f"{_dumps(k)}: {_dumps(v)}" for k, v in plan.items() if k != "segments")
        segments = _json_list([_dumps(s) for s in plan["segments"]], "    ")
        plans.append(f'{{{head}, "segments": {segments}}}')
    lines.append(f'  "plans": {_json_list(plans, "  ")}')
    return "{\n" + ",\n".join(lines) + "\n}\n"


def _expect(value: object, kind: type | tuple[type, ...], where: str, name: str, what: str) -> Any:
    if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
        raise FileFormatError(f"expected {what}, got {json.dumps(value, ensure_ascii=False)[:40]}",
                              where=where, column=name or None)
    return value


def _text_field(obj: Mapping[str, Any], key: str, where: str) -> str:
    value = obj.get(key, "")
    return str(_expect("" if value is None else value, str, where, key, "text"))


def project_from_dict(
    data: object, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None
) -> Project:
    """Validate a decoded JSON document fully and build the project."""
    try:
        return _project_from_dict(data, limits)
    except FileFormatError as exc:
        raise exc.with_path(path) if path else exc from None


def _project_from_dict(data: object, limits: PointLimits) -> Project:
    top = "the file"
    if not isinstance(data, dict):
        raise FileFormatError("expected a JSON object at the top level")
    doc: dict[str, Any] = data
    if doc.get("format") != FORMAT_NAME:
        raise FileFormatError(f"expected {FORMAT_NAME!r}, got {doc.get('format')!r}: not a TeachPad project",
                              where=top, column="format")
    version = doc.get("version")
    if version != FORMAT_VERSION or isinstance(version, bool):
        raise FileFormatError(
            f"version {version!r} is not supported (this TeachPad reads version {FORMAT_VERSION})",
            where=top, column="version",
        )
    name = _text_field(doc, "name", top) or "untitled"
    description = _text_field(doc, "description", top)
    created = _text_field(doc, "created", top)
    modified = _text_field(doc, "modified", top)

    raw_points = _expect(doc.get("points", []), list, top, "points", "a list of points")
    points: list[TempPoint] = []
    seen: dict[int, int] = {}
    for i, raw in enumerate(raw_points):
        where = f"points[{i}]"
        obj = _expect(raw, dict, where, "", "an object")
        if isinstance(obj.get("id"), int | float | str) and not isinstance(obj.get("id"), bool):
            where = f"points[{i}] (id {obj['id']})"
        try:
            state_text = obj.get("sync", SyncState.UNKNOWN.value)
            try:
                state = SyncState.parse(str(state_text))
            except ValueError as exc:
                raise FieldError("sync", str(exc)) from None
            point = point_from_fields(obj, limits, sync=state)
        except FieldError as exc:
            raise FileFormatError(exc.reason, where=where, column=exc.field) from None
        if point.sync is SyncState.FAILED:
            point = replace(point, sync_error=_text_field(obj, "sync_error", where))
        if point.id in seen:
            raise FileFormatError(f"id {point.id} is already used by points[{seen[point.id]}]",
                                  where=where, column="id")
        seen[point.id] = i
        points.append(point)

    raw_plans = _expect(doc.get("plans", []), list, top, "plans", "a list of plans")
    plans: list[Plan] = []
    for i, raw in enumerate(raw_plans):
        where = f"plans[{i}]"
        obj = _expect(raw, dict, where, "", "an object")
        try:
            plan_name = validate_plan_name(obj.get("name"))
            loops = validate_loops(obj.get("loops", 1))
        except FieldError as exc:
            raise FileFormatError(exc.reason, where=where, column=exc.field) from None
        where = f"plans[{i}] ({plan_name!r})"
        if plan_name in (p.name for p in plans):
            raise FileFormatError(f"another plan is named {plan_name!r}", where=where, column="name")
        segments: list[Segment] = []
        raw_segments = _expect(obj.get("segments", []), list, where, "segments", "a list of segments")
        for j, raw_seg in enumerate(raw_segments):
            seg_where = f"{where} segment {j + 1}"
            seg = _expect(raw_seg, dict, seg_where, "", "an object")
            segments.append(_segment_from_dict(seg, seg_where))
        plans.append(Plan(plan_name, segments, loops))

    return Project(name=name, ledger=PointLedger(points, limits), plans=plans,
                   description=description, created=created, modified=modified)


def _segment_from_dict(obj: Mapping[str, Any], where: str) -> Segment:
    for key in ("type", "end"):
        if key not in obj:
            raise FileFormatError("the value is missing", where=where, column=key)
    try:
        kind = parse_kind(obj["type"])
        via = obj.get("via")
        if kind is SegmentKind.ARC and via is None:
            raise FieldError("via", "an arc needs its middle point")
        if kind is SegmentKind.LINE and via is not None:
            raise FieldError("via", "a line has no middle point")
        kwargs: dict[str, Any] = {}
        if "speed" in obj:
            kwargs["speed"] = obj["speed"]
        if "orientation" in obj:
            kwargs["orientation_changes"] = parse_orientation(obj["orientation"])
        if "ignore_middle" in obj:
            kwargs["ignore_middle"] = obj["ignore_middle"]
        if "tool" in obj:
            kwargs["tool"] = obj["tool"]
        return Segment(kind, obj["end"], via, **kwargs)
    except FieldError as exc:
        column = "type" if exc.field == "kind" else exc.field  # the file's key for the kind
        raise FileFormatError(exc.reason, where=where, column=column) from None


def parse_project(text: str, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None) -> Project:
    """A project from JSON text; :class:`FileFormatError` names where the text is wrong."""
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FileFormatError(f"not valid JSON ({exc.msg})", path=path,
                              where=f"line {exc.lineno}, column {exc.colno}") from None
    except RecursionError:
        raise FileFormatError("not valid JSON (nested too deeply)", path=path) from None
    return project_from_dict(data, limits, path=path)


def _read_bytes(path: Path) -> bytes:
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise FileFormatError(f"the file is too large ({size} bytes)", path=str(path))
        return path.read_bytes()
    except FileNotFoundError:
        raise FileFormatError("the file does not exist", path=str(path)) from None
    except IsADirectoryError:
        raise FileFormatError("is a directory, not a file", path=str(path)) from None


def load_project(path: str | os.PathLike[str], limits: PointLimits = DEFAULT_LIMITS) -> Project:
    p = Path(path)
    return parse_project(decode_text(_read_bytes(p), str(p)), limits, path=str(p))


def save_project(project: Project, path: str | os.PathLike[str], *, touch: bool = True) -> None:
    """Write the project atomically; sets ``modified`` (unless ``touch`` is False)."""
    if touch:
        project.modified = _now_iso()
    atomic_write_bytes(path, project_to_json(project).encode("utf-8"))


# --- CSV files ----------------------------------------------------------------------------------


def read_points_csv(path: str | os.PathLike[str], limits: PointLimits = DEFAULT_LIMITS) -> list[TempPoint]:
    p = Path(path)
    return parse_points_csv(decode_text(_read_bytes(p), str(p)), limits, path=str(p))


def write_points_csv(path: str | os.PathLike[str], points: Iterable[TempPoint], *, bom: bool = True) -> None:
    """Write points as CSV, atomically; with a BOM by default so spreadsheet programs read the
    Chinese names as UTF-8."""
    text = points_to_csv(points)
    atomic_write_bytes(path, (("\ufeff" + text) if bom else text).encode("utf-8"))


# --- atomic save and autosave -----------------------------------------------------------------------


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Replace ``path`` with ``data`` so that a crash leaves the old file or the new, never a mix.

    Temp file in the same directory (same filesystem), written in full, fsynced, then
    ``os.replace``; the directory is fsynced afterwards where the OS allows it. On any error
    the temp file is removed and the old file is untouched. Keeps an existing file's mode.
    """
    target = Path(path)
    directory = target.parent
    tmp = directory / f".{target.name}.{uuid.uuid4().hex[:8]}.tmp"
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0), 0o666)
    try:
        try:
            view = memoryview(data)
            while view:
                written = os.write(fd, view)
                view = view[written:]
            os.fsync(fd)
        finally:
            os.close(fd)
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


def default_autosave_dir() -> Path:
    """Per-user directory for autosaves of projects that were never saved."""
    if sys.platform == "win32":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Application Support"
    else:
        base = Path(os.environ.get("XDG_STATE_HOME") or Path.home() / ".local" / "state")
    return base / "teachpad" / "autosave"


def autosave_path(project_path: str | os.PathLike[str] | None, *, user_dir: Path | None = None) -> Path:
    """Where to autosave: ``demo.teachpad.json`` -> ``demo.teachpad.autosave.json`` next to
    it; an unsaved project goes to ``<user_dir>/untitled.autosave.json``."""
    if project_path is None:
        return (user_dir or default_autosave_dir()) / f"untitled{AUTOSAVE_SUFFIX}"
    p = Path(project_path)
    stem = p.name[: -len(".json")] if p.name.endswith(".json") else p.name
    return p.with_name(stem + AUTOSAVE_SUFFIX)


def save_autosave(project: Project, project_path: str | os.PathLike[str] | None, *,
                  user_dir: Path | None = None) -> Path:
    """Write the autosave (atomically; ``modified`` untouched); returns its path."""
    target = autosave_path(project_path, user_dir=user_dir)
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(target, project_to_json(project).encode("utf-8"))
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

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
         "uploaded": {"time": "2025-01-31T09:00:00Z", "endpoint": "tcp 192.168.1.10:502"}}
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

A point's keys are the CSV columns plus ``uploaded`` (history: when and to which controller
this host last uploaded the point). A file cannot know what a controller holds, so a loaded
point is always ``unknown``; the ``sync`` / ``sync_error`` keys of older files are ignored and
never written. Unknown keys are ignored; a different ``format`` or ``version`` is refused.
Loading parses and validates everything before it returns, so a bad file never half-replaces
what the caller holds; errors are :class:`~app.points.point.FileFormatError` naming the JSON
path and field (``points[6] (id 12), field 'x': 'abc' is not a number``) and quote at most a
short prefix of a bad value. Whatever loading accepts, saving can write (no NaN, no lone
surrogates, no numbers beyond float range).

The project in memory (:class:`Project`) lives in :mod:`app.points.project_model`; this module
is the file format and reads it, :mod:`app.points.project_write` writes it. Saving is atomic
(:mod:`app.points.atomic`); autosave and recovery live in :mod:`app.points.autosave` (import
them from there), the one-instance lock in :mod:`app.points.lock`.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from app.errors import Reason
from app.plan.segments import (
    Plan,
    Segment,
    SegmentKind,
    parse_kind,
    parse_orientation,
    validate_loops,
    validate_plan_name,
)
from app.points.atomic import atomic_write_bytes, read_limited
from app.points.fields import DEFAULT_LIMITS, FieldError, OversizedNumber, PointLimits, has_surrogates, shown
from app.points.ledger import PointLedger
from app.points.point import (
    FileFormatError,
    SyncState,
    TempPoint,
    fast_point_from_fields,
    point_from_fields,
    with_provenance,
)
from app.points.project_model import HISTORY_TEXT_MAX, LastUpload, Project, now_iso
from app.points.project_write import (
    FORMAT_NAME,
    FORMAT_VERSION,
    project_bytes,
)
from app.points.provenance import Origin, Provenance, provenance_from_json, software_name, stamp
from app.watchlist.project_io import KEY as WATCH_LIST_KEY
from app.watchlist.project_io import watch_list_from

PROJECT_SUFFIX = ".teachpad.json"

__all__ = [
    "PROJECT_SUFFIX",
    "load_project",
    "parse_project",
    "project_from_dict",
    "read_points_csv",
    "save_project",
    "write_points_csv",
]


# --- JSON (reading; app.points.project_write writes) ------------------------------------------


# Where in the file: the English text and the same as a code with arguments (for the GUI).
Place = tuple[str, Reason]
_TOP: Place = ("the file", Reason("place_file"))
# what a value should have been: the English words and the code the GUI words
_EXPECTED = {
    "text": "text",
    "points": "a list of points",
    "plans": "a list of plans",
    "segments": "a list of segments",
    "object": "an object",
    "uploaded": "an object with time and endpoint",
}


def _refuse(message: str, problem: Reason | None, where: Place, column: str | None = None) -> FileFormatError:
    return FileFormatError(message, where=where[0], place=where[1], column=column, problem=problem)


def _field_problem(exc: FieldError) -> Reason | None:
    """A field's refusal as a problem (None for one without a specific code)."""
    return exc.as_reason() if exc.code != "invalid_input" else None


def _point_place(index: int, point_id: int | None = None) -> Place:
    if point_id is None:
        return f"points[{index}]", Reason("place_point", {"index": index})
    return f"points[{index}] (id {point_id})", Reason("place_point_id", {"index": index, "id": point_id})


def _expect(value: object, kind: type | tuple[type, ...], where: Place, name: str, what: str) -> Any:
    if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
        got = (
            {"got_kind": "list" if isinstance(value, list) else "object"}
            if isinstance(value, list | dict)
            else {"got": _json_shown(value)}
        )
        raise _refuse(
            f"expected {_EXPECTED[what]}, got {_json_shown(value)}",
            Reason("expected_type", {"expected": what, **got}),
            where,
            name or None,
        )
    return value


def _json_shown(value: object) -> str:
    if isinstance(value, str | OversizedNumber) or (isinstance(value, int) and not isinstance(value, bool)):
        return shown(value)
    if isinstance(value, list | dict):
        return "a list" if isinstance(value, list) else "an object"
    return shown(json.dumps(value, ensure_ascii=False, allow_nan=True), 40)[1:-1]


def _first_surrogate(value: object, path: str) -> Place | None:
    """Where the first string (key or value) holding a lone surrogate is, if any."""
    stack: list[tuple[object, str]] = [(value, path)]
    while stack:
        item, where = stack.pop()
        if isinstance(item, str):
            if has_surrogates(item):
                return (where, Reason("place_json_path", {"path": where})) if where else _TOP
        elif isinstance(item, list):
            stack.extend((v, f"{where}[{i}]") for i, v in reversed(list(enumerate(item))))
        elif isinstance(item, dict):
            for k, v in reversed(list(item.items())):
                key_text = str(k)
                if has_surrogates(key_text):
                    return f"{where} (a key)", Reason("place_json_key", {"path": where})
                stack.append((v, f"{where}.{key_text}" if where else key_text))
    return None


def _text_field(obj: Mapping[str, Any], key: str, where: Place) -> str:
    value = obj.get(key, "")
    return str(_expect("" if value is None else value, str, where, key, "text"))


def project_from_dict(
    data: object, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None, scan_text: bool = True
) -> Project:
    """Validate a decoded JSON document fully and build the project. ``scan_text=False``
    skips the search for lone surrogates (the caller knows the document has none)."""
    try:
        return _project_from_dict(data, limits, scan_text=scan_text)
    except FileFormatError as exc:
        raise exc.with_path(path) if path else exc from None


def _project_from_dict(data: object, limits: PointLimits, *, scan_text: bool = True) -> Project:
    top = _TOP
    doc = _checked_document(data, scan_text=scan_text)
    name = _text_field(doc, "name", top) or "untitled"
    description = _text_field(doc, "description", top)
    created = _text_field(doc, "created", top)
    modified = _text_field(doc, "modified", top)
    points, history = _points_from(_expect(doc.get("points", []), list, top, "points", "points"), limits)
    plans = _plans_from(_expect(doc.get("plans", []), list, top, "plans", "plans"))
    watch_list = watch_list_from(doc.get(WATCH_LIST_KEY))  # optional (docs/PROJECT_FORMAT.md)
    return Project(
        name=name,
        ledger=PointLedger.from_checked(points, limits),
        plans=plans,
        description=description,
        created=created,
        modified=modified,
        upload_history=history,
        watch_list=tuple(watch_list),
    )


def _checked_document(data: object, *, scan_text: bool) -> dict[str, Any]:
    """The top-level object of a TeachPad project of the version this reads, all of its text
    Unicode (``scan_text=False``: the caller knows it is)."""
    if not isinstance(data, dict):
        raise FileFormatError("expected a JSON object at the top level", problem=Reason("not_json_object"))
    doc: dict[str, Any] = data
    bad_text = _first_surrogate(doc, "") if scan_text else None
    if bad_text is not None:
        raise _refuse(
            "holds an invalid character (a lone surrogate, not Unicode text)",
            Reason("bad_character"),
            bad_text,
        )
    if doc.get("format") != FORMAT_NAME:
        got = _json_shown(doc.get("format"))
        raise _refuse(
            f"expected {FORMAT_NAME!r}, got {got}: not a TeachPad project",
            Reason("not_a_project", {"expected": repr(FORMAT_NAME), "got": got}),
            _TOP,
            "format",
        )
    version = doc.get("version")
    if version != FORMAT_VERSION or isinstance(version, bool):
        got = _json_shown(version)
        raise _refuse(
            f"version {got} is not supported (this TeachPad reads version {FORMAT_VERSION})",
            Reason("version_unsupported", {"version": got, "supported": FORMAT_VERSION}),
            _TOP,
            "version",
        )
    return doc


def _points_from(raw_points: list[Any], limits: PointLimits) -> tuple[list[TempPoint], dict[int, LastUpload]]:
    """The file's points and their upload history. The fast path takes a well-formed point
    whole; anything else goes the careful way, whose refusal says where and what."""
    points: list[TempPoint] = []
    history: dict[int, LastUpload] = {}
    seen: dict[int, int] = {}
    unknown = SyncState.UNKNOWN
    for i, raw in enumerate(raw_points):
        point = fast_point_from_fields(raw, limits, sync=unknown) if type(raw) is dict else None
        if point is None or point.id in seen:
            point = _careful_point(raw, i, limits, seen)
        seen[point.id] = i
        made = raw.get("made")
        if made is not None:
            point = with_provenance(point, _provenance_from(made, i, point.id))
        points.append(point)
        uploaded = raw.get("uploaded")
        if uploaded is not None:
            record = _history_from(uploaded, i, point.id)
            if record is not None:
                history[point.id] = record
    return points, history


def _careful_point(raw: object, index: int, limits: PointLimits, seen: Mapping[int, int]) -> TempPoint:
    """The point at ``points[index]`` validated field by field; refuses an id used before."""
    where = _point_place(index)
    obj = _expect(raw, dict, where, "", "object")
    raw_id = obj.get("id")
    if isinstance(raw_id, int) and not isinstance(raw_id, bool) and abs(raw_id) < 10**9:
        where = _point_place(index, raw_id)
    try:
        # A file cannot know what a controller holds: every loaded point is "unknown"
        # (older files' "sync" / "sync_error" keys are ignored).
        point = point_from_fields(obj, limits, sync=SyncState.UNKNOWN)
    except FieldError as exc:
        raise _refuse(exc.reason, _field_problem(exc), where, exc.field) from None
    if point.id in seen:
        raise _refuse(
            f"id {point.id} is already used by points[{seen[point.id]}]",
            Reason("point_id_twice", {"id": point.id, "other": seen[point.id]}),
            _point_place(index, point.id),
            "id",
        )
    return point


def _plans_from(raw_plans: list[Any]) -> list[Plan]:
    """The file's plans, each name used once."""
    plans: list[Plan] = []
    plan_names: set[str] = set()  # the names so far: a linear check, not pairwise
    for i, raw in enumerate(raw_plans):
        plan = _plan_from(raw, i, plan_names)
        plans.append(plan)
        plan_names.add(plan.name)
    return plans


def _plan_from(raw: object, index: int, taken: set[str]) -> Plan:
    """The plan at ``plans[index]``; refuses a name in ``taken``."""
    where = (f"plans[{index}]", Reason("place_plan", {"index": index}))
    obj = _expect(raw, dict, where, "", "object")
    try:
        plan_name = validate_plan_name(obj.get("name"))
        loops = validate_loops(obj.get("loops", 1))
    except FieldError as exc:
        raise _refuse(exc.reason, _field_problem(exc), where, exc.field) from None
    where = (
        f"plans[{index}] ({plan_name!r})",
        Reason("place_plan_named", {"index": index, "name": plan_name}),
    )
    if plan_name in taken:
        raise _refuse(
            f"another plan is named {plan_name!r}",
            Reason("plan_name_taken", {"name": plan_name}),
            where,
            "name",
        )
    segments: list[Segment] = []
    raw_segments = _expect(obj.get("segments", []), list, where, "segments", "segments")
    for j, raw_seg in enumerate(raw_segments):
        seg_where = (
            f"{where[0]} segment {j + 1}",
            Reason("place_segment", {"index": index, "name": plan_name, "segment": j + 1}),
        )
        seg = _expect(raw_seg, dict, seg_where, "", "object")
        segments.append(_segment_from_dict(seg, seg_where))
    return Plan(plan_name, segments, loops)


def _history_from(raw: object, index: int, point_id: int) -> LastUpload | None:
    if raw is None:
        return None
    where = _point_place(index, point_id)
    obj = _expect(raw, dict, where, "uploaded", "uploaded")
    inner: Place = (f"{where[0]} uploaded", Reason("place_point_upload", {"index": index, "id": point_id}))
    when = _text_field(obj, "time", inner)
    endpoint = _text_field(obj, "endpoint", inner)
    return LastUpload(when[:HISTORY_TEXT_MAX], endpoint[:HISTORY_TEXT_MAX])


def _provenance_from(raw: object, index: int, point_id: int) -> Provenance:
    """A point's ``made`` object (how it was made); anything but an object is refused."""
    return provenance_from_json(_expect(raw, dict, _point_place(index, point_id), "made", "object"))


def _segment_from_dict(obj: Mapping[str, Any], where: Place) -> Segment:
    for key in ("type", "end"):
        if key not in obj:
            raise _refuse("the value is missing", Reason("value_missing"), where, key)
    try:
        kind = parse_kind(obj["type"])
        via = obj.get("via")
        if kind is SegmentKind.ARC and via is None:
            raise FieldError("via", "an arc needs its middle point", code="arc_needs_middle")
        if kind is SegmentKind.LINE and via is not None:
            raise FieldError("via", "a line has no middle point", code="line_has_no_middle")
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
        raise _refuse(exc.reason, _field_problem(exc), where, column) from None


def _json_int(digits: str) -> int | OversizedNumber:
    # int() refuses more than 4300 digits with a ValueError; no field needs more than a few.
    return OversizedNumber(digits) if len(digits.lstrip("-")) > 300 else int(digits)


def _json_float(text: str) -> float | OversizedNumber:
    # json would turn 1e400 into inf; keep the text so the message says "too large".
    number = float(text)
    return number if math.isfinite(number) else OversizedNumber(text)


# A JSON escape that decodes to a surrogate (\\ud800..\\udfff); only these, or surrogates in
# the text itself, can put a lone surrogate into the decoded document.
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F]")


def parse_project(text: str, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None) -> Project:
    """A project from JSON text; :class:`FileFormatError` names where the text is wrong.

    Fast path first: the stock decoder (C, no per-number hooks) and the point fast path; the
    surrogate scan only when the text could hold one. Any refusal (or a number the stock
    decoder cannot take) re-runs the exact path below, so every message is the careful one."""
    try:
        data = json.loads(text)
    except (ValueError, RecursionError):  # bad JSON, an int of > 4300 digits, deep nesting
        return _parse_project_exact(text, limits, path=path)
    scan = has_surrogates(text) or _SURROGATE_ESCAPE.search(text) is not None
    try:
        return project_from_dict(data, limits, path=path, scan_text=scan)
    except FileFormatError:
        return _parse_project_exact(text, limits, path=path)


def _parse_project_exact(text: str, limits: PointLimits, *, path: str | None) -> Project:
    """Decode with hooks that keep oversized numbers as text (for "too large" messages)."""
    try:
        data = json.loads(text, parse_int=_json_int, parse_float=_json_float)
    except json.JSONDecodeError as exc:
        raise FileFormatError(
            f"not valid JSON ({exc.msg})",
            path=path,
            where=f"line {exc.lineno}, column {exc.colno}",
            problem=Reason("not_json"),
            place=Reason("place_line", {"line": exc.lineno, "column": exc.colno}),
        ) from None
    except RecursionError:
        raise FileFormatError(
            "not valid JSON (nested too deeply)", path=path, problem=Reason("json_too_deep")
        ) from None
    return project_from_dict(data, limits, path=path)


def load_project(path: str | os.PathLike[str], limits: PointLimits = DEFAULT_LIMITS) -> Project:
    from app.points.csv_io import decode_text  # (csv: imported by the first file read, not at start-up)

    p = Path(path)
    return parse_project(decode_text(read_limited(p), str(p)), limits, path=str(p))


def save_project(project: Project, path: str | os.PathLike[str], *, touch: bool = True) -> None:
    """Write the project atomically; sets ``modified`` (unless ``touch`` is False).
    :class:`ProjectTooLarge` (nothing written) when TeachPad could not open the file again."""
    if touch:
        project.modified = now_iso()
    atomic_write_bytes(path, project_bytes(project))


# --- CSV files ----------------------------------------------------------------------------------


def read_points_csv(
    path: str | os.PathLike[str], limits: PointLimits = DEFAULT_LIMITS, *, made: Provenance | None = None
) -> list[TempPoint]:
    """The file's points, each recording that it was imported from this file, now (``made``:
    another provenance, e.g. with the controller the link reaches)."""
    from app.points.csv_io import decode_text, parse_points_csv

    p = Path(path)
    points = parse_points_csv(decode_text(read_limited(p), str(p)), limits, path=str(p))
    if made is None:
        made = stamp(Origin.IMPORTED, software=software_name(), file=p.name)
    return [with_provenance(point, made) for point in points]


def write_points_csv(path: str | os.PathLike[str], points: Iterable[TempPoint], *, bom: bool = True) -> None:
    """Write points as CSV, atomically; with a BOM by default so spreadsheet programs read the
    Chinese names as UTF-8."""
    from app.points.csv_io import points_to_csv

    text = points_to_csv(points)
    atomic_write_bytes(path, (("\ufeff" + text) if bom else text).encode("utf-8"))

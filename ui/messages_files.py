"""The sentences of refused values and files: a point's fields, a points CSV file, a project
file and a plan's segments (codes of app/points/fields.py, csv_io.py, project.py and
app/plan/segments.py). Data and the file / place wording only: :mod:`ui.messages` adds
:data:`FILE_TEMPLATES` to its sentences (:func:`ui.messages.refusal_text`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from PySide6.QtCore import QCoreApplication

from app.points.point import FileFormatError

CONTEXT = "Messages"


def QT_TRANSLATE_NOOP(context: str, text: str) -> str:
    return text


def _tr(text: str) -> str:
    return QCoreApplication.translate(CONTEXT, text)


FILE_TEMPLATES: dict[str, str] = {
    # a point's field refused (app/points/point.py), in a cell edit or a file
    "not_a_number": QT_TRANSLATE_NOOP("Messages", "{value} is not a number"),
    "too_large": QT_TRANSLATE_NOOP("Messages", "{value} is too large"),
    "value_empty": QT_TRANSLATE_NOOP("Messages", "the value is empty"),
    "not_finite": QT_TRANSLATE_NOOP("Messages", "{value} is not a finite number"),
    "not_integer": QT_TRANSLATE_NOOP("Messages", "{value} is not an integer"),
    "id_out_of_range": QT_TRANSLATE_NOOP("Messages", "id {value} is outside {id_min}..{id_max}"),
    "bad_tool": QT_TRANSLATE_NOOP("Messages", "tool {value} is not 0..{max} or {none} (none)"),
    "not_text": QT_TRANSLATE_NOOP("Messages", "the value is not text"),
    "too_long": QT_TRANSLATE_NOOP("Messages", "the text is longer than {max} characters"),
    "bad_character": QT_TRANSLATE_NOOP(
        "Messages", "holds an invalid character (a lone surrogate, not Unicode text)"
    ),
    "not_one_line": QT_TRANSLATE_NOOP("Messages", "must be one line"),
    "value_missing": QT_TRANSLATE_NOOP("Messages", "the value is missing"),
    # a points CSV file refused (app/points/csv_io.py)
    "not_utf8": QT_TRANSLATE_NOOP(
        "Messages", "not UTF-8 text (bad byte at offset {offset}); save the file as UTF-8"
    ),
    "empty_file": QT_TRANSLATE_NOOP("Messages", "the file is empty (expected a header row)"),
    "unknown_column": QT_TRANSLATE_NOOP("Messages", "unknown column {name} (expected: {expected})"),
    "column_twice": QT_TRANSLATE_NOOP("Messages", "the column appears twice"),
    "column_missing": QT_TRANSLATE_NOOP("Messages", "the column is missing from the header"),
    "cell_count": QT_TRANSLATE_NOOP(
        "Messages", "has {cells} cells, the header has {header} (truncated or extra cells?)"
    ),
    "row_id_taken": QT_TRANSLATE_NOOP("Messages", "id {id} is already used on row {other}"),
    "not_csv": QT_TRANSLATE_NOOP("Messages", "not valid CSV (a quote is not closed, or a stray character)"),
    # a file that cannot be read at all (app/points/atomic.py read_limited), or an OSError's errno
    "file_too_large": QT_TRANSLATE_NOOP("Messages", "the file is too large ({size} bytes, at most {limit})"),
    "project_too_large": QT_TRANSLATE_NOOP(
        "Messages",
        "The project would be {size} bytes, more than TeachPad opens ({limit} bytes): nothing was changed or written.",
    ),
    "no_such_file": QT_TRANSLATE_NOOP("Messages", "the file does not exist"),
    "is_a_directory": QT_TRANSLATE_NOOP("Messages", "is a folder, not a file"),
    "permission_denied": QT_TRANSLATE_NOOP("Messages", "permission denied"),
    "os_error": QT_TRANSLATE_NOOP("Messages", "the system refused the file (error {errno})"),
    # a project file refused (app/points/project.py)
    "not_json": QT_TRANSLATE_NOOP("Messages", "not valid JSON"),
    "json_too_deep": QT_TRANSLATE_NOOP("Messages", "not valid JSON (nested too deeply)"),
    "not_json_object": QT_TRANSLATE_NOOP(
        "Messages", "not a project: expected a JSON object at the top level"
    ),
    "not_a_project": QT_TRANSLATE_NOOP(
        "Messages", "not a TeachPad project (format {got}, expected {expected})"
    ),
    "version_unsupported": QT_TRANSLATE_NOOP(
        "Messages", "version {version} is not supported (this TeachPad reads version {supported})"
    ),
    "expected_type": QT_TRANSLATE_NOOP("Messages", "expected {expected}, got {got}"),
    "point_id_twice": QT_TRANSLATE_NOOP("Messages", "id {id} is already used by point {other_number}"),
    "plan_name_taken": QT_TRANSLATE_NOOP("Messages", "another plan is named \u201c{name}\u201d"),
    # a plan's segments and names refused (app/plan/segments.py, ui/models/segment_model.py)
    "not_yes_no": QT_TRANSLATE_NOOP("Messages", "{value} is not yes or no"),
    "not_segment_kind": QT_TRANSLATE_NOOP("Messages", "{value} is not a line or an arc"),
    "not_orientation": QT_TRANSLATE_NOOP(
        "Messages", "{value} is not \u201cchanges\u201d or \u201ckept\u201d"
    ),
    "negative_point_id": QT_TRANSLATE_NOOP("Messages", "point id {id} is negative"),
    "no_such_field": QT_TRANSLATE_NOOP("Messages", "there is no field \u201c{name}\u201d"),
    "plan_name_empty": QT_TRANSLATE_NOOP("Messages", "a plan needs a name"),
    "plan_name_format": QT_TRANSLATE_NOOP(
        "Messages", "the name must be one line of at most {max} characters"
    ),
    "bad_loops": QT_TRANSLATE_NOOP("Messages", "{value} loops: give 0 (endless) to {max}"),
    "cannot_move_segment": QT_TRANSLATE_NOOP(
        "Messages", "cannot move segment {src} to {dst} in {segments} segments"
    ),
    "arc_needs_middle": QT_TRANSLATE_NOOP("Messages", "an arc needs its middle point"),
    "line_has_no_middle": QT_TRANSLATE_NOOP("Messages", "a line has no middle point"),
    "segment_point_missing": QT_TRANSLATE_NOOP(
        "Messages", "point P{id} does not exist: pick one of the list"
    ),
    "speed_not_positive": QT_TRANSLATE_NOOP("Messages", "{speed} mm/s: the speed must be above 0"),
    "arc_same_points": QT_TRANSLATE_NOOP("Messages", "an arc's middle point must differ from its end point"),
}

# what a project file's value should have been (app/points/project.py _EXPECTED keys)
_EXPECTED: dict[str, str] = {
    "text": QT_TRANSLATE_NOOP("Messages", "text"),
    "points": QT_TRANSLATE_NOOP("Messages", "a list of points"),
    "plans": QT_TRANSLATE_NOOP("Messages", "a list of plans"),
    "segments": QT_TRANSLATE_NOOP("Messages", "a list of segments"),
    "object": QT_TRANSLATE_NOOP("Messages", "an object"),
    "uploaded": QT_TRANSLATE_NOOP("Messages", "an object with time and endpoint"),
}
_GOT_KINDS: dict[str, str] = {
    "list": QT_TRANSLATE_NOOP("Messages", "a list"),
    "object": QT_TRANSLATE_NOOP("Messages", "an object"),
}

# where in a project file (FileFormatError.place codes); points and plans counted from 1
_PLACES: dict[str, str] = {
    "place_file": QT_TRANSLATE_NOOP("Messages", "the file"),
    "place_point": QT_TRANSLATE_NOOP("Messages", "point {number}"),
    "place_point_id": QT_TRANSLATE_NOOP("Messages", "point {number} (id {id})"),
    "place_point_upload": QT_TRANSLATE_NOOP("Messages", "point {number} (id {id}), upload history"),
    "place_plan": QT_TRANSLATE_NOOP("Messages", "plan {number}"),
    "place_plan_named": QT_TRANSLATE_NOOP("Messages", "plan {number} \u201c{name}\u201d"),
    "place_segment": QT_TRANSLATE_NOOP("Messages", "plan {number} \u201c{name}\u201d, segment {segment}"),
    "place_line": QT_TRANSLATE_NOOP("Messages", "line {line}, column {column}"),
    "place_json_path": QT_TRANSLATE_NOOP("Messages", "at \u201c{path}\u201d"),
    "place_json_key": QT_TRANSLATE_NOOP("Messages", "a key at \u201c{path}\u201d"),
}

_AT_ROW_COLUMN = QT_TRANSLATE_NOOP("Messages", "row {row}, column '{column}': {problem}")
_AT_ROW = QT_TRANSLATE_NOOP("Messages", "row {row}: {problem}")
_AT_COLUMN = QT_TRANSLATE_NOOP("Messages", "column '{column}': {problem}")
_AT_PLACE_FIELD = QT_TRANSLATE_NOOP("Messages", "{place}, field '{column}': {problem}")
_AT_PLACE = QT_TRANSLATE_NOOP("Messages", "{place}: {problem}")
_IN_FILE = QT_TRANSLATE_NOOP("Messages", "{file}: {text}")


def file_fields(code: str, args: Mapping[str, Any], out: dict[str, str]) -> None:
    """Translate the arguments of a file code that are words, not values (in place)."""
    if code == "expected_type":
        out["expected"] = _tr(_EXPECTED.get(str(args.get("expected")), _EXPECTED["object"]))
        if "got_kind" in args:
            out["got"] = _tr(_GOT_KINDS.get(str(args["got_kind"]), _GOT_KINDS["object"]))
    elif code == "point_id_twice" and "other" in args:
        out["other_number"] = str(int(args["other"]) + 1)


def _place_text(exc: FileFormatError) -> str | None:
    place = exc.place
    if place is None or place.code not in _PLACES:
        return None
    args = {k: str(v) for k, v in place.args.items()}
    if "index" in place.args:
        args["number"] = str(int(place.args["index"]) + 1)
    try:
        return _tr(_PLACES[place.code]).format(**args)
    except KeyError:
        return None


def file_text(exc: FileFormatError, problem: str | None) -> str | None:
    """A refused file's ``problem`` (already worded) with its place, row and column; None when
    the problem or its place has no wording (the English text is then shown whole)."""
    if problem is None:
        return None
    column = exc.column
    if exc.where is not None:
        place = _place_text(exc)
        if place is None:
            return None
        text = (
            _tr(_AT_PLACE_FIELD).format(place=place, column=column, problem=problem)
            if column
            else _tr(_AT_PLACE).format(place=place, problem=problem)
        )
    elif exc.row is not None and column is not None:
        text = _tr(_AT_ROW_COLUMN).format(row=exc.row, column=column, problem=problem)
    elif exc.row is not None:
        text = _tr(_AT_ROW).format(row=exc.row, problem=problem)
    elif column is not None:
        text = _tr(_AT_COLUMN).format(column=column, problem=problem)
    else:
        text = problem
    file = exc.params.get("file")
    return _tr(_IN_FILE).format(file=file, text=text) if file else text


_OS_CODES = {
    FileNotFoundError: "no_such_file",
    IsADirectoryError: "is_a_directory",
    PermissionError: "permission_denied",
}


def os_problem(exc: OSError) -> tuple[str, dict[str, Any]]:
    """An OSError as a file problem's code and arguments (its strerror is the system's English)."""
    for kind, code in _OS_CODES.items():
        if isinstance(exc, kind):
            return code, {}
    return "os_error", {"errno": exc.errno if exc.errno is not None else "?"}

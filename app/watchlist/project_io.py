"""The watch list in the project file (``watch_list``, docs/PROJECT_FORMAT.md): read and written.

An optional top-level key of the version 1 format: a list of ``{"source": "gv" | "reg",
"number": n, "type": "float32" | "int16" | "bits", "name": text}``. A project without it has an
empty watch list; a TeachPad from before it ignores the key (unknown keys are ignored), so the
format's version stays 1. A bad entry refuses the file like any other bad field, naming its place
(``watch_list[2], field 'number': GV 40000 is out of range (0..32767)``).
"""

from __future__ import annotations

from collections.abc import Sequence

from app.errors import InvalidInput, Reason
from app.points.point import FileFormatError
from app.watchlist.entry import MAX_ENTRIES, WatchEntry

__all__ = ["KEY", "watch_list_from", "watch_list_to_json"]

KEY = "watch_list"


def _place(index: int | None) -> tuple[str, Reason]:
    where = KEY if index is None else f"{KEY}[{index}]"
    return where, Reason("place_json_path", {"path": where})


def watch_list_from(raw: object) -> list[WatchEntry]:
    """The file's watch list (None or absent: empty); :class:`FileFormatError` naming the entry."""
    if raw is None:
        return []
    if not isinstance(raw, list):
        where, place = _place(None)
        raise FileFormatError("expected a list of watched values", where=where, place=place)
    if len(raw) > MAX_ENTRIES:
        where, place = _place(None)
        raise FileFormatError(f"at most {MAX_ENTRIES} watched values", where=where, place=place)
    entries: list[WatchEntry] = []
    for index, item in enumerate(raw):
        entries.append(_entry_from(item, index))
    return entries


def _entry_from(item: object, index: int) -> WatchEntry:
    where, place = _place(index)
    if not isinstance(item, dict):
        raise FileFormatError("expected an object", where=where, place=place)
    column = "source"
    try:
        source = item.get("source", "gv")
        column = "number"
        number = item.get("number")
        if isinstance(number, float) and number.is_integer():
            number = int(number)
        name = item.get("name", "")
        if not isinstance(name, str):
            column = "name"
            raise InvalidInput("expected text")
        column = "type"
        return WatchEntry.make(str(source), number, item.get("type"), name)
    except InvalidInput as exc:
        raise FileFormatError(str(exc), where=where, place=place, column=_column(exc, column)) from None


def _column(exc: InvalidInput, guess: str) -> str:
    return {"watch_bad_type": "type", "watch_bad_source": "source", "watch_bad_name": "name"}.get(
        exc.code, "number" if exc.code.endswith("out_of_range") or exc.code == "watch_bad_number" else guess
    )


def watch_list_to_json(entries: Sequence[WatchEntry]) -> list[dict[str, object]]:
    return [entry.to_dict() for entry in entries]

"""Temp points as CSV (documented in docs/PROJECT_FORMAT.md).

Header row with the columns ``id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note``; UTF-8, with or
without a BOM; ``id`` and ``x``..``c`` are required, the others may be left out (defaults:
empty name and note, external axes 0, tool 200 = none). Rows are numbered as a spreadsheet
shows them: the header is row 1. A bad file is refused whole with a
:class:`~app.points.point.FileFormatError` naming the row and the column.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable

from app.errors import Reason
from app.points.fields import DEFAULT_LIMITS, FieldError, PointLimits, shown
from app.points.number_text import value_text
from app.points.point import CSV_COLUMNS, CSV_REQUIRED, FileFormatError, TempPoint, point_from_fields

_POSE_FIELDS = ("x", "y", "z", "a", "b", "c")


def points_to_csv(points: Iterable[TempPoint]) -> str:
    """The CSV text (no BOM) of ``points``, header first; numbers as :mod:`app.points.number_text`
    writes them (shortest float32 text, 0 near 0, +180 for A/C at ±180)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")
    writer.writerow(CSV_COLUMNS)
    for p in points:
        writer.writerow(
            [
                str(p.id),
                p.name,
                *(value_text(v, field) for v, field in zip(p.xyzabc, _POSE_FIELDS, strict=True)),
                *(value_text(v) for v in p.ext),
                str(p.tool),
                p.note,
            ]
        )
    return out.getvalue()


def decode_text(data: bytes, path: str | None = None) -> str:
    """UTF-8 text, a leading BOM dropped; refuses other encodings with a hint."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FileFormatError(
            f"not UTF-8 text (bad byte at offset {exc.start}); save the file as UTF-8",
            path=path,
            problem=Reason("not_utf8", {"offset": exc.start}),
        ) from None


def _read_rows(text: str, path: str | None) -> list[list[str]]:
    """The CSV's rows as cells (a leading BOM dropped); text the csv module refuses is not CSV."""
    if text.startswith("\ufeff"):
        text = text[1:]
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[list[str]] = []
    try:
        rows.extend(reader)
    except csv.Error as exc:
        reason = shown(str(exc), 80)[1:-1]
        # the csv module's own detail stays in the English text; the GUI says "not valid CSV"
        raise FileFormatError(
            f"not valid CSV ({reason})", path=path, row=len(rows) + 1, problem=Reason("not_csv")
        ) from None
    return rows


def _header_index(rows: list[list[str]], path: str | None) -> int:
    """The index of the header: the first row with a cell that is not blank."""
    header_at = next((i for i, r in enumerate(rows) if any(cell.strip() for cell in r)), None)
    if header_at is None:
        raise FileFormatError(
            "the file is empty (expected a header row)", path=path, row=1, problem=Reason("empty_file")
        )
    return header_at


def _check_header(cells: list[str], header: list[str], header_row: int, path: str | None) -> None:
    """Every column known and named once, every required column present."""
    for col, name in enumerate(header):
        if name not in CSV_COLUMNS:
            raise FileFormatError(
                f"unknown column {shown(cells[col])} (expected: {','.join(CSV_COLUMNS)})",
                path=path,
                row=header_row,
                problem=Reason(
                    "unknown_column", {"name": shown(cells[col]), "expected": ",".join(CSV_COLUMNS)}
                ),
            )
        if header.index(name) != col:
            raise FileFormatError(
                "the column appears twice",
                path=path,
                row=header_row,
                column=name,
                problem=Reason("column_twice"),
            )
    for name in CSV_COLUMNS:
        if name in CSV_REQUIRED and name not in header:
            raise FileFormatError(
                "the column is missing from the header",
                path=path,
                row=header_row,
                column=name,
                problem=Reason("column_missing"),
            )


def _parse_row(
    cells: list[str], header: list[str], number: int, limits: PointLimits, path: str | None
) -> TempPoint:
    """The point of one data row (spreadsheet row ``number``)."""
    if len(cells) != len(header):
        raise FileFormatError(
            f"has {len(cells)} cells, the header has {len(header)} (truncated or extra cells?)",
            path=path,
            row=number,
            problem=Reason("cell_count", {"cells": len(cells), "header": len(header)}),
        )
    fields = dict(zip(header, cells, strict=True))
    try:
        return point_from_fields(fields, limits)
    except FieldError as exc:
        raise FileFormatError(
            exc.reason, path=path, row=number, column=exc.field, problem=exc.as_reason()
        ) from None


def parse_points_csv(
    text: str, limits: PointLimits = DEFAULT_LIMITS, *, path: str | None = None
) -> list[TempPoint]:
    """Parse CSV text fully; raises :class:`FileFormatError` naming the row and column."""
    rows = _read_rows(text, path)
    header_at = _header_index(rows, path)
    header = [cell.strip().lower() for cell in rows[header_at]]
    header_row = header_at + 1
    _check_header(rows[header_at], header, header_row, path)
    points: list[TempPoint] = []
    seen: dict[int, int] = {}
    for number, cells in enumerate(rows[header_at + 1 :], start=header_row + 1):
        if not any(cell.strip() for cell in cells):
            continue  # blank line
        point = _parse_row(cells, header, number, limits, path)
        if point.id in seen:
            raise FileFormatError(
                f"id {point.id} is already used on row {seen[point.id]}",
                path=path,
                row=number,
                column="id",
                problem=Reason("row_id_taken", {"id": point.id, "other": seen[point.id]}),
            )
        seen[point.id] = number
        points.append(point)
    return points

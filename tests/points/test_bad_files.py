"""Project and CSV files under bad input: huge numbers, NaN / inf, lone surrogates, 10 MB lines,
non-UTF-8 bytes, wrong types. Each is refused with a short message naming the JSON path (project)
or the row and column (CSV), never a traceback, and the file is left untouched. Whatever loading
accepts, saving writes (a seeded random round trip)."""

from __future__ import annotations

import json
import random
import struct
from collections.abc import Iterable, Sequence
from pathlib import Path

import pytest

from app.cli import points as cli_points
from app.cli.context import CliContext
from app.connection import ConnectionSettings
from app.points.csv_io import parse_points_csv, points_to_csv
from app.points.fields import QUOTE_CHARS
from app.points.number_text import shown_value
from app.points.point import FileFormatError, TempPoint
from app.points.project import load_project, parse_project, read_points_csv, save_project
from app.points.project_write import project_to_json

MESSAGE_MAX = 400  # a refusal is a sentence or two, never the bad value itself
BIG_LINE = 10 * 1024 * 1024
HUGE_INT = str(10**400)
DIGITS_5000 = "7" * 5000


def _point(**changes: object) -> dict[str, object]:
    p: dict[str, object] = {"id": 5, "name": "p", "x": 1.0, "y": 0, "z": 0, "a": 0, "b": 0, "c": 0}
    p.update(changes)
    return p


def _project_text(points: list[str] | None = None, plans: str = "[]", **top: str) -> str:
    """JSON text built by hand, so that it can hold what json.dumps would not write."""
    head = {"format": '"teachpad-project"', "version": "1", **top}
    body = ", ".join(f'"{k}": {v}' for k, v in head.items())
    pts = ", ".join(points if points is not None else [json.dumps(_point())])
    return f'{{{body}, "points": [{pts}], "plans": {plans}}}'


def _point_text(field: str, raw: str) -> str:
    """A point whose ``field`` holds the raw JSON text ``raw``."""
    fields = {k: json.dumps(v) for k, v in _point().items()}
    fields[field] = raw
    return "{" + ", ".join(f'"{k}": {v}' for k, v in fields.items()) + "}"


BAD_PROJECTS: list[tuple[str, str, str, str]] = [
    # case, file text, where (JSON path + field), reason
    ("10**400 as x", _project_text([_point_text("x", HUGE_INT)]), "points[0] (id 5), field 'x'", "too large"),
    (
        "5000 digits as id",
        _project_text([_point_text("id", DIGITS_5000)]),
        "points[0], field 'id'",
        "too large",
    ),
    (
        "5000 digits as loops",
        _project_text(plans='[{"name": "p", "loops": ' + DIGITS_5000 + "}]"),
        "plans[0], field 'loops'",
        "too large",
    ),
    ("1e400", _project_text([_point_text("z", "1e400")]), "field 'z'", "too large"),
    ("5000-digit float", _project_text([_point_text("z", DIGITS_5000 + ".5")]), "field 'z'", "too large"),
    ("NaN", _project_text([_point_text("y", "NaN")]), "points[0] (id 5), field 'y'", "not a finite number"),
    ("Infinity", _project_text([_point_text("a", "Infinity")]), "field 'a'", "not a finite number"),
    (
        "-Infinity speed",
        _project_text(plans='[{"name": "p", "segments": [{"type": "line", "end": 5, "speed": -Infinity}]}]'),
        "segment 1, field 'speed'",
        "finite",
    ),
    (
        "lone surrogate in a name",
        _project_text([_point_text("name", '"ab\\ud800cd"')]),
        "points[0].name",
        "lone surrogate",
    ),
    (
        "lone surrogate in a plan name",
        _project_text(plans='[{"name": "\\udfff"}]'),
        "plans[0].name",
        "lone surrogate",
    ),
    ("lone surrogate in a key", _project_text(extra='{"\\ud800": 1}'), "extra (a key)", "lone surrogate"),
    (
        "10 MB name",
        _project_text([_point_text("name", json.dumps("n" * BIG_LINE))]),
        "field 'name'",
        "longer than 200",
    ),
    ("10 MB number", _project_text([_point_text("x", "9" * BIG_LINE)]), "field 'x'", "too large"),
    (
        "10 MB format",
        _project_text(format=json.dumps("f" * BIG_LINE)),
        "field 'format'",
        "not a TeachPad project",
    ),
    ("list as x", _project_text([_point_text("x", "[1, 2]")]), "field 'x'", "not a number"),
    ("text as tool", _project_text([_point_text("tool", '"drill"')]), "field 'tool'", "not a number"),
    ("fractional id", _project_text([_point_text("id", "1.5")]), "field 'id'", "not an integer"),
    ("number as name", _project_text([_point_text("name", "12")]), "field 'name'", "is not text"),
    (
        "object as points",
        _project_text(points=None).replace('"points": [', '"points": {"a": [') + "}",
        "the file, field 'points'",
        "expected a list of points, got an object",
    ),
    ("string as plans", _project_text(plans='"' + "p" * 1000 + '"'), "field 'plans'", "expected a list"),
    (
        "bad history",
        _project_text([_point_text("uploaded", '{"time": 5}')]),
        "uploaded, field 'time'",
        "expected text",
    ),
]


@pytest.mark.parametrize(("case", "text", "where", "reason"), BAD_PROJECTS, ids=[c[0] for c in BAD_PROJECTS])
def test_bad_project_is_refused_briefly_naming_where_and_untouched(
    tmp_path: Path, case: str, text: str, where: str, reason: str
) -> None:
    path = tmp_path / "bad.teachpad.json"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    before, mtime = path.read_bytes(), path.stat().st_mtime_ns
    with pytest.raises(FileFormatError) as info:
        load_project(path)
    message = str(info.value)
    assert message.startswith(str(path))
    assert where in message and reason in message, message
    assert len(message) - len(str(path)) < MESSAGE_MAX, message[:500]
    assert path.read_bytes() == before and path.stat().st_mtime_ns == mtime


def test_non_utf8_and_raw_surrogate_bytes_are_refused(tmp_path: Path) -> None:
    path = tmp_path / "gbk.teachpad.json"
    for raw in (
        _project_text().replace('"p"', '"点"').encode("gbk"),
        _project_text().encode("utf-8").replace(b'"p"', b'"\xed\xa0\x80"'),
    ):  # a surrogate in UTF-8
        path.write_bytes(raw)
        with pytest.raises(FileFormatError, match=r"not UTF-8 text \(bad byte at offset"):
            load_project(path)
        assert path.read_bytes() == raw


def test_a_bad_project_through_the_cli_is_a_message_not_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "bad.teachpad.json"
    path.write_text(_project_text([_point_text("x", DIGITS_5000)]), encoding="utf-8")
    parser_args = ["points", "list", str(path)]
    import argparse

    parser = argparse.ArgumentParser()
    cli_points.register(parser.add_subparsers(dest="command"))
    args = parser.parse_args(parser_args)
    assert args.handler(CliContext(args, ConnectionSettings())) == cli_points.EXIT_USAGE
    err = capsys.readouterr().err
    assert "field 'x'" in err and "too large" in err and "Traceback" not in err
    assert len(err) < MESSAGE_MAX + len(str(path))


HEADER = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
ROW = ["5", "p", "1", "2", "3", "0", "0", "0", "0", "0", "0", "0", "0", "200", ""]


def _csv_row(column: str, value: str) -> str:
    cells = list(ROW)
    cells[HEADER.split(",").index(column)] = value
    return HEADER + "\r\n" + "1,a,0,0,0,0,0,0,0,0,0,0,0,200,\r\n" + ",".join(cells) + "\r\n"


BAD_CSV: list[tuple[str, str, str, str]] = [
    ("10**400 as id", _csv_row("id", HUGE_INT), "row 3, column 'id'", "too large"),
    ("5000 digits as x", _csv_row("x", DIGITS_5000), "row 3, column 'x'", "too large"),
    ("5000 digits as tool", _csv_row("tool", DIGITS_5000), "row 3, column 'tool'", "too large"),
    ("1e400", _csv_row("y", "1e400"), "row 3, column 'y'", "too large"),
    ("nan", _csv_row("z", "nan"), "row 3, column 'z'", "not a finite number"),
    ("-inf", _csv_row("a", "-inf"), "row 3, column 'a'", "not a finite number"),
    ("Infinity", _csv_row("e2", "Infinity"), "row 3, column 'e2'", "not a finite number"),
    ("10 MB cell", _csv_row("note", "n" * BIG_LINE), "row 3", "not valid CSV"),
    ("10 MB line of cells", HEADER + "\r\n" + "1," * (BIG_LINE // 2) + "\r\n", "row 2", "cells"),
    ("long text as x", _csv_row("x", "x" * 100_000), "row 3, column 'x'", "is not a number"),
    ("text as tool", _csv_row("tool", "drill"), "row 3, column 'tool'", "not a number"),
    ("fractional id", _csv_row("id", "2.5"), "row 3, column 'id'", "not an integer"),
    ("long header", HEADER + "," + "h" * 100_000 + "\r\n", "row 1", "unknown column"),
]


@pytest.mark.parametrize(("case", "text", "where", "reason"), BAD_CSV, ids=[c[0] for c in BAD_CSV])
def test_bad_csv_is_refused_briefly_naming_row_and_column_and_untouched(
    tmp_path: Path, case: str, text: str, where: str, reason: str
) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    before, mtime = path.read_bytes(), path.stat().st_mtime_ns
    with pytest.raises(FileFormatError) as info:
        read_points_csv(path)
    message = str(info.value)
    assert where in message and reason in message, message[:500]
    assert len(message) - len(str(path)) < MESSAGE_MAX, message[:500]
    assert path.read_bytes() == before and path.stat().st_mtime_ns == mtime


def test_csv_lone_surrogate_and_bad_bytes(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="row 3, column 'name': holds an invalid character"):
        parse_points_csv(_csv_row("name", "a\ud800"))
    path = tmp_path / "gbk.csv"
    path.write_bytes(_csv_row("name", "点").encode("gbk"))
    with pytest.raises(FileFormatError, match="not UTF-8"):
        read_points_csv(path)


def test_quotes_are_short() -> None:
    with pytest.raises(FileFormatError) as info:
        parse_points_csv(_csv_row("x", "y" * 5000))
    assert "'" + "y" * QUOTE_CHARS + "'... (5000 characters)" in str(info.value)


# --- whatever loading accepts, saving writes -------------------------------------------------------


NASTY_TEXT = [
    "",
    " ",
    "原点",
    "a,b",
    'q"q',
    "line\nbreak",
    "\x00",
    "\ud800",
    "\udfff x",
    "e\u0301",
    "\U0001f916",
    "\u202e",
    "\ufeff",
    "x" * 201,
    "y" * 2001,
    "\\",
    "\t",
]
NASTY_NUMBERS: list[object] = [
    0,
    -0.0,
    1,
    -1,
    0.1,
    1e-320,
    5e-324,
    1.7976931348623157e308,
    3.4e38,
    1e300,
    10**20,
    10**400,
    2**53 + 1,
    0.5,
    200,
    199,
    10000,
    10001,
    -5,
    12.0,
    float("nan"),
    float("inf"),
    True,
    None,
    "5",
    " 7 ",
    "1e3",
    "abc",
    [],
    {},
]


def _pick(rng: random.Random, pool: Sequence[object], good: object, p_good: float = 0.97) -> object:
    return good if rng.random() < p_good else rng.choice(pool)


def _random_doc(rng: random.Random) -> dict[str, object]:
    points = []
    for i in range(rng.randint(0, 6)):
        p: dict[str, object] = {"id": _pick(rng, NASTY_NUMBERS, i + 1)}
        for key in ("x", "y", "z", "a", "b", "c", "e1", "e3"):
            p[key] = _pick(rng, NASTY_NUMBERS, rng.uniform(-2000, 2000))
        p["tool"] = _pick(rng, NASTY_NUMBERS, rng.choice([0, 5, 199, 200]))
        p["name"] = _pick(rng, [*NASTY_TEXT, 5], rng.choice(NASTY_TEXT[:5]))
        p["note"] = _pick(rng, NASTY_TEXT, rng.choice(NASTY_TEXT[:7]))
        if rng.random() < 0.3:
            p["uploaded"] = {"time": rng.choice(NASTY_TEXT), "endpoint": rng.choice(NASTY_TEXT)}
        if rng.random() < 0.2:
            p["sync"] = rng.choice(["on-controller", "failed", "bogus", 5])
        points.append(p)
    plans = []
    for j in range(rng.randint(0, 3)):
        segs = [
            {
                "type": _pick(rng, ["arc", "spline", 1], "line"),
                "end": _pick(rng, NASTY_NUMBERS, 1),
                "speed": _pick(rng, NASTY_NUMBERS, rng.uniform(1, 900)),
                "tool": _pick(rng, NASTY_NUMBERS, 200),
            }
            for _ in range(rng.randint(0, 4))
        ]
        plans.append(
            {
                "name": _pick(rng, NASTY_TEXT, f"plan {j}"),
                "loops": _pick(rng, NASTY_NUMBERS, 1),
                "segments": segs,
            }
        )
    return {
        "format": "teachpad-project",
        "version": 1,
        "name": _pick(rng, NASTY_TEXT, "demo"),
        "description": _pick(rng, NASTY_TEXT, ""),
        "points": points,
        "plans": plans,
    }


def _f32(value: float) -> float:
    try:
        return float(struct.unpack("<f", struct.pack("<f", value))[0])
    except OverflowError:
        return value


def _as_written(points: Iterable[TempPoint]) -> list[tuple[object, ...]]:
    """The points as a CSV keeps them: each number as it reads (shown_value), to the float32 the
    controller holds (a float32 is written as its shortest float32 text, which reads back as
    another float64 with the same float32)."""
    return [
        (
            p.id,
            p.name,
            tuple(_f32(shown_value(v, f)) for v, f in zip(p.xyzabc, "xyzabc", strict=True)),
            tuple(_f32(shown_value(v)) for v in p.ext),
            p.tool,
            p.note,
        )
        for p in points
    ]


def test_saving_never_fails_on_what_loading_accepted(tmp_path: Path) -> None:
    rng = random.Random(20250131)
    accepted = refused = 0
    path = tmp_path / "fuzz.teachpad.json"
    for _ in range(400):
        doc = _random_doc(rng)
        text = json.dumps(doc, ensure_ascii=rng.random() < 0.5, allow_nan=True)
        try:
            project = parse_project(text)
        except FileFormatError as exc:
            refused += 1
            assert len(str(exc)) < MESSAGE_MAX, str(exc)[:500]
            continue
        accepted += 1
        save_project(project, path)  # must not raise
        back = load_project(path)
        assert back.ledger.snapshot() == project.ledger.snapshot()
        assert [(p.name, p.loops, p.segments) for p in back.plans] == [
            (p.name, p.loops, p.segments) for p in project.plans
        ]
        assert back.upload_history == project.upload_history
        assert project_to_json(back) == project_to_json(project)
        # the CSV reads as the table does (app/points/number_text.py): the float32 the controller
        # holds, 0 near 0, +180 for A/C at -180; and it writes the same text again
        csv_text = points_to_csv(project.ledger)
        again = parse_points_csv(csv_text)
        assert _as_written(again) == _as_written(project.ledger)
        assert points_to_csv(again) == csv_text
    assert accepted > 40 and refused > 40, (accepted, refused)


def test_csv_round_trip_of_random_rows() -> None:
    rng = random.Random(7)
    for _ in range(300):
        rows = [HEADER]
        for i in range(rng.randint(0, 5)):
            name = rng.choice(NASTY_TEXT[:7]) if rng.random() < 0.9 else rng.choice(NASTY_TEXT)
            cells = [str(_pick(rng, NASTY_NUMBERS, i + 1, 0.9)), str(name)]
            cells += [
                str(_pick(rng, NASTY_NUMBERS, round(rng.uniform(-999, 999), 3), 0.9)) for _ in range(11)
            ]
            cells += [str(_pick(rng, NASTY_NUMBERS, 200, 0.9)), "note"]
            rows.append(",".join(json.dumps(c) if ("," in c or '"' in c or "\n" in c) else c for c in cells))
        text = "\r\n".join(rows) + "\r\n"
        try:
            points = parse_points_csv(text)
        except FileFormatError as exc:
            assert len(str(exc)) < MESSAGE_MAX
            continue
        again = parse_points_csv(points_to_csv(points))
        assert _as_written(again) == _as_written(points)  # see _as_written
        assert points_to_csv(again) == points_to_csv(points)
        points_to_csv(points).encode("utf-8")  # what was accepted can be written

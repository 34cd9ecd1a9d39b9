"""The project-load fast path (stock JSON decoder, fast_point_from_fields, no double checks)
builds exactly what the careful path builds and refuses with the careful path's messages."""

from __future__ import annotations

import json
from collections.abc import Sequence

import pytest

from app.points.fields import FieldError, PointLimits
from app.points.ledger import PointLedger
from app.points.point import (
    FileFormatError,
    SyncState,
    fast_point_from_fields,
    is_valid_point,
    make_point,
    point_from_fields,
)
from app.points.project import _parse_project_exact, parse_project

GOOD = {
    "id": 7,
    "name": "原点",
    "x": 1.5,
    "y": -2.0,
    "z": 3.0,
    "a": 180.0,
    "b": 0.0,
    "c": 0.25,
    "e1": 0.0,
    "e2": 1.0,
    "e3": 0.0,
    "e4": 0.0,
    "e5": 0.0,
    "tool": 3,
    "note": "two\nlines",
}


def _doc(points: Sequence[object]) -> str:
    return json.dumps(
        {"format": "teachpad-project", "version": 1, "name": "t", "points": points, "plans": []},
        ensure_ascii=False,
    )


def test_fast_point_equals_careful_point() -> None:
    fast = fast_point_from_fields(GOOD, sync=SyncState.UNKNOWN)
    assert fast is not None
    careful = point_from_fields(GOOD, sync=SyncState.UNKNOWN)
    assert fast == careful and hash(fast) == hash(careful) and repr(fast) == repr(careful)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("id", -1),
        ("id", 10**6),
        ("id", True),
        ("id", 7.0),
        ("id", "7"),
        ("x", float("nan")),
        ("x", float("inf")),
        ("y", 1),
        ("z", "1.0"),
        ("e3", ""),
        ("e5", None),
        ("tool", 201),
        ("tool", -1),
        ("tool", True),
        ("name", None),
        ("name", "a\nb"),
        ("name", "x" * 201),
        ("note", "x" * 2001),
        ("note", "\ud800"),
        ("name", "\udfff"),
        ("c", 1e308),
    ],
)
def test_fast_path_leaves_the_unusual_to_the_careful_path(key: str, value: object) -> None:
    fields = {**GOOD, key: value}
    fast = fast_point_from_fields(fields)
    try:
        careful = point_from_fields(fields)
    except FieldError:
        assert fast is None  # never accepts what the careful path refuses
        return
    assert fast is None or fast == careful
    # accepted by the careful path (e.g. an int coordinate): the project load still gets it
    loaded = parse_project(_doc([fields]))
    assert loaded.ledger[0] == careful.__class__(**{**careful.__dict__, "sync": SyncState.UNKNOWN})


def test_missing_fields_take_the_careful_path() -> None:
    for key in ("id", "x", "c"):
        fields = dict(GOOD)
        del fields[key]
        assert fast_point_from_fields(fields) is None


def test_limits_apply_on_the_fast_path() -> None:
    assert fast_point_from_fields(GOOD, PointLimits(1, 5)) is None
    assert fast_point_from_fields(GOOD, PointLimits(1, 7)) is not None


def test_loaded_project_matches_the_careful_decoder() -> None:
    points = [dict(GOOD, id=i, name=f"p{i}") for i in range(1, 50)]
    points[3]["x"] = 400  # an int coordinate: careful path for that point
    points[4]["uploaded"] = {"time": "2025-01-31T09:00:00Z", "endpoint": "tcp 1.2.3.4:502"}
    points[5]["e1"] = "  "  # blank optional: default
    text = _doc(points)
    fast, exact = parse_project(text), _parse_project_exact(text, PointLimits(), path=None)
    assert list(fast.ledger) == list(exact.ledger)
    assert fast.upload_history == exact.upload_history
    assert all(p.sync is SyncState.UNKNOWN for p in fast.ledger)


@pytest.mark.parametrize(
    ("raw", "words"),
    [
        ('"x": 1e400', "too large"),
        ('"id": ' + "9" * 5000, "too large"),
        ('"name": "\\ud800"', "lone surrogate"),
        ('"x": "abc"', "is not a number"),
    ],
)
def test_bad_files_keep_their_messages(raw: str, words: str) -> None:
    fields = ", ".join(
        f'"{k}": {json.dumps(v, ensure_ascii=False)}' for k, v in GOOD.items() if k != raw.split('"')[1]
    )
    text = _doc([]).replace('"points": []', '"points": [{' + fields + ", " + raw + "}]")
    with pytest.raises(FileFormatError) as fast:
        parse_project(text, path="f.json")
    with pytest.raises(FileFormatError) as exact:
        _parse_project_exact(text, PointLimits(), path="f.json")
    assert words in str(fast.value) and str(fast.value) == str(exact.value)


def test_duplicate_id_is_refused_on_the_fast_path() -> None:
    with pytest.raises(FileFormatError, match="already used by points\\[0\\]"):
        parse_project(_doc([GOOD, GOOD]))


def test_ledger_quick_check_agrees_with_make_point() -> None:
    good = make_point(1, "a", (1.0, 2.0, 3.0, 4.0, 5.0, 6.0))
    assert is_valid_point(good)
    bad = good.__class__(**{**good.__dict__, "x": float("nan")})
    assert not is_valid_point(bad)
    with pytest.raises(FieldError):
        PointLedger([bad])
    assert len(PointLedger([good])) == 1


def test_upload_history_on_the_fast_path() -> None:
    good = dict(GOOD, uploaded={"time": "2025-01-31T09:00:00Z", "endpoint": "tcp 1.2.3.4:502"})
    project = parse_project(_doc([good]))
    assert project.upload_history[7].endpoint == "tcp 1.2.3.4:502"
    bad = dict(GOOD, uploaded={"time": 5, "endpoint": ""})
    with pytest.raises(FileFormatError) as fast:
        parse_project(_doc([bad]))
    with pytest.raises(FileFormatError) as exact:
        _parse_project_exact(_doc([bad]), PointLimits(), path=None)
    assert str(fast.value) == str(exact.value) and "points[0] (id 7) uploaded" in str(fast.value)

"""Project JSON and points CSV: round trips, refusals naming row and field, atomic save, autosave."""

from __future__ import annotations

import json
import os
import stat
from dataclasses import replace
from pathlib import Path

import pytest

from app.errors import InvalidInput
from app.plan.checks import check_plan, has_errors
from app.plan.segments import Plan, Segment
from app.points.atomic import atomic_write_bytes
from app.points.autosave import autosave_path, discard_autosave, find_autosave, save_autosave
from app.points.csv_io import parse_points_csv, points_to_csv
from app.points.fields import PointLimits
from app.points.ledger import PointLedger
from app.points.ledger_import import ImportMode
from app.points.point import FileFormatError, SyncState, make_point
from app.points.project import load_project, parse_project, read_points_csv, save_project, write_points_csv
from app.points.project_model import LastUpload, Project
from app.points.project_write import project_to_json

SAMPLES = Path(__file__).resolve().parents[2] / "resources" / "samples"
HEADER = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"


def sample_project() -> Project:
    ledger = PointLedger(
        [
            make_point(1, "原点", (400, 0, 450, 180, 0, 0), sync=SyncState.ON_CONTROLLER),
            make_point(
                2,
                '取料点, "A"',
                (450.125, -150, 250, 180, 0, 0),
                (1, 2, 3, 4, 5),
                tool=3,
                note="多行\n备注",
                sync=SyncState.FAILED,
                sync_error="bad point id",
            ),
            make_point(10000, "", (0.1, 1e-3, -3.5e5, -179.999, 90, 0), sync=SyncState.CHANGED),
        ]
    )
    plans = [
        Plan(
            "主程序",
            [
                Segment.line(2, 120.5),
                Segment.arc(1, 10000, 30, orientation_changes=False, ignore_middle=True, tool=3),
            ],
            loops=3,
        ),
        Plan("empty", [], loops=0),
    ]
    return Project(name="测试", ledger=ledger, plans=plans, description="d", created="2025-01-01T00:00:00Z")


# --- CSV -------------------------------------------------------------------------------------


def test_csv_round_trip_with_chinese_bom_quotes_and_newlines(tmp_path: Path) -> None:
    project = sample_project()
    path = tmp_path / "points.csv"
    write_points_csv(path, project.ledger)
    raw = path.read_bytes()
    assert raw.startswith(b"\xef\xbb\xbf" + HEADER.encode())
    assert "取料点".encode() in raw
    back = read_points_csv(path)
    for original, loaded in zip(project.ledger, back, strict=True):
        assert loaded.id == original.id and loaded.name == original.name and loaded.note == original.note
        assert (loaded.xyzabc, loaded.ext, loaded.tool) == (original.xyzabc, original.ext, original.tool)
    write_points_csv(path, project.ledger, bom=False)
    assert not path.read_bytes().startswith(b"\xef\xbb\xbf")
    assert [p.name for p in read_points_csv(path)] == [p.name for p in project.ledger]


def test_csv_minimal_columns_any_order_and_blank_lines() -> None:
    text = "\ufeffX, id ,y,z,a,b,c,Name\r\n\r\n1.5,3,2,3,180,0,0,点\r\n,,,,,,,\r\n2,4,0,0,0,0,0,\n"
    points = parse_points_csv(text)
    assert [(p.id, p.x, p.name, p.tool, p.ext) for p in points] == [
        (3, 1.5, "点", 200, (0.0,) * 5),
        (4, 2.0, "", 200, (0.0,) * 5),
    ]
    assert points[0].sync is SyncState.CHANGED


BAD_CSV = [
    (
        "bad number",
        f"{HEADER}\n1,a,0,0,0,0,0,0,0,0,0,0,0,200,\n2,b,abc,0,0,0,0,0,0,0,0,0,0,200,\n",
        3,
        "x",
        "'abc' is not a number",
    ),
    ("missing column", "id,name,x,y,z,a,b\n1,a,0,0,0,0,0\n", 1, "c", "missing"),
    (
        "duplicate id",
        f"{HEADER}\n1,a,0,0,0,0,0,0,0,0,0,0,0,200,\n1,b,0,0,0,0,0,0,0,0,0,0,0,200,\n",
        3,
        "id",
        "id 1 is already used on row 2",
    ),
    ("id out of range", f"{HEADER}\n10001,a,0,0,0,0,0,0,0,0,0,0,0,200,\n", 2, "id", "outside 0..10000"),
    ("negative id", f"{HEADER}\n-1,a,0,0,0,0,0,0,0,0,0,0,0,200,\n", 2, "id", "outside"),
    ("NaN", f"{HEADER}\n1,a,0,0,NaN,0,0,0,0,0,0,0,0,200,\n", 2, "z", "not a finite number"),
    ("inf", f"{HEADER}\n1,a,0,0,0,0,0,inf,0,0,0,0,0,200,\n", 2, "c", "not a finite number"),
    ("empty required", f"{HEADER}\n1,a,0,,0,0,0,0,0,0,0,0,0,200,\n", 2, "y", "the value is empty"),
    ("bad tool", f"{HEADER}\n1,a,0,0,0,0,0,0,0,0,0,0,0,300,\n", 2, "tool", "tool 300"),
    ("fractional id", f"{HEADER}\n1.5,a,0,0,0,0,0,0,0,0,0,0,0,200,\n", 2, "id", "not an integer"),
    ("truncated row", f"{HEADER}\n1,a,0,0,0,0,0,0,0,0,0,0,0,200,\n2,b,0,0,0", 3, None, "5 cells"),
    ("unknown column", "id,name,x,y,z,a,b,c,colour\n", 1, None, "unknown column 'colour'"),
    ("column twice", "id,x,y,z,a,b,c,x\n", 1, "x", "twice"),
    ("empty file", "\n\n", 1, None, "empty"),
    ("unclosed quote", f'{HEADER}\n1,"a,0,0,0,0,0,0,0,0,0,0,0,200,\n', 2, None, "not valid CSV"),
]


@pytest.mark.parametrize(("case", "text", "row", "column", "reason"), BAD_CSV, ids=[c[0] for c in BAD_CSV])
def test_bad_csv_is_refused_naming_row_and_column_and_ledger_unchanged(
    tmp_path: Path, case: str, text: str, row: int, column: str | None, reason: str
) -> None:
    path = tmp_path / "in.csv"
    path.write_text(text, encoding="utf-8")
    ledger = sample_project().ledger
    before, revision = ledger.snapshot(), ledger.revision
    with pytest.raises(FileFormatError) as info:
        ledger.import_points(read_points_csv(path), ImportMode.REPLACE)
    err = info.value
    assert isinstance(err, InvalidInput)
    assert (err.row, err.column) == (row, column)
    assert reason in str(err)
    assert f"row {row}" in str(err) and str(path) in str(err)
    if column:
        assert f"column '{column}'" in str(err)
    assert ledger.snapshot() == before and ledger.revision == revision


def test_csv_message_reads_like_the_issue() -> None:
    text = (
        f"{HEADER}\n"
        + "".join(f"{i},p,0,0,0,0,0,0,0,0,0,0,0,200,\n" for i in range(5))
        + "5,p,abc,0,0,0,0,0,0,0,0,0,0,200,\n"
    )
    with pytest.raises(FileFormatError, match=r"^row 7, column 'x': 'abc' is not a number$"):
        parse_points_csv(text)


def test_csv_not_utf8_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "gbk.csv"
    path.write_bytes(f"{HEADER}\n1,取料点,0,0,0,0,0,0,0,0,0,0,0,200,\n".encode("gbk"))
    with pytest.raises(FileFormatError, match="not UTF-8"):
        read_points_csv(path)


def test_csv_respects_id_limits_setting() -> None:
    with pytest.raises(FileFormatError, match=r"outside 1\.\.9999"):
        parse_points_csv(f"{HEADER}\n0,a,0,0,0,0,0,0,0,0,0,0,0,200,\n", PointLimits(1, 9999))


def test_points_to_csv_floats_round_trip_exactly() -> None:
    """A value that is no float32 (typed, computed) is written as its exact repr; one nearer 0
    than the table's 0.0005 reads 0 (app/points/number_text.py; float32 values: tests/points)."""
    p = make_point(1, pose=(0.1, 1 / 3, -0.001, 179.99999999999997, 0, 1e15))
    (back,) = parse_points_csv(points_to_csv([p]))
    assert back.xyzabc == p.xyzabc
    (back,) = parse_points_csv(points_to_csv([make_point(1, pose=(0.1, 1 / 3, -1e-300, 1e-7, 0, 1e15))]))
    assert back.xyzabc == (0.1, 1 / 3, 0.0, 0.0, 0.0, 1e15)


# --- JSON ------------------------------------------------------------------------------------


def test_project_round_trip(tmp_path: Path) -> None:
    project = sample_project()
    path = tmp_path / "p.teachpad.json"
    save_project(project, path)
    assert project.modified
    doc = json.loads(path.read_text(encoding="utf-8"))
    assert doc["format"] == "teachpad-project" and doc["version"] == 1
    assert "取料点" in path.read_text(encoding="utf-8")  # not \\u-escaped
    back = load_project(path)
    assert back.name == "测试" and back.description == "d" and back.created == project.created
    # a file cannot know what a controller holds: every loaded point is "unknown"
    assert back.ledger.snapshot() == tuple(
        replace(p, sync=SyncState.UNKNOWN, sync_error="") for p in project.ledger.snapshot()
    )
    assert '"sync"' not in path.read_text(encoding="utf-8")
    assert [(p.name, p.loops, p.segments) for p in back.plans] == [
        (p.name, p.loops, p.segments) for p in project.plans
    ]
    assert project_to_json(back) == project_to_json(project)


def _doc(**changes: object) -> dict[str, object]:
    doc: dict[str, object] = json.loads(project_to_json(sample_project()))
    doc.update(changes)
    return doc


def _point(**changes: object) -> dict[str, object]:
    p: dict[str, object] = {"id": 5, "name": "p", "x": 0, "y": 0, "z": 0, "a": 0, "b": 0, "c": 0}
    p.update(changes)
    return p


def _with_points(*points: dict[str, object]) -> str:
    return json.dumps(_doc(points=list(points), plans=[]))


BAD_JSON = [
    ("wrong version", json.dumps(_doc(version=2)), "field 'version'", "version 2 is not supported"),
    ("wrong format", json.dumps(_doc(format="other")), "field 'format'", "not a TeachPad project"),
    ("not JSON", "hello", "line 1, column 1", "not valid JSON"),
    ("truncated", project_to_json(sample_project())[:300], "line ", "not valid JSON"),
    ("top-level list", "[]", "", "expected a JSON object"),
    (
        "bad number",
        _with_points(_point(), _point(id=6, x="abc")),
        "points[1] (id 6), field 'x'",
        "'abc' is not a number",
    ),
    ("NaN", _with_points(_point(y=float("nan"))), "points[0] (id 5), field 'y'", "not a finite number"),
    (
        "duplicate id",
        _with_points(_point(), _point()),
        "points[1] (id 5), field 'id'",
        "already used by points[0]",
    ),
    ("id out of range", _with_points(_point(id=20000)), "field 'id'", "outside 0..10000"),
    (
        "missing column",
        _with_points({"id": 1, "x": 0, "y": 0, "z": 0, "a": 0, "b": 0}),
        "field 'c'",
        "is missing",
    ),
    ("bool as number", _with_points(_point(z=True)), "field 'z'", "not a number"),
    ("bad history", _with_points(_point(uploaded=[1])), "field 'uploaded'", "expected an object"),
    ("points not a list", json.dumps(_doc(points={})), "field 'points'", "expected a list"),
    (
        "arc without via",
        json.dumps(_doc(plans=[{"name": "p", "segments": [{"type": "arc", "end": 1}]}])),
        "plans[0] ('p') segment 1, field 'via'",
        "needs its middle point",
    ),
    (
        "line with via",
        json.dumps(_doc(plans=[{"name": "p", "segments": [{"type": "line", "end": 1, "via": 2}]}])),
        "field 'via'",
        "no middle point",
    ),
    (
        "bad kind",
        json.dumps(_doc(plans=[{"name": "p", "segments": [{"type": "spline", "end": 1}]}])),
        "field 'type'",
        "'line' or 'arc'",
    ),
    (
        "NaN speed",
        json.dumps(
            _doc(plans=[{"name": "p", "segments": [{"type": "line", "end": 1, "speed": float("nan")}]}])
        ),
        "field 'speed'",
        "finite",
    ),
    (
        "bad tool",
        json.dumps(_doc(plans=[{"name": "p", "segments": [{"type": "line", "end": 1, "tool": 205}]}])),
        "field 'tool'",
        "tool 205",
    ),
    (
        "bad loops",
        json.dumps(_doc(plans=[{"name": "p", "loops": -1, "segments": []}])),
        "field 'loops'",
        "is not 0",
    ),
    (
        "plan name twice",
        json.dumps(_doc(plans=[{"name": "p"}, {"name": "p"}])),
        "plans[1]",
        "another plan is named",
    ),
    ("plan without name", json.dumps(_doc(plans=[{"segments": []}])), "field 'name'", "needs a name"),
]


@pytest.mark.parametrize(("case", "text", "where", "reason"), BAD_JSON, ids=[c[0] for c in BAD_JSON])
def test_bad_project_is_refused_naming_where(
    tmp_path: Path, case: str, text: str, where: str, reason: str
) -> None:
    path = tmp_path / "bad.teachpad.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError) as info:
        load_project(path)
    message = str(info.value)
    assert message.startswith(str(path))
    assert where in message and reason in message, message


def test_missing_file_and_directory_are_refused(tmp_path: Path) -> None:
    with pytest.raises(FileFormatError, match="does not exist"):
        load_project(tmp_path / "nope.json")
    with pytest.raises(FileFormatError, match="directory"):
        load_project(tmp_path)


def test_loaded_points_are_unknown_and_upload_history_round_trips(tmp_path: Path) -> None:
    """Old files' "sync": "on-controller" is ignored; the upload history is kept, never "synced"."""
    text = _with_points(
        _point(sync="on-controller"), _point(id=6, sync="failed", sync_error="x"), _point(id=7, sync="bogus")
    )
    project = parse_project(text)
    assert [p.sync for p in project.ledger] == [SyncState.UNKNOWN] * 3
    assert project.upload_history == {}
    project.record_upload([5, 7], "tcp 10.0.0.5:502", when="2025-02-01T10:00:00Z")
    path = tmp_path / "h.teachpad.json"
    save_project(project, path)
    back = load_project(path)
    assert back.upload_history == project.upload_history
    assert back.upload_history[5] == LastUpload("2025-02-01T10:00:00Z", "tcp 10.0.0.5:502")
    assert all(p.sync is SyncState.UNKNOWN for p in back.ledger)


def test_unknown_keys_are_ignored_and_defaults_apply() -> None:
    text = json.dumps(
        {
            "format": "teachpad-project",
            "version": 1,
            "future": 1,
            "points": [{"id": 1, "x": 0, "y": 0, "z": 0, "a": 0, "b": 0, "c": 0, "colour": "red"}],
            "plans": [{"name": "p", "segments": [{"type": "line", "end": 1}]}],
        }
    )
    project = parse_project(text)
    assert project.name == "untitled"
    assert project.ledger[0].sync is SyncState.UNKNOWN and project.ledger[0].tool == 200
    assert project.plans[0].segments == [Segment.line(1)]


def test_project_plans_and_references() -> None:
    project = sample_project()
    assert project.references(1) == [("主程序", 1)]
    assert project.plan("主程序").loops == 3
    with pytest.raises(InvalidInput, match="no plan named"):
        project.plan("x")
    with pytest.raises(InvalidInput, match="already exists"):
        project.add_plan(Plan("empty"))
    assert project.unique_plan_name("empty") == "empty 2"
    rev = project.revision
    project.add_plan(Plan("b"))
    with pytest.raises(InvalidInput):
        project.rename_plan(2, "empty")
    project.rename_plan(2, "c")
    assert project.revision > rev
    changed = project.renumber_point(0, 7)
    assert changed == [("主程序", [1])]
    assert project.plan("主程序").segments[1].via_id == 7 and project.ledger[0].id == 7


# --- atomic save -------------------------------------------------------------------------------


def test_atomic_save_failure_mid_write_keeps_old_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "p.teachpad.json"
    save_project(sample_project(), path)
    old = path.read_bytes()
    real_write = os.write
    calls = {"n": 0}

    def failing_write(fd: int, data: bytes | memoryview) -> int:
        calls["n"] += 1
        if calls["n"] == 1:
            return real_write(fd, bytes(data[:100]))  # a short write, then the disk fills up
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "write", failing_write)
    big = sample_project()
    big.ledger.add("x" * 100)
    with pytest.raises(OSError, match="No space"):
        save_project(big, path)
    monkeypatch.undo()
    assert calls["n"] == 2
    assert path.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no temp file left
    assert path.read_bytes() == old and len(load_project(path).ledger) == len(sample_project().ledger)


@pytest.mark.parametrize("fail", ["fsync", "replace"])
def test_atomic_save_failure_before_rename_keeps_old_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, fail: str
) -> None:
    path = tmp_path / "f.bin"
    path.write_bytes(b"old")

    def boom(*args: object) -> None:
        raise OSError(5, f"{fail} failed")

    monkeypatch.setattr(os, fail, boom)
    with pytest.raises(OSError, match=f"{fail} failed"):
        atomic_write_bytes(path, b"new contents")
    monkeypatch.undo()
    assert path.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["f.bin"]


def test_atomic_save_replaces_and_keeps_mode(tmp_path: Path) -> None:
    path = tmp_path / "f.txt"
    atomic_write_bytes(path, b"one")
    assert path.read_bytes() == b"one"
    os.chmod(path, 0o640)
    atomic_write_bytes(path, b"two")
    assert path.read_bytes() == b"two"
    assert stat.S_IMODE(path.stat().st_mode) == 0o640


# --- autosave ----------------------------------------------------------------------------------


def _set_mtime(path: Path, seconds: float) -> None:
    os.utime(path, (seconds, seconds))


def test_autosave_path(tmp_path: Path) -> None:
    assert autosave_path(tmp_path / "demo.teachpad.json") == tmp_path / "demo.teachpad.autosave.json"
    assert autosave_path(tmp_path / "demo") == tmp_path / "demo.autosave.json"
    assert autosave_path(None, user_dir=tmp_path) == tmp_path / "untitled.autosave.json"


def test_autosave_newer_than_project_is_offered(tmp_path: Path) -> None:
    path = tmp_path / "demo.teachpad.json"
    project = sample_project()
    save_project(project, path)
    _set_mtime(path, 1_000_000)
    assert find_autosave(path) is None  # no autosave

    project.ledger.add("after the save")
    auto = save_autosave(project, path)
    _set_mtime(auto, 1_000_010)
    assert find_autosave(path) == auto
    assert len(load_project(auto).ledger) == len(project.ledger)

    _set_mtime(path, 1_000_020)  # the project was saved after the autosave
    assert find_autosave(path) is None

    _set_mtime(path, 1_000_000)
    auto.write_bytes(path.read_bytes())  # same content: nothing to recover
    _set_mtime(auto, 1_000_010)
    assert find_autosave(path) is None

    path.unlink()  # the project file is gone: offer the autosave
    assert find_autosave(path) == auto
    assert discard_autosave(path) and not auto.exists() and not discard_autosave(path)


def test_autosave_of_untitled_project(tmp_path: Path) -> None:
    user_dir = tmp_path / "state" / "teachpad"
    assert find_autosave(None, user_dir=user_dir) is None
    auto = save_autosave(sample_project(), None, user_dir=user_dir)
    assert auto.parent == user_dir and find_autosave(None, user_dir=user_dir) == auto


# --- samples ----------------------------------------------------------------------------------


def test_sample_project_and_csv() -> None:
    project = load_project(SAMPLES / "demo.teachpad.json")
    assert len(project.ledger) == 8 and len(project.plans) == 2
    assert any(any("\u4e00" <= ch <= "\u9fff" for ch in p.name) for p in project.ledger)
    for p in project.ledger:
        assert 300 <= p.x <= 500 and -200 <= p.y <= 200 and 200 <= p.z <= 500
        assert (p.a, p.b, p.c) == (180, 0, 0)
    for plan in project.plans:
        assert {s.kind.value for s in plan.segments} == {"line", "arc"}
        issues = check_plan(plan, project.ledger, current_pose=project.ledger.point(1))
        assert not has_errors(issues), issues
    csv_points = read_points_csv(SAMPLES / "demo_points.csv")
    assert [(p.id, p.name, p.xyzabc) for p in csv_points] == [
        (p.id, p.name, p.xyzabc) for p in project.ledger
    ]

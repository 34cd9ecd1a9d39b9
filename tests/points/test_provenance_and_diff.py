"""Point provenance (kept in the project, stamped by a CSV import) and the points diff
(``app/points/diff.py``, ``teachpad-cli points diff``)."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import pytest

from app.cli.main import main as cli_main
from app.points.diff import ChangeKind, diff_points, orientation_change_deg
from app.points.ledger import PointLedger
from app.points.ledger_import import ImportMode
from app.points.point import TempPoint, make_point, with_provenance
from app.points.project import load_project, read_points_csv, save_project, write_points_csv
from app.points.project_model import Project
from app.points.provenance import UNKNOWN_PROVENANCE, Origin, edited, stamp

SAMPLES = Path(__file__).resolve().parents[2] / "resources" / "samples"


def _point(
    pid: int, x: float = 400.0, a: float = 180.0, b: float = 0.0, c: float = 0.0, tool: int = 200
) -> TempPoint:
    return make_point(pid, f"p{pid}", (x, 0.0, 450.0, a, b, c), tool=tool)


# --- provenance -------------------------------------------------------------------------------


def test_provenance_survives_save_and_load(tmp_path: Path) -> None:
    taught = stamp(
        Origin.TAUGHT,
        controller="tcp 10.0.0.5:502 unit 1",
        software="TeachPad 9.9",
        when="2026-01-02T03:04:05Z",
    )
    typed = edited(
        stamp(Origin.TYPED, software="TeachPad 9.9", when="2026-01-01T00:00:00Z"), when="2026-01-03T00:00:00Z"
    )
    imported = stamp(
        Origin.IMPORTED, file="cell 3.csv", software="teachpad-cli 9.9", when="2026-01-04T00:00:00Z"
    )
    points = [
        with_provenance(_point(1), taught),
        with_provenance(_point(2), typed),
        with_provenance(_point(3), imported),
        _point(4),
    ]
    path = tmp_path / "p.teachpad.json"
    save_project(Project(ledger=PointLedger(points)), path)
    loaded = {p.id: p.made for p in load_project(path).ledger}
    assert loaded == {1: taught, 2: typed, 3: imported, 4: UNKNOWN_PROVENANCE}
    raw = json.loads(path.read_text(encoding="utf-8"))["points"]
    assert raw[0]["made"] == {
        "how": "taught",
        "time": "2026-01-02T03:04:05Z",
        "controller": "tcp 10.0.0.5:502 unit 1",
        "software": "TeachPad 9.9",
    }
    assert "made" not in raw[3]  # unknown: nothing written, the file reads as before


def test_an_old_project_opens_with_provenance_unknown() -> None:
    project = load_project(SAMPLES / "demo.teachpad.json")  # written before provenance existed
    assert len(project.ledger) > 0
    assert all(p.made == UNKNOWN_PROVENANCE and p.made.origin is Origin.UNKNOWN for p in project.ledger)


def test_provenance_is_not_part_of_a_points_equality() -> None:
    plain = _point(1)
    assert with_provenance(plain, stamp(Origin.TAUGHT)) == plain


def test_a_bad_made_key_is_refused_in_one_line(tmp_path: Path) -> None:
    path = tmp_path / "bad.teachpad.json"
    doc = json.loads((SAMPLES / "demo.teachpad.json").read_text(encoding="utf-8"))
    doc["points"][1]["made"] = "yesterday"
    path.write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(Exception) as info:
        load_project(path)
    text = str(info.value)
    assert "\n" not in text and "points[1]" in text and "'made'" in text


def test_an_unknown_how_from_a_newer_teachpad_reads_as_unknown(tmp_path: Path) -> None:
    path = tmp_path / "newer.teachpad.json"
    doc = json.loads((SAMPLES / "demo.teachpad.json").read_text(encoding="utf-8"))
    doc["points"][0]["made"] = {"how": "scanned", "time": "2030-01-01T00:00:00Z", "extra": [1]}
    path.write_text(json.dumps(doc), encoding="utf-8")
    made = load_project(path).ledger[0].made
    assert made.origin is Origin.UNKNOWN and made.time == "2030-01-01T00:00:00Z"


def test_a_csv_import_records_the_file(tmp_path: Path) -> None:
    csv_path = tmp_path / "from the cell.csv"
    write_points_csv(csv_path, [_point(1), _point(2)])
    points = read_points_csv(csv_path)
    assert {p.made.origin for p in points} == {Origin.IMPORTED}
    assert {p.made.file for p in points} == {"from the cell.csv"}
    assert all(p.made.time and p.made.software.startswith("TeachPad") for p in points)
    # ... and the project keeps it
    project = Project(ledger=PointLedger())
    project.ledger.import_points(points, ImportMode.REPLACE)
    save_project(project, tmp_path / "p.teachpad.json")
    assert load_project(tmp_path / "p.teachpad.json").ledger[0].made.file == "from the cell.csv"


def test_an_import_that_changes_nothing_keeps_the_points_history() -> None:
    taught = stamp(Origin.TAUGHT, when="2026-01-01T00:00:00Z")
    ledger = PointLedger([with_provenance(_point(1), taught), with_provenance(_point(2), taught)])
    imported = stamp(Origin.IMPORTED, file="x.csv")
    ledger.import_points([with_provenance(_point(1), imported), with_provenance(_point(2, x=1.0), imported)])
    assert ledger.point(1).made == taught  # the same point: the import did not make it
    assert ledger.point(2).made == imported


def test_the_cli_import_records_the_file(tmp_path: Path) -> None:
    csv_path = tmp_path / "in.csv"
    write_points_csv(csv_path, [_point(7)])
    project = tmp_path / "new.teachpad.json"
    assert cli_main(["points", "import", str(project), "--csv", str(csv_path)]) == 0
    made = load_project(project).ledger[0].made
    assert (made.origin, made.file) == (Origin.IMPORTED, "in.csv")


# --- diff -------------------------------------------------------------------------------------


@pytest.mark.parametrize(("moved_mm", "found"), [(0.2, True), (0.05, False)])
def test_a_move_over_the_tolerance_is_found_and_one_under_it_is_not(moved_mm: float, found: bool) -> None:
    a = [_point(1), _point(2)]
    b = [_point(1, x=400.0 + moved_mm), _point(2)]
    diff = diff_points(a, b, tol_mm=0.1, tol_deg=0.1)
    assert diff.differ is found
    if found:
        (change,) = diff.changes
        assert change.kind is ChangeKind.MOVED and change.point_id == 1
        assert change.distance_mm == pytest.approx(moved_mm, abs=1e-9)
        assert change.delta == pytest.approx((moved_mm, 0.0, 0.0), abs=1e-9)
    else:
        assert diff.same == 2


@pytest.mark.parametrize(
    ("before", "after", "angle"),
    [
        ((179.95, 0.0, 0.0), (-179.95, 0.0, 0.0), 0.1),  # A across +-180: 0.1 deg, not 359.9
        ((180.0, 0.0, 0.0), (-180.0, 0.0, 0.0), 0.0),
        ((0.0, 0.0, 179.9), (0.0, 0.0, -179.9), 0.2),  # C across +-180
        ((0.0, 0.0, 10.0), (0.0, 0.0, 10.3), 0.3),
    ],
)
def test_orientation_changes_across_the_wrap_are_measured_right(
    before: tuple[float, float, float], after: tuple[float, float, float], angle: float
) -> None:
    a, b = _point(1, a=before[0], b=before[1], c=before[2]), _point(1, a=after[0], b=after[1], c=after[2])
    assert orientation_change_deg(a, b) == pytest.approx(angle, abs=1e-6)
    diff = diff_points([a], [b], tol_deg=0.15)
    assert diff.differ is (angle > 0.15)


def test_the_same_orientation_in_another_abc_triple_is_no_change() -> None:
    # (A, B, C) and (A+180, 180-B, C+180) are one rotation
    a = _point(1, a=10.0, b=20.0, c=30.0)
    b = _point(1, a=-170.0, b=160.0, c=-150.0)
    assert orientation_change_deg(a, b) == pytest.approx(0.0, abs=1e-6)


def test_added_removed_and_tool() -> None:
    a = [_point(1), _point(2), _point(3)]
    b = [_point(2), _point(3, tool=4), _point(9)]
    diff = diff_points(a, b)
    assert [(c.kind, c.point_id) for c in diff.changes] == [
        (ChangeKind.REMOVED, 1),
        (ChangeKind.TOOL, 3),
        (ChangeKind.ADDED, 9),
    ]
    assert diff.same == 1


def test_a_negative_or_nan_tolerance_is_refused() -> None:
    with pytest.raises(ValueError, match="tolerance"):
        diff_points([], [], tol_mm=-1.0)
    with pytest.raises(ValueError, match="tolerance"):
        diff_points([], [], tol_deg=math.nan)


# --- teachpad-cli points diff -----------------------------------------------------------------


@pytest.fixture
def demo(tmp_path: Path) -> Path:
    path = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", path)
    return path


def _moved_copy(demo: Path, tmp_path: Path, dx: float) -> Path:
    project = load_project(demo)
    row = 1
    project.ledger.set_field(row, "x", project.ledger[row].x + dx)
    out = tmp_path / "moved.teachpad.json"
    save_project(project, out)
    return out


def test_cli_diff_finds_a_point_moved_02_mm_over_01(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    other = _moved_copy(demo, tmp_path, 0.2)
    assert cli_main(["points", "diff", str(demo), str(other), "--tol-mm", "0.1"]) == 1
    out = capsys.readouterr().out
    moved = [line for line in out.splitlines() if line.startswith("moved")]
    assert len(moved) == 1 and "P2" in moved[0] and "0.200 mm" in moved[0]
    assert "1 difference over 0.1 mm / 0.1°" in out


def test_cli_diff_of_a_005_mm_move_says_the_same(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    other = _moved_copy(demo, tmp_path, 0.05)
    assert cli_main(["points", "diff", str(demo), str(other)]) == 0
    assert "the same within 0.1 mm / 0.1°" in capsys.readouterr().out


def test_cli_diff_a_project_against_a_csv(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    project = load_project(demo)
    points = list(project.ledger)[1:]  # the first one removed
    points.append(make_point(77, "new", (1.0, 2.0, 3.0, 0.0, 0.0, 0.0)))
    csv_path = tmp_path / "points.csv"
    write_points_csv(csv_path, points)
    assert cli_main(["points", "diff", str(demo), str(csv_path)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert any(line.startswith("removed") and "P1" in line for line in lines)
    assert any(line.startswith("added") and "P77 'new'" in line for line in lines)


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        (
            "bad.teachpad.json",
            '{"format": "teachpad-project", "version": 1, "points": [{"id": 1, "x": "abc"',
            "not valid JSON",
        ),
        ("bad.csv", "id,x,y,z,a,b,c\n1,abc,0,0,0,0,0\n", "'abc' is not a number"),
        ("gbk.csv", None, "not UTF-8"),
        ("missing.csv", "", "does not exist"),
    ],
)
def test_cli_diff_of_a_malformed_file_says_one_clear_line(
    demo: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, content: str | None, words: str
) -> None:
    path = tmp_path / name
    if content is None:
        path.write_bytes("id,x,y,z,a,b,c\n1,0,0,0,0,0,0,名\n".encode("gbk"))
    elif name != "missing.csv":
        path.write_text(content, encoding="utf-8")
    assert cli_main(["points", "diff", str(demo), str(path)]) == 2
    captured = capsys.readouterr()
    err_lines = captured.err.strip().splitlines()
    assert len(err_lines) == 1 and words in err_lines[0] and name in err_lines[0]
    assert "Traceback" not in captured.err and captured.out == ""

"""``points import`` never writes a project TeachPad then refuses to open (issue 19 section 6):
the size the project would have is checked before the write (the read limit lowered here)."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.points import atomic
from app.points.project import load_project
from tests.cli.test_cli import one_line_error

LIMIT = 20_000  # bytes TeachPad reads (64 MB in the product)


def _csv(path: Path, n: int, first: int = 1) -> Path:
    header = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
    rows = [f"{i},P{i},{300 + i},{-i},400,180,0,{i % 90},0,0,0,0,0,200," for i in range(first, first + n)]
    path.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    return path


def test_an_import_the_project_could_not_be_read_back_from_is_refused_before_the_write(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(atomic, "MAX_FILE_BYTES", LIMIT)
    project = tmp_path / "cell.teachpad.json"
    assert main(["points", "import", str(project), "--csv", str(_csv(tmp_path / "few.csv", 10))]) == 0
    saved = project.read_bytes()
    big = _csv(tmp_path / "many.csv", 400, first=100)
    assert big.stat().st_size < LIMIT  # the CSV itself is readable: the project would not be
    capsys.readouterr()
    code = main(["points", "import", str(project), "--csv", str(big), "--merge"])
    err = capsys.readouterr().err
    assert code == ExitCode.FAILED
    line = one_line_error(err)
    assert "not saved: the project would be" in line and f"more than TeachPad opens ({LIMIT} bytes)" in line
    assert project.read_bytes() == saved  # untouched, and TeachPad still opens it
    assert len(load_project(project).ledger) == 10
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".teachpad-tmp")] == []
    fresh = tmp_path / "fresh.teachpad.json"
    assert main(["points", "import", str(fresh), "--csv", str(big)]) == ExitCode.FAILED
    assert not fresh.exists()


def test_what_is_written_is_always_read_back(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atomic, "MAX_FILE_BYTES", LIMIT)
    project = tmp_path / "cell.teachpad.json"
    for n in (50, 100, 150, 200):  # up to the limit, each import is written or refused, never broken
        main(["points", "import", str(project), "--csv", str(_csv(tmp_path / f"p{n}.csv", n))])
        assert project.stat().st_size <= LIMIT
        load_project(project)

"""The watch list in the project file: round trip, an old project opens, bad entries refused."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from app.points.point import FileFormatError
from app.points.project import load_project, parse_project, save_project
from app.points.project_model import Project
from app.watchlist.entry import Source, ValueType, WatchEntry

SAMPLE = Path(__file__).resolve().parents[2] / "resources" / "samples" / "demo.teachpad.json"

ENTRIES = (
    WatchEntry.make(Source.GV, 10, name="工具长度 tool length"),
    WatchEntry.make(Source.REGISTER, 562, ValueType.BITS, "alarms"),
    WatchEntry.make(Source.GV, 11, ValueType.INT16),
)


def test_round_trip(tmp_path: Path) -> None:
    project = Project(name="cell")
    before = project.revision
    project.set_watch_list(ENTRIES)
    assert project.revision != before  # a change of the project (dirty)
    path = tmp_path / "cell.teachpad.json"
    save_project(project, path)
    doc = json.loads(path.read_text(encoding="utf-8"))
    assert doc["version"] == 1  # extended compatibly: the version stays 1
    assert doc["watch_list"][1] == {"source": "reg", "number": 562, "type": "bits", "name": "alarms"}
    assert load_project(path).watch_list == ENTRIES


def test_an_old_project_opens_with_an_empty_watch_list(tmp_path: Path) -> None:
    old = json.loads(SAMPLE.read_text(encoding="utf-8-sig"))
    assert "watch_list" not in old
    project = load_project(SAMPLE)
    assert project.watch_list == ()
    assert len(project.ledger) > 0
    path = tmp_path / "old.teachpad.json"
    save_project(project, path)
    assert "watch_list" not in json.loads(path.read_text(encoding="utf-8"))  # written as before


@pytest.mark.parametrize(
    ("entry", "words"),
    [
        (
            {"source": "gv", "number": 40000, "type": "float32"},
            "watch_list[0], field 'number': GV 40000 is out of range",
        ),
        (
            {"source": "gv", "number": 1, "type": "double"},
            "watch_list[0], field 'type': unknown type 'double'",
        ),
        ({"source": "coil", "number": 1}, "watch_list[0], field 'source': unknown source 'coil'"),
        ({"source": "reg", "number": "x"}, "watch_list[0], field 'number'"),
        ({"source": "reg", "number": 3, "name": 5}, "watch_list[0], field 'name'"),
    ],
)
def test_a_bad_entry_is_refused_naming_its_place(entry: dict[str, object], words: str) -> None:
    doc = {"format": "teachpad-project", "version": 1, "watch_list": [entry]}
    with pytest.raises(FileFormatError) as caught:
        parse_project(json.dumps(doc), path="p.teachpad.json")
    assert words in str(caught.value)

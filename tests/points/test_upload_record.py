"""The upload record (app/points/upload_record.py): what it proves and what it refuses to."""

from __future__ import annotations

from pathlib import Path

import pytest

from app.link.types import ControllerIdentity
from app.points.point import FileFormatError, make_point
from app.points.upload_record import UploadRecord, load_record, record_path, save_record

HERE = ControllerIdentity("127.0.0.1:502", 1, "low_first", 99, 4242.0)


def test_a_record_round_trips_and_holds_only_the_same_pose_and_tool(tmp_path: Path) -> None:
    p1 = make_point(1, "a", (1, 2, 3, 4, 5, 6), tool=3)
    record = UploadRecord(HERE)
    record.confirm([p1])
    where = record_path(tmp_path / "cell.teachpad.json")
    assert where.name == "cell.teachpad.json.upload-record.json"
    save_record(where, record)
    back = load_record(where)
    assert back is not None and back.identity == HERE and back.holds(p1)
    assert not back.holds(make_point(1, "a", (1, 2, 3.5, 4, 5, 6), tool=3))  # moved
    assert not back.holds(make_point(1, "a", (1, 2, 3, 4, 5, 6), tool=4))  # another tool frame
    assert not back.holds(make_point(2, "b", (1, 2, 3, 4, 5, 6), tool=3))  # never confirmed


@pytest.mark.parametrize(
    "here",
    [
        ControllerIdentity("127.0.0.1:503", 1, "low_first", 99, 4242.0),  # another endpoint
        ControllerIdentity("127.0.0.1:502", 2, "low_first", 99, 4242.0),  # another unit
        ControllerIdentity("127.0.0.1:502", 1, "high_first", 99, 4242.0),  # another word order
        ControllerIdentity("127.0.0.1:502", 1, "low_first", 98, 4242.0),  # another canary GV
        ControllerIdentity("127.0.0.1:502", 1, "low_first", 99, 4243.0),  # another token: a restart
    ],
)
def test_only_the_same_boot_is_the_same_boot(here: ControllerIdentity) -> None:
    assert UploadRecord(HERE).same_boot(HERE)
    assert not UploadRecord(HERE).same_boot(here)
    void = ControllerIdentity("127.0.0.1:502", 1, "low_first", 99, None)
    assert not UploadRecord(void).same_boot(void)  # a voided record (after a restart) proves nothing


@pytest.mark.parametrize(
    "text",
    [
        "not json",
        '{"format": "teachpad-project", "version": 1}',
        '{"format": "teachpad-upload-record", "version": 2, "controller": {}, "points": []}',
        '{"format": "teachpad-upload-record", "version": 1, "controller": {"endpoint": "x", "unit": 1, '
        '"word_order": "low_first", "canary_gv": 99, "token": 5}, "points": [[1, 2, 3]]}',
        '{"format": "teachpad-upload-record", "version": 1, "controller": {"endpoint": "x", "unit": true, '
        '"word_order": "low_first", "canary_gv": 99, "token": 5}, "points": []}',
    ],
)
def test_a_malformed_record_is_refused_in_words(tmp_path: Path, text: str) -> None:
    where = tmp_path / "x.upload-record.json"
    where.write_text(text, encoding="utf-8")
    with pytest.raises(FileFormatError, match="not a TeachPad upload record"):
        load_record(where)
    assert load_record(tmp_path / "missing.json") is None

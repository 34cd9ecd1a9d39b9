"""The point ledger: validation, edits, sync states, search, upload bookkeeping."""

from __future__ import annotations

import math

import pytest

from app.errors import InvalidInput
from app.models import Pose
from app.points.fields import FieldError, PointLimits
from app.points.ledger import PointLedger
from app.points.ledger_import import ImportMode
from app.points.point import SyncState, make_point, point_from_pose
from app.points.upload import parse_id_list
from app.protocol.registers import TOOL_NONE

ON = SyncState.ON_CONTROLLER


def ledger3() -> PointLedger:
    return PointLedger(
        [
            make_point(1, "原点", (400, 0, 450, 180, 0, 0), sync=ON),
            make_point(2, "Pick A", (450, -150, 250, 180, 0, 0), sync=ON),
            make_point(5, "pick B", (450, 150, 250, 180, 0, 0), tool=0, sync=SyncState.CHANGED),
        ]
    )


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"point_id": -1}, "id"),
        ({"point_id": 10001}, "id"),
        ({"point_id": 1.5}, "id"),
        ({"point_id": True}, "id"),
        ({"pose": (math.nan, 0, 0, 0, 0, 0)}, "x"),
        ({"pose": (0, math.inf, 0, 0, 0, 0)}, "y"),
        ({"pose": (0, 0, 0, 0, 0, "-inf")}, "c"),
        ({"pose": (0, 0, "abc", 0, 0, 0)}, "z"),
        ({"pose": (0, 0, 0)}, "pose"),
        ({"ext": (0, 0, 0, 0, math.nan)}, "e5"),
        ({"tool": 201}, "tool"),
        ({"tool": -1}, "tool"),
        ({"name": "two\nlines"}, "name"),
        ({"name": 5}, "name"),
    ],
)
def test_make_point_refuses_bad_values_naming_the_field(kwargs: dict[str, object], field: str) -> None:
    args: dict[str, object] = {"point_id": 1, "name": "p", "pose": (0,) * 6}
    args.update(kwargs)
    point_id = args.pop("point_id")
    with pytest.raises(FieldError) as info:
        make_point(point_id, **args)  # type: ignore[arg-type]
    assert info.value.field == field
    assert isinstance(info.value, InvalidInput)


def test_make_point_accepts_text_and_limits_setting() -> None:
    p = make_point("7", "x", ("1.5", "2", "3e2", "180", "0", "-0"), tool="199")
    assert p.xyzabc == (1.5, 2.0, 300.0, 180.0, 0.0, 0.0)
    assert p.tool == 199 and p.id == 7
    assert make_point(0, tool=TOOL_NONE).tool == 200
    with pytest.raises(FieldError):
        make_point(0, limits=PointLimits(1, 9999))
    assert make_point(10000).id == 10000
    with pytest.raises(FieldError):
        make_point(10000, limits=PointLimits(0, 9999))


def test_point_from_pose_keeps_external_axes() -> None:
    p = point_from_pose(3, Pose(1, 2, 3, 4, 5, 6, ext=(7, 8, 9, 10, 11)), "here")
    assert p.xyzabc == (1, 2, 3, 4, 5, 6) and p.ext == (7, 8, 9, 10, 11)
    assert p.sync is SyncState.CHANGED


def test_add_uses_next_free_id_and_new_points_need_upload() -> None:
    ledger = ledger3()
    assert ledger.next_free_id() == 0
    assert ledger.next_free_id(after=1) == 3
    assert ledger.next_free_id(after=5) == 6
    row = ledger.add("new", (1, 2, 3, 4, 5, 6))
    assert row == 3 and ledger[3].id == 0 and ledger[3].sync is SyncState.CHANGED
    row = ledger.add("front", point_id=3, row=0)
    assert row == 0 and ledger.ids() == [3, 1, 2, 5, 0]
    with pytest.raises(FieldError, match="already used"):
        ledger.add("dup", point_id=1)


def test_changing_the_id_range_setting() -> None:
    ledger = ledger3()
    with pytest.raises(InvalidInput, match=r"outside 2\.\.9999: 1"):
        ledger.set_limits(PointLimits(2, 9999))
    ledger.set_limits(PointLimits(1, 5))
    assert ledger.limits.id_max == 5
    with pytest.raises(FieldError, match="outside"):
        ledger.add(point_id=6)


def test_next_free_id_when_full() -> None:
    ledger = PointLedger([make_point(i, limits=PointLimits(0, 2)) for i in range(3)], PointLimits(0, 2))
    with pytest.raises(InvalidInput, match="no free point id"):
        ledger.next_free_id()


def test_duplicate_remove_move_and_their_undo() -> None:
    ledger = ledger3()
    row = ledger.duplicate(0)
    assert row == 1
    copy = ledger[1]
    assert copy.id == 3 and copy.name == "原点" and copy.xyzabc == ledger[0].xyzabc
    assert copy.sync is SyncState.CHANGED
    removed = ledger.remove(1)
    assert removed == copy and ledger.ids() == [1, 2, 5]

    before = ledger.snapshot()
    gone = ledger.remove_rows([2, 0])
    assert [(r, p.id) for r, p in gone] == [(0, 1), (2, 5)]
    assert ledger.ids() == [2]
    for r, p in gone:  # undo
        ledger.insert(r, p)
    assert ledger.snapshot() == before

    ledger.move(0, 2)
    assert ledger.ids() == [2, 5, 1]
    ledger.move(2, 0)
    assert ledger.snapshot() == before
    with pytest.raises(InvalidInput):
        ledger.move(0, 3)


def test_editing_pose_marks_changed_but_name_does_not() -> None:
    ledger = ledger3()
    edit = ledger.set_field(0, "name", "home 原点")
    assert edit.new.sync is ON and edit.changed_fields == ("name",)
    edit = ledger.set_field(0, "e2", "12.5")
    assert edit.new.sync is ON and edit.new.ext[1] == 12.5
    edit = ledger.set_field(0, "x", "401.25")
    assert ledger[0].x == 401.25 and ledger[0].sync is SyncState.CHANGED
    assert set(edit.changed_fields) == {"x", "sync"}
    ledger.replace(0, edit.old)  # undo restores the sync state too
    assert ledger[0].sync is ON and ledger[0].x == 400
    ledger.set_field(1, "tool", 3)
    assert ledger[1].sync is SyncState.CHANGED
    same = ledger.set_field(2, "y", 150)
    assert same.old == same.new


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("x", "abc", "'abc' is not a number"),
        ("x", "nan", "finite"),
        ("a", math.inf, "finite"),
        ("id", 2, "already used"),
        ("id", 10001, "outside"),
        ("tool", 250, "tool 250"),
        ("sync", "x", "no such field"),
    ],
)
def test_refused_edit_leaves_ledger_unchanged(field: str, value: object, match: str) -> None:
    ledger = ledger3()
    before, revision = ledger.snapshot(), ledger.revision
    with pytest.raises(InvalidInput, match=match):
        ledger.set_field(0, field, value)
    assert ledger.snapshot() == before and ledger.revision == revision


def test_set_pose_touch_up() -> None:
    ledger = ledger3()
    edit = ledger.set_pose(1, (1, 2, 3, 4, 5, 6), (1, 1, 1, 1, 1))
    assert ledger[1].xyzabc == (1, 2, 3, 4, 5, 6) and ledger[1].ext == (1, 1, 1, 1, 1)
    assert edit.new.sync is SyncState.CHANGED
    with pytest.raises(FieldError, match="finite"):
        ledger.set_pose(1, (1, 2, math.nan, 4, 5, 6))
    assert ledger[1].z == 3


def test_sync_states_and_mark_all_unknown() -> None:
    ledger = ledger3()
    ledger.set_sync(2, SyncState.FAILED, "bad point id")
    assert ledger.get(2).sync_error == "bad point id"  # type: ignore[union-attr]
    rows = ledger.mark_all_unknown()
    assert rows == [0, 1]
    assert [p.sync for p in ledger] == [SyncState.UNKNOWN, SyncState.UNKNOWN, SyncState.CHANGED]
    assert ledger[1].sync_error == ""
    assert ledger.mark_all_unknown() == []
    assert [p.id for p in ledger.needing_upload()] == [1, 2, 5]
    with pytest.raises(InvalidInput):
        ledger.set_sync(99, ON)


def test_find_by_id_and_name() -> None:
    ledger = ledger3()
    assert ledger.find("5") == [2]
    assert ledger.find("pick") == [1, 2]
    assert ledger.find("PICK b") == [2]
    assert ledger.find("原") == [0]
    assert ledger.find("  ") == []
    assert ledger.find("1") == [0]
    assert ledger.get(3) is None and 5 in ledger and "5" not in ledger


def test_revision_counts_changes() -> None:
    ledger = ledger3()
    assert ledger.revision == 0
    ledger.set_field(0, "note", "n")
    ledger.set_sync(1, SyncState.UNKNOWN)
    assert ledger.revision == 2


def test_replace_all_checks_everything_first() -> None:
    ledger = ledger3()
    before = ledger.snapshot()
    with pytest.raises(InvalidInput, match="id 1 is already used"):
        ledger.replace_all([make_point(1), make_point(2), make_point(1)])
    assert ledger.snapshot() == before


def test_import_keeps_sync_of_identical_points() -> None:
    ledger = ledger3()
    incoming = [
        make_point(1, "原点 renamed", (400, 0, 450, 180, 0, 0)),  # same on the controller
        make_point(2, "Pick A", (451, -150, 250, 180, 0, 0)),  # moved
        make_point(9, "new", (0, 0, 0, 0, 0, 0)),
    ]
    merged = PointLedger(ledger.snapshot())
    report = merged.import_points(incoming, ImportMode.MERGE)
    assert (report.added, report.updated, report.unchanged, report.removed) == (1, 2, 0, 0)
    assert merged.ids() == [1, 2, 5, 9]
    assert [p.sync for p in merged] == [ON, SyncState.CHANGED, SyncState.CHANGED, SyncState.CHANGED]
    assert merged[0].name == "原点 renamed"

    report = ledger.import_points(incoming, ImportMode.REPLACE)
    assert ledger.ids() == [1, 2, 9] and report.removed == 1
    with pytest.raises(InvalidInput, match="appears twice"):
        ledger.import_points([make_point(3), make_point(3)])


def test_parse_id_list() -> None:
    assert parse_id_list("1,2,5-9") == [1, 2, 5, 6, 7, 8, 9]
    assert parse_id_list(" 3 , 3,1-2 ") == [3, 1, 2]
    for bad in ("a", "5-1", "1-", "1;2"):
        with pytest.raises(InvalidInput):
            parse_id_list(bad)

"""The Chinese UI says a refused project file, a refused import and a refused segment edit in
Chinese (issue 9): the real ProjectController and SegmentTableModel with the shipped .qm."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QTranslator
from PySide6.QtGui import QUndoStack

from app.points.ledger_import import ImportMode
from app.points.project import load_project
from tests.ui.controllers.test_project_controller import SAMPLES, FakeDialogs
from tests.ui.test_messages import QM, assert_chinese
from ui.controllers.project_controller import ProjectController
from ui.models.plan_columns import COL_END, COL_KIND, COL_SPEED, COL_VIA
from ui.models.segment_model import SegmentTableModel


@pytest.fixture
def zh(qapp: object) -> Iterator[None]:
    translator = QTranslator()
    assert translator.load(str(QM))
    QCoreApplication.installTranslator(translator)
    yield
    QCoreApplication.removeTranslator(translator)


@pytest.fixture
def controller(qtbot: Any, zh: None, tmp_path: Path) -> Iterator[tuple[ProjectController, FakeDialogs]]:
    target = tmp_path / "demo.teachpad.json"
    shutil.copy(SAMPLES / "demo.teachpad.json", target)
    dialogs = FakeDialogs()
    ctl = ProjectController(
        load_project(target), target, dialogs=dialogs, autosave_interval=0, autosave_dir=tmp_path / "user"
    )
    yield ctl, dialogs
    ctl.close()


Controller = tuple[ProjectController, FakeDialogs]


def test_a_malformed_project_is_refused_in_chinese(
    qtbot: Any, controller: Controller, tmp_path: Path
) -> None:
    ctl, dialogs = controller
    before = ctl.project
    bad = tmp_path / "坏.teachpad.json"
    text = (SAMPLES / "demo.teachpad.json").read_text(encoding="utf-8")
    bad.write_text(text.replace('"type": "line"', '"type": "circle"', 1), encoding="utf-8")
    assert not ctl.open_file(bad)
    title, shown = dialogs.errors[-1]
    assert title == "无法打开工程"
    assert shown == (
        "坏.teachpad.json：第 1 条轨迹“pick and place”第 1 段，字段“type”：'circle' 不是直线或圆弧"
    ), shown
    assert ctl.project is before  # nothing half replaced
    bad.write_text('{"format": ', encoding="utf-8")
    assert not ctl.open_file(bad)
    assert dialogs.errors[-1][1] == "坏.teachpad.json：第 1 行第 12 列：不是有效的 JSON"
    assert not ctl.open_file(tmp_path / "没有.teachpad.json")
    assert dialogs.errors[-1][1] == "没有.teachpad.json：文件不存在"


def test_an_import_reports_and_refuses_in_chinese(qtbot: Any, controller: Controller, tmp_path: Path) -> None:
    ctl, dialogs = controller
    bad = tmp_path / "点.csv"
    bad.write_text('id,name,x,y,z,a,b,c\n1,"a,0,0,0,0,0,0\n', encoding="utf-8")
    assert not ctl.import_csv(bad, ImportMode.MERGE)
    assert dialogs.errors[-1][1].startswith("点.csv：第 2 行：不是有效的 CSV 文件")
    assert_chinese(dialogs.errors[-1][1].replace("点.csv", ""))
    good = tmp_path / "好.csv"
    good.write_text("id,name,x,y,z,a,b,c\n90,新,1,2,3,0,0,0\n", encoding="utf-8")
    with qtbot.waitSignal(ctl.statusMessage) as said:
        assert ctl.import_csv(good, ImportMode.MERGE)
    assert said.args[0] == f"已导入 {good}：新增 1 个，更新 0 个，未变 0 个，删除 0 个"


@pytest.mark.parametrize(
    ("column", "value", "reason"),
    [
        (COL_KIND, "circle", "'circle' 不是直线或圆弧"),
        (COL_SPEED, "0", "0 mm/s：速度必须大于 0"),
        (COL_END, "99", "点 P99 不存在：请从列表中选择"),
        (COL_VIA, "7", "圆弧的中间点必须与终点不同"),
    ],
)
def test_a_segment_edit_is_refused_in_chinese(
    qtbot: Any, zh: None, column: int, value: str, reason: str
) -> None:
    project = load_project(SAMPLES / "demo.teachpad.json")
    model = SegmentTableModel(QUndoStack(), project.ledger)
    model.set_plan(project.plans[1])  # circle: line, arc, arc, line
    with qtbot.waitSignal(model.editRejected) as rejected:
        assert model.setData(model.index(1, column), value) is False
    text = rejected.args[0]
    assert text.startswith("第 2 段") and text.endswith(reason), text
    assert_chinese(text.replace("'circle'", ""))

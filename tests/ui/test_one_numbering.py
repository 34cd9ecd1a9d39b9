"""One numbering of tools and external axes everywhere (issue 21). Tools: GV245's number, as the
CSV, the project file, the cell editor and ``--tool`` hold it ("tool 3" is 3 in the CSV, not
"tool 4"). External axes: J7..J11, as the jog panel, go to zero and the joint frame name them
(the monitor and ``teachpad-cli status`` said EJ1..EJ5)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack

from app.cli.main import main
from app.models import Pose
from app.points.csv_io import points_to_csv
from app.points.fields import tool_text
from app.points.point import make_point
from app.points.project_model import Project
from app.protocol.codec import float_to_registers
from app.protocol.enums import JOINT_AXIS_NAMES
from app.protocol.naming import describe_registers
from app.protocol.registers import GV_TOOL_FRAME, gv_reg
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from ui.models.point_columns import COL_TOOL
from ui.models.points_model import PointsModel
from ui.panels.monitor_panel import MonitorPanel


def test_a_tool_reads_as_its_csv_number(qtbot: Any, translator: Any) -> None:
    point = make_point(5, "P5", (400, 0, 300, 180, 0, 0), tool=3)
    assert points_to_csv([point]).splitlines()[1].split(",")[13] == "3"
    assert tool_text(3) == "tool 3"
    project = Project(name="tools")
    project.ledger.replace_all([point])
    model = PointsModel(project, QUndoStack())
    index = model.index(0, COL_TOOL)
    assert model.data(index, Qt.ItemDataRole.DisplayRole) == "tool 3"
    assert model.data(index, Qt.ItemDataRole.EditRole) == "3"
    (item,) = describe_registers(gv_reg(GV_TOOL_FRAME), float_to_registers(3.0))
    assert item.label == "GV245 tool = 3.0 (tool 3)"  # the traffic inspector's meaning
    assert translator.set_language("zh_CN")
    model.retranslate()
    assert model.data(index, Qt.ItemDataRole.DisplayRole) == "工具 3"


def test_external_axes_are_j7_to_j11_in_the_monitor(qtbot: Any) -> None:
    panel = MonitorPanel()
    qtbot.addWidget(panel)
    panel.on_pose(Pose(1, 2, 3, 4, 5, 6, ext=(7.0, 8.0, 9.0, 10.0, 11.0)))
    panel.refresh()
    assert not any(name.startswith("EJ") for name in panel.readouts)
    assert [panel.readouts[name].text() for name in JOINT_AXIS_NAMES[6:]] == [
        "7.000",
        "8.000",
        "9.000",
        "10.000",
        "11.000",
    ]
    captions = [panel.readouts[name].caption() for name in JOINT_AXIS_NAMES[6:]]
    assert captions == list(JOINT_AXIS_NAMES[6:])


def test_the_points_table_names_external_axes_j7_to_j11(qtbot: Any, translator: Any) -> None:
    """The table's external-axis columns read as the jog panel names the axes; the tip says the
    CSV column (e1..e5, kept for existing files); the switch that shows them too."""
    from ui.models.point_columns import EXT_COLUMNS
    from ui.panels.points_panel import PointsPanel

    model = PointsModel(Project(name="ext"), QUndoStack())
    horizontal = Qt.Orientation.Horizontal
    headers = [model.headerData(c, horizontal, Qt.ItemDataRole.DisplayRole) for c in EXT_COLUMNS]
    assert headers == list(JOINT_AXIS_NAMES[6:])
    assert "e1" in model.headerData(EXT_COLUMNS[0], horizontal, Qt.ItemDataRole.ToolTipRole)
    panel = PointsPanel(model)
    qtbot.addWidget(panel)
    assert panel.action_show_ext.text() == "J7–J11"
    assert translator.set_language("zh_CN")
    model.retranslate()
    tip = model.headerData(EXT_COLUMNS[4], horizontal, Qt.ItemDataRole.ToolTipRole)
    assert "外部轴" in tip and "e5" in tip


def test_the_cli_status_names_external_axes_as_jog_and_zero_do(
    sim: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["--port", str(sim.port), "--poll-timeout", "1.0", "status"]) == 0
    line = next(line for line in capsys.readouterr().out.splitlines() if line.startswith("external"))
    assert "EJ" not in line and all(f"{name} " in line for name in JOINT_AXIS_NAMES[6:])

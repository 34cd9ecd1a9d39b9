"""The points table and its cell editor read a float32 as the CSV writes it (issue 21): 596.903,
not 596.9028930664062; 0.000, not -0.000; A/C at -180 as +180."""

from __future__ import annotations

from typing import Any

from PySide6.QtCore import Qt
from PySide6.QtGui import QUndoStack

from app.points.point import make_point
from app.points.project_model import Project
from app.protocol.codec import decode_floats, encode_floats
from ui.models.point_columns import COLUMNS
from ui.models.points_model import PointsModel


def test_table_and_editor_texts(qtbot: Any) -> None:
    pose = tuple(decode_floats(encode_floats([596.903, -9.2e-06, -0.0004, -180.0, 12.5, -179.9999])))
    project = Project(name="numbers")
    project.ledger.replace_all([make_point(1, "P1", pose)])
    model = PointsModel(project, QUndoStack())

    def cell(name: str, role: Qt.ItemDataRole) -> Any:
        return model.data(model.index(0, COLUMNS.index(name)), role)

    shown = [cell(n, Qt.ItemDataRole.DisplayRole) for n in ("x", "y", "z", "a", "b", "c")]
    assert shown == ["596.903", "0.000", "0.000", "180.000", "12.500", "180.000"]
    edited = [cell(n, Qt.ItemDataRole.EditRole) for n in ("x", "y", "z", "a", "b", "c")]
    assert edited == ["596.903", "0.0", "0.0", "180.0", "12.5", "180.0001"]

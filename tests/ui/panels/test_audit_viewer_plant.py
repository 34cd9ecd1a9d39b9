"""The audit viewer's role filter knows the plant: the Sparkplug gateway writes its records as
``plant (R1)`` (app/gateway/plant.py); "plant" in the role box shows them, every robot's, and
nothing else; the role reads in the operator's language, the robot's name as written."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt

from app.gateway.plant import plant_audit_role
from app.safety.audit import AuditLog
from app.safety.audit_read import AuditFilter, query
from tests.ui.panels.test_audit_words import _column
from tests.ui.pendant_support import translator_fixture  # noqa: F401 - fixture
from tests.ui.test_messages import assert_chinese
from ui.panels.audit_viewer import AuditViewer


def _trail(folder: Path) -> None:
    """An operator's record, and the plant's for two robots (as the gateway's edge node writes them)."""
    AuditLog(folder).record("action", "edit envelope")
    for robot in ("R1", "R2"):
        plant = AuditLog(folder, role=plant_audit_role(robot))
        plant.record("refused", f"#1 program/run 3 ({robot})", result="refused")
        plant.close()


def test_the_plant_filter_shows_the_plants_records(qtbot: Any, translator: Any, tmp_path: Path) -> None:
    _trail(tmp_path)
    assert {r.role for r in query(tmp_path)} == {"operator", "plant (R1)", "plant (R2)"}
    viewer = AuditViewer(tmp_path)
    qtbot.addWidget(viewer)
    box = viewer.role_box
    at = box.findData("plant")
    assert at >= 0 and box.itemText(at) == "plant"
    box.setCurrentIndex(at)
    viewer.refresh()
    assert [r.role for r in viewer.model.records] == ["plant (R1)", "plant (R2)"]
    assert _column(viewer.model, "role") == ["plant (R1)", "plant (R2)"]
    assert "2 records" in viewer.status.text()
    # the operator's filter still holds only its own (exact roles are unchanged)
    assert [r.role for r in query(tmp_path, AuditFilter(role="operator"))] == ["operator"]
    assert query(tmp_path, AuditFilter(role="plant (R2)"))[0].role == "plant (R2)"
    assert translator.set_language("zh_CN")
    chinese = AuditViewer(tmp_path)
    qtbot.addWidget(chinese)
    at = chinese.role_box.findData("plant")
    assert_chinese(chinese.role_box.itemText(at))
    chinese.role_box.setCurrentIndex(at)
    chinese.refresh()
    roles = _column(chinese.model, "role")
    assert roles == ["工厂系统（R1）", "工厂系统（R2）"], roles
    assert chinese.model.data(chinese.model.index(0, 1), Qt.ItemDataRole.DisplayRole) == roles[0]

"""The connection dialog lists the machine's serial ports (pyserial's list, monkeypatched here)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.link.client import ConnectionSettings
from ui.dialogs import connection_dialog
from ui.dialogs.connection_dialog import ConnectionDialog, SerialPortInfo


class FakePort:
    def __init__(self, device: str, description: str) -> None:
        self.device, self.description = device, description


@pytest.fixture
def ports(monkeypatch: pytest.MonkeyPatch) -> list[FakePort]:
    listed = [FakePort("/dev/ttyUSB1", "CH340 USB-Serial"), FakePort("/dev/ttyS0", "n/a")]
    monkeypatch.setattr("serial.tools.list_ports.comports", lambda: list(listed))
    return listed


def test_the_serial_ports_are_listed_and_refreshed(qtbot: Any, ports: list[FakePort]) -> None:
    dialog = ConnectionDialog(ConnectionSettings(serial_port="/dev/pts/7"))
    qtbot.addWidget(dialog)
    combo = dialog.serial_combo
    assert [combo.itemText(i) for i in range(combo.count())] == ["/dev/ttyS0", "/dev/ttyUSB1"]
    assert combo.itemData(1, Qt.ItemDataRole.ToolTipRole) == "/dev/ttyUSB1: CH340 USB-Serial"
    assert dialog.serial_edit.text() == "/dev/pts/7"  # a port the system does not list stays
    assert "2" in dialog.ports_note.text()
    ports.append(FakePort("/dev/ttyACM0", "Arduino"))
    dialog.refresh_button.click()
    assert combo.count() == 3 and dialog.serial_edit.text() == "/dev/pts/7"
    combo.setCurrentIndex(combo.findText("/dev/ttyACM0"))
    settings = dialog.settings()
    assert settings.serial_port == "/dev/ttyACM0" and settings.transport == "rtu"


def test_no_ports_still_lets_the_user_type_one(qtbot: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(connection_dialog, "available_serial_ports", lambda: [])
    dialog = ConnectionDialog()
    qtbot.addWidget(dialog)
    assert dialog.serial_combo.count() == 0 and "type" in dialog.ports_note.text()
    dialog.transport_combo.setCurrentIndex(1)
    dialog.serial_edit.setText("COM3")
    assert dialog.settings().serial_port == "COM3"


def test_a_failing_port_list_is_not_an_error(qtbot: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken() -> list[SerialPortInfo]:
        raise OSError("no /sys here")

    monkeypatch.setattr(connection_dialog, "available_serial_ports", broken)
    dialog = ConnectionDialog()
    qtbot.addWidget(dialog)
    assert dialog.serial_combo.count() == 0 and "no /sys here" in dialog.ports_note.text()

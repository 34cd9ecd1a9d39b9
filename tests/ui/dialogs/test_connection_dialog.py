"""The connection dialog lists the machine's serial ports (pyserial's list, monkeypatched here)
and opens on the connection in use (a real link to the simulator)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import Qt

from app.connection import ConnectionSettings
from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState
from app.protocol.codec import WordOrder
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    is_state,
    link_fixture,
)
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


# --- opening on the connection in use (issue 9) -------------------------------------------------


def test_opens_on_the_link_connection_and_says_it_is_connected(
    qtbot: Any, link: RobotLink, sim_factory: Any, ports: list[FakePort]
) -> None:
    """A real link to the simulator: the dialog shows its settings (not the defaults), says
    it is connected, and the poll rate; OK without changes gives the same connection back."""
    sim = sim_factory(unit=7, word_order=WordOrder.HIGH_FIRST)
    options = {"unit": 7, "word_order": WordOrder.HIGH_FIRST, "monitor_only": True, "timeout": 0.4}
    used = connect(qtbot, link, sim, **options, poll_timeout=None)  # the dialog has no poll timeout
    # remembered, older: where is not shown; unit and word order are the register profile's (which
    # the remembered settings carry), shown read-only
    saved = ConnectionSettings(host="10.0.0.9", port=1502, unit=7, word_order=WordOrder.HIGH_FIRST)
    dialog = ConnectionDialog.for_link(link, saved, poll_hz=40.0)
    qtbot.addWidget(dialog)
    assert dialog.host_edit.text() == "127.0.0.1" and dialog.port_spin.value() == sim.port
    assert dialog.unit_spin.value() == 7 and dialog.monitor_check.isChecked()
    assert dialog.order_combo.currentData() == WordOrder.HIGH_FIRST.value
    assert not dialog.unit_spin.isEnabled() and not dialog.order_combo.isEnabled()
    assert dialog.transport_combo.currentData() == "tcp"
    text = dialog.current_label.text()
    assert f"Connected to 127.0.0.1:{sim.port}" in text and "unit 7" in text
    assert "Polling at 40 Hz" in text and "Monitor only" in text
    assert dialog.settings() == used
    # disconnected: the dialog says so, still on the link's last settings
    with qtbot.waitSignal(
        link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED), timeout=SIGNAL_TIMEOUT_MS
    ):
        link.disconnect()
    later = ConnectionDialog.for_link(link, saved, poll_hz=40.0)
    qtbot.addWidget(later)
    assert later.current_label.text().startswith(f"Not connected (last: 127.0.0.1:{sim.port})")
    assert later.port_spin.value() == sim.port


def test_a_serial_link_shows_its_serial_settings(qtbot: Any, ports: list[FakePort]) -> None:
    serial = ConnectionSettings(serial_port="/dev/ttyUSB1", baudrate=9600, parity="E", stopbits=2, unit=3)
    dialog = ConnectionDialog(serial, connection=ConnectionState(LinkState.CONNECTING), poll_hz=20)
    qtbot.addWidget(dialog)
    assert dialog.transport_combo.currentData() == "rtu" and dialog.pages.currentIndex() == 1
    assert dialog.serial_edit.text() == "/dev/ttyUSB1" and dialog.baud_combo.currentData() == 9600
    assert dialog.parity_combo.currentData() == "E" and dialog.stopbits_spin.value() == 2
    text = dialog.current_label.text()
    assert "Connecting to /dev/ttyUSB1 9600 8E2" in text and "Modbus RTU" in text and "unit 3" in text
    assert ConnectionDialog(serial).current_label.isHidden()  # no link given: no status line

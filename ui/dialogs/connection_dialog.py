"""Connect…: Modbus TCP or RTU (serial, the machine's ports listed), unit id, word order, timeout,
monitor-only.

Opened from a link (:meth:`ConnectionDialog.for_link`), it shows the connection in use (the
link's settings, else the remembered ones), whether it is connected, and the poll rate.

Given a register profile (``for_link`` derives it from the remembered settings, which carry the
profile in force), the unit id and the word order are the profile's: shown, not editable here
(an administrator changes them in Safety -> Register profile...), and :meth:`settings` applies the
whole profile to the connection."""

from __future__ import annotations

import dataclasses
from typing import NamedTuple, Protocol

from PySide6.QtCore import QEvent, Qt, Slot
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QStackedWidget,
    QVBoxLayout,
    QWidget,
)

from app.connection import ConnectionSettings
from app.link.hostname import host_problem
from app.link.types import ConnectionState, LinkState
from app.protocol.codec import WordOrder
from app.safety.register_profile import RegisterProfile
from ui.messages import connection_text

_BAUDRATES = (9600, 19200, 38400, 57600, 115200, 230400)
_PARITIES = ("N", "E", "O")


class SerialPortInfo(NamedTuple):
    device: str  # what to open: /dev/ttyUSB0, COM3
    description: str  # what it is, as the system names it


def available_serial_ports() -> list[SerialPortInfo]:
    """The machine's serial ports (pyserial's ``comports()``), sorted by device name."""
    from serial.tools import list_ports

    ports = [
        SerialPortInfo(p.device, p.description if p.description not in (None, "n/a") else "")
        for p in list_ports.comports()
    ]
    return sorted(ports, key=lambda p: p.device)


class LinkView(Protocol):
    """What the dialog reads of the link (:class:`~app.link.robot_link.RobotLink` fits)."""

    @property
    def connection(self) -> ConnectionState: ...

    @property
    def settings(self) -> ConnectionSettings | None: ...


class ConnectionDialog(QDialog):
    """Edits a :class:`ConnectionSettings`; ``settings()`` returns the result. ``connection``
    and ``poll_hz``: the link's state and poll rate, shown above the form."""

    def __init__(
        self,
        settings: ConnectionSettings | None = None,
        parent: QWidget | None = None,
        *,
        connection: ConnectionState | None = None,
        poll_hz: float | None = None,
        profile: RegisterProfile | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("ConnectionDialog")
        self._base = settings or ConnectionSettings()
        self.profile = profile
        self._connection = connection
        self._poll_hz = poll_hz
        self.current_label = QLabel(self)  # the connection in use, connected or not
        self.current_label.setWordWrap(True)
        self.current_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)

        self.transport_combo = QComboBox(self)
        self.transport_combo.addItem("", "tcp")
        self.transport_combo.addItem("", "rtu")

        self.tcp_page = QWidget(self)
        tcp_form = QFormLayout(self.tcp_page)
        tcp_form.setContentsMargins(0, 0, 0, 0)
        self.host_edit = QLineEdit(self.tcp_page)
        self.port_spin = QSpinBox(self.tcp_page)
        self.port_spin.setRange(1, 65535)
        self.host_caption = QLabel(self.tcp_page)
        self.port_caption = QLabel(self.tcp_page)
        self.host_note = QLabel(self.tcp_page)  # why the host typed is refused (hidden: none)
        self.host_note.setObjectName("hostNote")
        self.host_note.setWordWrap(True)
        self.host_note.hide()
        self.host_edit.textEdited.connect(lambda _text: self.host_note.hide())
        tcp_form.addRow(self.host_caption, self.host_edit)
        tcp_form.addRow(self.host_note)
        tcp_form.addRow(self.port_caption, self.port_spin)

        self.rtu_page = QWidget(self)
        rtu_form = QFormLayout(self.rtu_page)
        rtu_form.setContentsMargins(0, 0, 0, 0)
        # editable: a port the system does not list (a pty, a symlink) can still be typed
        self.serial_combo = QComboBox(self.rtu_page)
        self.serial_combo.setEditable(True)
        self.serial_combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        serial_edit = self.serial_combo.lineEdit()
        assert serial_edit is not None  # an editable combo box always has its line edit
        self.serial_edit: QLineEdit = serial_edit
        self.serial_edit.setPlaceholderText("/dev/ttyUSB0, COM3")
        self.refresh_button = QPushButton(self.rtu_page)
        self.refresh_button.clicked.connect(self.refresh_serial_ports)
        serial_row = QHBoxLayout()
        serial_row.addWidget(self.serial_combo, 1)
        serial_row.addWidget(self.refresh_button)
        self.ports_note = QLabel(self.rtu_page)
        self.baud_combo = QComboBox(self.rtu_page)
        for baud in _BAUDRATES:
            self.baud_combo.addItem(str(baud), baud)
        self.parity_combo = QComboBox(self.rtu_page)
        for parity in _PARITIES:
            self.parity_combo.addItem("", parity)
        self.stopbits_spin = QSpinBox(self.rtu_page)
        self.stopbits_spin.setRange(1, 2)
        self.serial_caption = QLabel(self.rtu_page)
        self.baud_caption = QLabel(self.rtu_page)
        self.parity_caption = QLabel(self.rtu_page)
        self.stopbits_caption = QLabel(self.rtu_page)
        rtu_form.addRow(self.serial_caption, serial_row)
        rtu_form.addRow(self.ports_note)
        rtu_form.addRow(self.baud_caption, self.baud_combo)
        rtu_form.addRow(self.parity_caption, self.parity_combo)
        rtu_form.addRow(self.stopbits_caption, self.stopbits_spin)

        self.pages = QStackedWidget(self)
        self.pages.addWidget(self.tcp_page)
        self.pages.addWidget(self.rtu_page)
        self.transport_combo.currentIndexChanged.connect(self.pages.setCurrentIndex)

        self.unit_spin = QSpinBox(self)
        self.unit_spin.setRange(0, 247)
        self.order_combo = QComboBox(self)
        self.order_combo.addItem("", WordOrder.LOW_FIRST.value)
        self.order_combo.addItem("", WordOrder.HIGH_FIRST.value)
        self.timeout_spin = QDoubleSpinBox(self)
        self.timeout_spin.setRange(0.05, 30.0)
        self.timeout_spin.setDecimals(2)
        self.timeout_spin.setSingleStep(0.1)
        self.timeout_spin.setSuffix(" s")
        self.monitor_check = QCheckBox(self)
        self.profile_note = QLabel(self)  # "unit and word order: from the register profile"
        self.profile_note.setWordWrap(True)
        self.profile_note.setVisible(profile is not None)

        self.transport_caption = QLabel(self)
        self.unit_caption = QLabel(self)
        self.order_caption = QLabel(self)
        self.timeout_caption = QLabel(self)
        form = QFormLayout()
        form.addRow(self.transport_caption, self.transport_combo)
        form.addRow(self.pages)
        form.addRow(self.unit_caption, self.unit_spin)
        form.addRow(self.order_caption, self.order_combo)
        form.addRow(self.profile_note)
        form.addRow(self.timeout_caption, self.timeout_spin)
        form.addRow(self.monitor_check)

        self.buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel, self
        )
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.current_label)
        layout.addLayout(form)
        layout.addWidget(self.buttons)
        self._ports: list[SerialPortInfo] = []
        self._ports_error: str | None = None
        self.refresh_serial_ports()
        self.set_settings(self._base)
        self.retranslate()

    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("Connect to controller"))
        self.transport_caption.setText(self.tr("Transport:"))
        self.transport_combo.setItemText(0, self.tr("Modbus TCP"))
        self.transport_combo.setItemText(1, self.tr("Modbus RTU (serial)"))
        self.host_caption.setText(self.tr("Host:"))
        self.port_caption.setText(self.tr("Port:"))
        self.serial_caption.setText(self.tr("Serial port:"))
        self.refresh_button.setText(self.tr("Refresh"))
        self.refresh_button.setToolTip(self.tr("List the serial ports of this computer again"))
        self._show_ports_note()
        self.baud_caption.setText(self.tr("Baud rate:"))
        self.parity_caption.setText(self.tr("Parity:"))
        for i, text in enumerate((self.tr("none"), self.tr("even"), self.tr("odd"))):
            self.parity_combo.setItemText(i, text)
        self.stopbits_caption.setText(self.tr("Stop bits:"))
        self.unit_caption.setText(self.tr("Unit id:"))
        self.order_caption.setText(self.tr("Float word order:"))
        self.order_combo.setItemText(0, self.tr("Low word first (CDAB, default)"))
        self.order_combo.setItemText(1, self.tr("High word first (ABCD)"))
        self.timeout_caption.setText(self.tr("Timeout:"))
        self.monitor_check.setText(self.tr("Monitor only (never write to the controller)"))
        if self.profile is not None:
            note = self.tr(
                "Unit id and word order come from the register profile (Safety → Register "
                "profile…, administrator)."
            )
            self.profile_note.setText(note)
            for widget in (self.unit_spin, self.order_combo):
                widget.setToolTip(note)
        self._show_current()

    @classmethod
    def for_link(
        cls,
        link: LinkView,
        saved: ConnectionSettings,
        poll_hz: float | None = None,
        parent: QWidget | None = None,
    ) -> ConnectionDialog:
        """The dialog on the connection in use: the link's settings (the remembered ones when
        the link has none yet), its state and the poll rate."""
        return cls(
            link.settings or saved,
            parent,
            connection=link.connection,
            poll_hz=poll_hz,
            profile=RegisterProfile.from_connection(saved),
        )

    def _show_current(self) -> None:
        """ "Connected to …" / "Not connected (…)", with the transport and the poll rate."""
        state = self._connection
        self.current_label.setVisible(state is not None)
        if state is None:
            return
        s = self._base
        where = (
            f"{s.serial_port} {s.baudrate} {s.bytesize}{s.parity}{s.stopbits}"
            if s.serial_port
            else f"{s.host}:{s.port}"
        )
        transport = self.tr("Modbus RTU (serial)") if s.transport == "rtu" else self.tr("Modbus TCP")
        words = {
            LinkState.CONNECTED: self.tr("Connected to {where}"),
            LinkState.CONNECTING: self.tr("Connecting to {where}"),
            LinkState.NOT_ANSWERING: self.tr("Connected to {where}, but the controller does not answer"),
            LinkState.DOWN: self.tr("Connection to {where} lost; retrying"),
            LinkState.DISCONNECTED: self.tr("Not connected (last: {where})"),
        }
        lines = [
            words[state.state].format(where=state.endpoint or where),
            self.tr("{transport}, unit {unit}").format(transport=transport, unit=s.unit),
        ]
        if self._poll_hz is not None:
            lines.append(self.tr("Polling at {hz:g} Hz").format(hz=self._poll_hz))
        if state.monitor_only or s.monitor_only:
            lines.append(self.tr("Monitor only: nothing is written to the controller"))
        why = connection_text(state)
        if why and not state.connected:
            lines.append(why[:120])
        self.current_label.setText("\n".join(lines))
        self.current_label.setStyleSheet("font-weight: bold;" if state.connected else "")

    @Slot()
    def refresh_serial_ports(self) -> None:
        """List the machine's serial ports again; what is typed in the field stays."""
        typed = self.serial_edit.text()
        self._ports_error = None
        try:
            self._ports = available_serial_ports()
        except Exception as exc:  # the system refuses to list: say so; typing a port still works
            self._ports, self._ports_error = [], str(exc)[:80]
        self.serial_combo.blockSignals(True)
        self.serial_combo.clear()
        for port in self._ports:
            self.serial_combo.addItem(port.device, port.device)
            tip = f"{port.device}: {port.description}" if port.description else port.device
            self.serial_combo.setItemData(self.serial_combo.count() - 1, tip, Qt.ItemDataRole.ToolTipRole)
        self.serial_combo.setEditText(typed)
        self.serial_combo.blockSignals(False)
        self._show_ports_note()

    def _show_ports_note(self) -> None:
        if self._ports_error is not None:
            text = self.tr("Could not list the serial ports ({error}); type the device name").format(
                error=self._ports_error
            )
        elif self._ports:
            text = self.tr("Serial ports found: {n}").format(n=len(self._ports))
        else:
            text = self.tr("No serial port found; type the device name")
        self.ports_note.setText(text)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def set_settings(self, settings: ConnectionSettings) -> None:
        rtu = settings.serial_port is not None
        self.transport_combo.setCurrentIndex(1 if rtu else 0)
        self.pages.setCurrentIndex(1 if rtu else 0)
        self.host_edit.setText(settings.host)
        self.port_spin.setValue(settings.port)
        self.serial_combo.setEditText(settings.serial_port or "")
        index = self.baud_combo.findData(settings.baudrate)
        if index < 0:
            self.baud_combo.addItem(str(settings.baudrate), settings.baudrate)
            index = self.baud_combo.count() - 1
        self.baud_combo.setCurrentIndex(index)
        self.parity_combo.setCurrentIndex(max(0, self.parity_combo.findData(settings.parity)))
        self.stopbits_spin.setValue(settings.stopbits)
        shown = settings if self.profile is None else self.profile.apply(settings)
        self.unit_spin.setValue(shown.unit)
        self.order_combo.setCurrentIndex(max(0, self.order_combo.findData(shown.word_order.value)))
        for widget in (self.unit_spin, self.order_combo):
            widget.setEnabled(self.profile is None)
        self.timeout_spin.setValue(settings.timeout)
        self.monitor_check.setChecked(settings.monitor_only)

    def settings(self) -> ConnectionSettings:
        rtu = self.transport_combo.currentData() == "rtu"
        serial = self.serial_edit.text().strip() if rtu else ""
        edited = dataclasses.replace(
            self._base,
            host=self.host_edit.text().strip() or "127.0.0.1",
            port=self.port_spin.value(),
            serial_port=serial or None,
            framer="socket" if not rtu else self._base.framer,
            baudrate=int(self.baud_combo.currentData()),
            parity=str(self.parity_combo.currentData()),
            stopbits=self.stopbits_spin.value(),
            unit=self.unit_spin.value(),
            word_order=WordOrder(self.order_combo.currentData()),
            timeout=self.timeout_spin.value(),
            monitor_only=self.monitor_check.isChecked(),
        )
        return edited if self.profile is None else self.profile.apply(edited)

    @Slot()
    def accept(self) -> None:
        if self.transport_combo.currentData() == "rtu" and not self.serial_edit.text().strip():
            self.serial_edit.setFocus()
            self.serial_edit.setPlaceholderText(self.tr("a serial port is needed for RTU"))
            return
        if self.transport_combo.currentData() == "tcp" and not self._host_ok():
            return
        super().accept()

    def _host_ok(self) -> bool:
        """The host typed is an IP address or a valid host name; else say why, beside it."""
        problem = host_problem(self.host_edit.text().strip() or "127.0.0.1")
        if problem is None:
            self.host_note.hide()
            return True
        why = {
            "space": self.tr("it contains a space"),
            "too_long": self.tr("it is longer than 253 characters"),
            "empty_label": self.tr("it has an empty part (two dots in a row, or a dot at the start)"),
            "long_label": self.tr("a part between two dots is longer than 63 characters"),
            "bad_character": self.tr("it contains a character a host name cannot have"),
            "bad_hyphen": self.tr("a part between two dots starts or ends with a hyphen"),
            "bad_ip": self.tr("it looks like an IP address but is not one"),
        }.get(problem, problem)
        self.host_note.setText(self.tr("Not a valid host name or IP address: {why}.").format(why=why))
        self.host_note.show()
        self.host_edit.setFocus()
        self.host_edit.selectAll()
        return False

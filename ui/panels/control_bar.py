"""The top control bar: a big red Stop (always visible), Pause, Resume, and the work mode.

The mode switch shows the controller's *real* mode (register 560, including "Modbus teach"),
not what was last clicked: clicking asks for a mode, the next status read shows the result.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, Qt, Signal, Slot
from PySide6.QtWidgets import QButtonGroup, QGridLayout, QLabel, QPushButton, QSizePolicy, QWidget

from app.link.state import RobotState
from app.link.types import ConnectionState
from app.models import ControllerStatus
from app.protocol.enums import ControllerMode, WorkMode, controller_mode_text
from ui.i18n import protocol_text

STOP_STYLE = (
    "QPushButton { background-color: #c62828; color: white; font-weight: bold; font-size: 20px;"
    " border: 2px solid #8e0000; border-radius: 8px; padding: 6px 10px; }"
    "QPushButton:hover { background-color: #d32f2f; }"
    "QPushButton:pressed { background-color: #8e0000; }"
)
# Mode lamp colours: background, text (manual grey, auto blue, Modbus teach amber, unknown red).
MODE_COLORS: dict[int | None, tuple[str, str]] = {
    None: ("#eceff1", "#5f6368"),
    int(ControllerMode.MANUAL): ("#cfd8dc", "#263238"),
    int(ControllerMode.AUTO): ("#1565c0", "#ffffff"),
    int(ControllerMode.MODBUS_TEACH): ("#ef8f00", "#ffffff"),
}
UNKNOWN_MODE_COLORS = ("#c62828", "#ffffff")
BUTTON_HEIGHT = 34


class ControlBar(QWidget):
    """Stop / Pause / Resume and the manual / auto switch. Emits requests; holds no state."""

    stopRequested = Signal()
    pauseRequested = Signal()
    resumeRequested = Signal()
    modeRequested = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("ControlBar")
        self._mode: ControllerMode | int | None = None

        self.stop_button = QPushButton(self)
        self.stop_button.setObjectName("StopButton")
        self.stop_button.setStyleSheet(STOP_STYLE)
        self.stop_button.setMinimumHeight(2 * BUTTON_HEIGHT + 4)
        self.stop_button.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.stop_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.stop_button.clicked.connect(self.stopRequested)

        self.pause_button = QPushButton(self)
        self.resume_button = QPushButton(self)
        for button in (self.pause_button, self.resume_button):
            button.setMinimumHeight(BUTTON_HEIGHT)
            button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.pause_button.clicked.connect(self.pauseRequested)
        self.resume_button.clicked.connect(self.resumeRequested)

        self.mode_label = QLabel("—", self)
        self.mode_label.setObjectName("ModeLabel")
        self.mode_label.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.mode_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.manual_button = QPushButton(self)
        self.auto_button = QPushButton(self)
        self._mode_group = QButtonGroup(self)
        self._mode_group.setExclusive(False)  # shows the controller's mode, may be neither
        for mode, button in ((WorkMode.MANUAL, self.manual_button), (WorkMode.AUTO, self.auto_button)):
            button.setCheckable(True)
            button.setMinimumHeight(BUTTON_HEIGHT)
            button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
            self._mode_group.addButton(button, int(mode))
        self._mode_group.idClicked.connect(self._on_mode_clicked)

        # Stop on the left and the mode lamp on the right, two rows tall; the buttons between.
        layout = QGridLayout(self)
        layout.setContentsMargins(6, 4, 6, 4)
        layout.setHorizontalSpacing(6)
        layout.setVerticalSpacing(4)
        layout.addWidget(self.stop_button, 0, 0, 2, 1)
        layout.addWidget(self.pause_button, 0, 1)
        layout.addWidget(self.resume_button, 0, 2)
        layout.addWidget(self.manual_button, 1, 1)
        layout.addWidget(self.auto_button, 1, 2)
        layout.addWidget(self.mode_label, 0, 3, 2, 1)
        layout.setColumnStretch(0, 3)
        for column in (1, 2, 3):
            layout.setColumnStretch(column, 2)
        self.set_motion_enabled(False)
        self.retranslate()

    def retranslate(self) -> None:
        self.stop_button.setText(self.tr("STOP"))
        self.stop_button.setToolTip(self.tr("Stop all motion (Esc)"))
        self.pause_button.setText(self.tr("Pause"))
        self.pause_button.setToolTip(self.tr("Pause the current move or program"))
        self.resume_button.setText(self.tr("Resume"))
        self.resume_button.setToolTip(self.tr("Resume the paused move or program"))
        self.mode_label.setToolTip(self.tr("The controller's work mode (register 560)"))
        self.manual_button.setText(self.tr("Manual"))
        self.manual_button.setToolTip(self.tr("Switch the controller to manual mode"))
        self.auto_button.setText(self.tr("Auto"))
        self.auto_button.setToolTip(self.tr("Switch the controller to auto mode (needed for Modbus motion)"))
        self._show_mode()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- slots ------------------------------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Show the mode of ``state``'s status; no mode while the link is not connected."""
        state.statusChanged.connect(self.on_status)
        state.connectionChanged.connect(self._on_connection)
        if state.status is not None and state.connected:
            self.on_status(state.status)

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        if not connection.connected:
            self.clear_status()

    @Slot(ControllerStatus)
    def on_status(self, status: ControllerStatus) -> None:
        if status.mode != self._mode:
            self._mode = status.mode
            self._show_mode()

    def clear_status(self) -> None:
        self._mode = None
        self._show_mode()

    def set_motion_enabled(self, enabled: bool) -> None:
        """Pause / resume / mode need a writable link; Stop stays enabled whatever happens."""
        for button in (self.pause_button, self.resume_button, self.manual_button, self.auto_button):
            button.setEnabled(enabled)

    def mode_text(self) -> str:
        """The controller's mode as shown (translated), without the caption."""
        mode = self._mode
        return "" if mode is None else protocol_text(controller_mode_text(int(mode)))

    # --- internals --------------------------------------------------------------------
    def _show_mode(self) -> None:
        mode = self._mode
        name = "—" if mode is None else protocol_text(controller_mode_text(int(mode)))
        self.mode_label.setText(self.tr("Mode:\n{mode}").format(mode=name))
        background, color = MODE_COLORS.get(None if mode is None else int(mode), UNKNOWN_MODE_COLORS)
        self.mode_label.setStyleSheet(
            f"QLabel {{ background-color: {background}; color: {color}; border-radius: 5px;"
            " padding: 3px 10px; font-weight: bold; font-size: 15px; }")
        self.manual_button.setChecked(mode == ControllerMode.MANUAL)
        self.auto_button.setChecked(mode in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH))

    @Slot(int)
    def _on_mode_clicked(self, mode_id: int) -> None:
        self._show_mode()  # the check marks follow the controller, not the click
        self.modeRequested.emit(WorkMode(mode_id))

"""The top control bar: a big red Stop (always visible), Pause, Resume, and the work mode.

The mode switch shows the controller's *real* mode (register 560, including "Modbus teach"),
not what was last clicked: clicking asks for a mode, the next status read shows the result.

Nothing moves when a text changes: STOP and the mode badge have fixed sizes computed from the
widest text they show in every shipped language; a mode name wider than the badge wraps at a
space or elides, and the badge's tooltip holds the full text. The mode reads "unknown" (grey)
while the link is not live.
"""

from __future__ import annotations

import time

from PySide6.QtCore import QEvent, Qt, Signal, Slot
from PySide6.QtGui import QFont
from PySide6.QtWidgets import QButtonGroup, QGridLayout, QLabel, QPushButton, QSizePolicy, QWidget

from app.link.state import RobotState
from app.link.types import ConnectionState
from app.models import ControllerStatus
from app.protocol.enums import (
    CONTROLLER_MODE_TEXT,
    TR_CONTEXT,
    ControllerMode,
    WorkMode,
    controller_mode_text,
)
from ui.i18n import protocol_text
from ui.text_fit import both_languages, fit_in_every_language, fit_width

STOP_STYLE = (
    "QPushButton { background-color: #c62828; color: white;"
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
STOP_PIXELS = 20  # STOP's font size
STOP_MIN_WIDTH = 90  # px, whatever its text
MODE_PIXELS = 15  # the mode badge's font size
MODE_PADDING = 14  # px: the badge's left + right padding
MODE_MAX_WIDTH = 150  # px: a wider mode text wraps at a space or elides (tooltip: full text)


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
        #: when the STOP button was clicked (``time.monotonic()``): set while stopRequested is emitted
        #: for that click, None otherwise
        self.stop_clicked_at: float | None = None

        self.stop_button = QPushButton(self)
        self.stop_button.setObjectName("StopButton")
        self.stop_button.setStyleSheet(STOP_STYLE)
        stop_font = QFont(self.stop_button.font())
        stop_font.setPixelSize(STOP_PIXELS)
        stop_font.setBold(True)
        self.stop_button.setFont(stop_font)
        self.stop_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.stop_button.clicked.connect(self._on_stop_clicked)

        self.pause_button = QPushButton(self)
        self.resume_button = QPushButton(self)
        for button in (self.pause_button, self.resume_button):
            button.setMinimumHeight(BUTTON_HEIGHT)
            button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.pause_button.clicked.connect(self.pauseRequested)
        self.resume_button.clicked.connect(self.resumeRequested)

        self.mode_label = QLabel("—", self)
        self.mode_label.setObjectName("ModeLabel")
        mode_font = QFont(self.mode_label.font())
        mode_font.setPixelSize(MODE_PIXELS)
        mode_font.setBold(True)
        self.mode_label.setFont(mode_font)
        self.mode_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
        fit_in_every_language(self._fix_widths)
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
        layout.setColumnStretch(0, 0)
        layout.setColumnStretch(3, 0)
        for column in (1, 2):
            layout.setColumnStretch(column, 1)
            layout.setColumnMinimumWidth(column, 56)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Fixed)
        self._alarm_hold = False
        self._motion_enabled = False
        self._live = True  # unbound: every status shown is taken as live
        self.set_motion_enabled(False)
        self.retranslate()

    def retranslate(self) -> None:
        self.stop_button.setText(self.tr("STOP"))
        self.stop_button.setToolTip(self.tr("Stop all motion (Esc)"))
        self.pause_button.setText(self.tr("Pause"))
        self.pause_button.setToolTip(self.tr("Pause the current move or program"))
        self.resume_button.setText(self.tr("Resume"))
        self.resume_button.setToolTip(self.tr("Resume the paused move or program"))
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
        """Show the mode of ``state``'s status; "unknown" while the link is not live."""
        state.statusChanged.connect(self.on_status)
        state.connectionChanged.connect(self._on_connection)
        state.freshnessChanged.connect(self._on_freshness)
        self._live = state.fresh
        if state.status is not None and state.connected:
            self.on_status(state.status)

    @Slot(bool)
    def _on_freshness(self, fresh: bool) -> None:
        if fresh != self._live:
            self._live = fresh
            self._show_mode()

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
        self._motion_enabled = bool(enabled)
        for button in (self.pause_button, self.manual_button, self.auto_button):
            button.setEnabled(enabled)
        self.resume_button.setEnabled(enabled and not self._alarm_hold)

    def set_alarm_hold(self, hold: bool) -> None:
        """An e-stop / servo alarm holds Resume (it would restart motion); Stop and Pause stay."""
        self._alarm_hold = bool(hold)
        self.resume_button.setEnabled(self._motion_enabled and not self._alarm_hold)

    @Slot()
    def _on_stop_clicked(self) -> None:
        # the time first: the Stop goes out in stopRequested's first slot (the motion controller),
        # the measuring (ui/controllers/stop_timing.py) reads this time after it; cleared after the
        # signal, so a Stop asked for otherwise (the signal emitted alone) is not timed from this click
        self.stop_clicked_at = time.monotonic()
        try:
            self.stopRequested.emit()
        finally:
            self.stop_clicked_at = None

    def mode_text(self) -> str:
        """The controller's mode as shown (translated), without the caption; "" while unknown
        (no status yet, or the link is not live)."""
        mode = self._mode if self._live else None
        return "" if mode is None else protocol_text(controller_mode_text(int(mode)))

    # --- internals --------------------------------------------------------------------
    def _fix_widths(self) -> None:
        """The STOP button and the mode badge as wide as their widest text in every language."""
        stop_width = fit_width(self.stop_button, both_languages("ControlBar", "STOP"), 28)
        self.stop_button.setFixedSize(max(STOP_MIN_WIDTH, stop_width), 2 * BUTTON_HEIGHT + 4)
        self.mode_label.setFixedSize(self._mode_badge_width(), 2 * BUTTON_HEIGHT + 4)

    def _mode_badge_width(self) -> int:
        """The widest caption or mode word in every language, within MODE_MAX_WIDTH."""
        texts = [*both_languages("ControlBar", "Mode:"), *both_languages("ControlBar", "unknown")]
        for text in CONTROLLER_MODE_TEXT.values():
            texts.extend(both_languages(TR_CONTEXT, text))
        words = [word for text in texts for word in text.split()]
        return min(MODE_MAX_WIDTH, fit_width(self.mode_label, words, MODE_PADDING))

    def _fit_mode_name(self, name: str) -> str:
        """``name`` on at most two lines of the badge: wrapped at a space, else elided."""
        metrics = self.mode_label.fontMetrics()
        room = self.mode_label.maximumWidth() - MODE_PADDING
        if metrics.horizontalAdvance(name) <= room:
            return name
        lines: list[str] = []
        for word in name.split():
            if lines and metrics.horizontalAdvance(f"{lines[-1]} {word}") <= room:
                lines[-1] = f"{lines[-1]} {word}"
            else:
                lines.append(word)
        if len(lines) > 2:
            lines = [lines[0], " ".join(lines[1:])]
        return "\n".join(metrics.elidedText(line, Qt.TextElideMode.ElideRight, room) for line in lines)

    def _show_mode(self) -> None:
        mode = self._mode if self._live else None
        name = self.tr("unknown") if mode is None else protocol_text(controller_mode_text(int(mode)))
        full = self.tr("Mode:\n{mode}").format(mode=name)
        self.mode_label.setText(self.tr("Mode:\n{mode}").format(mode=self._fit_mode_name(name)))
        self.mode_label.setToolTip(
            full.replace("\n", " ") + "\n" + self.tr("The controller's work mode (register 560)")
        )
        background, color = MODE_COLORS.get(None if mode is None else int(mode), UNKNOWN_MODE_COLORS)
        self.mode_label.setStyleSheet(
            f"QLabel {{ background-color: {background}; color: {color}; border-radius: 5px;"
            " padding: 3px 4px; }"
        )
        self.manual_button.setChecked(mode == ControllerMode.MANUAL)
        self.auto_button.setChecked(mode in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH))

    @Slot(int)
    def _on_mode_clicked(self, mode_id: int) -> None:
        self._show_mode()  # the check marks follow the controller, not the click
        self.modeRequested.emit(WorkMode(mode_id))

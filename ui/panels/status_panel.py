"""Controller status at a glance: link and RTT, mode, program state, alarm lamps, last command
result and the controller clock with its drift from the PC clock.

``bind(state)`` subscribes the panel to a :class:`~app.link.state.RobotState` (connection,
status, alarms, RTT, last command result); the ``on_*`` slots take the payloads directly. The
panel keeps no controller state of its own beyond what is needed to draw it.

Staleness: while ``state.fresh`` is False (no good poll within the freshness limit, or the link
not CONNECTED) the mode and program lamps read "unknown" in grey, the clock and drift turn grey
and italic and the drift is marked "(stale)": nothing here looks live that isn't. The alarm
lamps keep the last known bits (an alarm is never hidden by a silent link) under a "last known"
title.
"""

from __future__ import annotations

import datetime as dt
import math
from typing import Any

from PySide6.QtCore import QCoreApplication, QEvent, QMargins, QSize, Qt, Slot
from PySide6.QtGui import QResizeEvent
from PySide6.QtWidgets import (
    QFormLayout,
    QGridLayout,
    QGroupBox,
    QLabel,
    QSizePolicy,
    QVBoxLayout,
    QWidget,
)

from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState
from app.models import CommandResult, ControllerStatus
from app.protocol.datetime_regs import ControllerClock
from app.protocol.enums import (
    ALARM_BITS,
    ALARM_MASK,
    ALARM_TEXT,
    CONTROLLER_MODE_TEXT,
    PROGRAM_STATE_TEXT,
    TR_CONTEXT,
    UNKNOWN_STATUS_TEXT,
    ControllerMode,
    ProgramState,
)
from app.protocol.registers import GV_DATE
from ui import messages
from ui.joins import join_names
from ui.messages import connection_text, result_level, result_text
from ui.palette import COLOR_ERROR, COLOR_NEUTRAL, COLOR_OK, COLOR_WARN
from ui.widgets.live_label import LiveLabel
from ui.widgets_common import (
    LEVEL_ERROR,
    LEVEL_INFO,
    LEVEL_OFF,
    LEVEL_OK,
    LEVEL_WARN,
    AlarmLamp,
    Lamp,
    connection_display,
    monospace_font,
)

CLOCK_DRIFT_WARN_S = 5.0  # |controller - PC| above this is shown in amber
CLOCK_DRIFT_ERROR_S = 300.0  # ... and above this in red
_CLOCK_FIRST_REGISTER = 2 * GV_DATE  # 576

_MODE_LEVEL = {
    ControllerMode.MANUAL: LEVEL_OFF,
    ControllerMode.AUTO: LEVEL_INFO,
    ControllerMode.MODBUS_TEACH: LEVEL_WARN,
}
_PROGRAM_LEVEL = {
    ProgramState.STOPPED: LEVEL_OFF,
    ProgramState.RUNNING: LEVEL_OK,
    ProgramState.PAUSED: LEVEL_WARN,
}
_LAMP_POINTS = 11.0


def _protocol_tr(text: str) -> str:
    return QCoreApplication.translate(TR_CONTEXT, text)


def _enum_text(enum_type: Any, texts: dict[Any, str], value: int) -> tuple[Any, str]:
    """(member or None, translated text) of a table-2 value; unknown values say their code."""
    try:
        member = enum_type(value)
    except ValueError:
        return None, _protocol_tr(UNKNOWN_STATUS_TEXT).format(code=value)
    return member, _protocol_tr(texts[member])


PREFERRED_WIDTH = 240  # px


class StatusPanel(QWidget):
    """Shows ControllerStatus, link state, RTT, the last CommandResult and the controller clock.

    The last payload of each slot is kept only to redraw it after a language change.
    """

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("StatusPanel")
        self._alarms: int | None = None
        self._status: ControllerStatus | None = None
        self._connection: ConnectionState | None = None
        self._refusal: str | None = None  # the guard rails' last refusal, newer than the last result
        self._rtt: float | None = None
        self._result: CommandResult | None = None
        self._clock: ControllerClock | None = None
        self._drift: float | None = None
        self._fresh = True  # unbound: every payload shown is taken as live
        self._build_ui()
        self.retranslate()

    def _build_ui(self) -> None:
        # Link.
        self._link_box = QGroupBox(self)
        link_form = QFormLayout(self._link_box)
        link_form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        self.link_lamp = Lamp("", self._link_box, point_size=_LAMP_POINTS)
        self.link_message = QLabel("", self._link_box)
        self.link_message.setWordWrap(True)
        self.link_message.setStyleSheet(f"color: {COLOR_NEUTRAL};")
        self.link_message.setVisible(False)
        # RTT, clock and drift change while streaming (twice and once a second): LiveLabels
        # repaint themselves only, never re-lay out the dock and the window around them
        self.rtt_label = LiveLabel("—", self._link_box)
        self.rtt_label.setFont(monospace_font(12))
        self._row_labels: dict[str, QLabel] = {}
        link_form.addRow(self._row_label("state"), self.link_lamp)
        link_form.addRow("", self.link_message)
        link_form.addRow(self._row_label("rtt"), self.rtt_label)

        # Controller.
        self._ctrl_box = QGroupBox(self)
        ctrl_form = QFormLayout(self._ctrl_box)
        ctrl_form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        self.mode_label = Lamp("—", self._ctrl_box, point_size=_LAMP_POINTS + 1)
        self.program_label = Lamp("—", self._ctrl_box, point_size=_LAMP_POINTS + 1)
        self.clock_label = LiveLabel("—", self._ctrl_box)
        self.clock_label.setFont(monospace_font(10))  # "YYYY-MM-DD hh:mm:ss" fits the narrow status dock
        self.clock_label.fit_texts(["8888-88-88 88:88:88"])
        self.drift_label = LiveLabel("", self._ctrl_box)
        self.drift_label.setFont(monospace_font(11))
        self.command_label = QLabel("", self._ctrl_box)
        self.command_label.setWordWrap(True)
        self.command_label.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Preferred)
        self.command_label.setProperty("ok", None)
        self.command_label.setStyleSheet(f"color: {COLOR_NEUTRAL};")
        ctrl_form.addRow(self._row_label("mode"), self.mode_label)
        ctrl_form.addRow(self._row_label("program"), self.program_label)
        ctrl_form.addRow(self._row_label("command"), self.command_label)
        ctrl_form.addRow(self._row_label("clock"), self.clock_label)
        ctrl_form.addRow(self._row_label("drift"), self.drift_label)

        # Alarms: one lamp per documented bit, plus one for undocumented bits.
        self._alarm_box = QGroupBox(self)
        alarm_grid = QGridLayout(self._alarm_box)
        alarm_grid.setSpacing(6)
        self._alarm_grid = alarm_grid
        self._alarm_columns = 0
        self.alarm_lamps: dict[int, AlarmLamp] = {}
        for bit in ALARM_BITS:
            lamp = AlarmLamp("", self._alarm_box, point_size=_LAMP_POINTS)
            self.alarm_lamps[int(bit)] = lamp
        self.other_alarm_lamp = AlarmLamp("", self._alarm_box, point_size=_LAMP_POINTS)
        for lamp in self._all_alarm_lamps():
            # The grid reflows (two columns, or one on a narrow dock): the lamps set no minimum width.
            lamp.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Fixed)
        self._layout_alarms(2)

        for label in (self.rtt_label, self.clock_label, self.drift_label, self.command_label):
            label.setMinimumHeight(28)
            label.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addWidget(self._link_box)
        layout.addWidget(self._ctrl_box)
        layout.addWidget(self._alarm_box)
        layout.addStretch(1)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Preferred)

    def sizeHint(self) -> QSize:
        # Narrow by default: the work tabs need the room; the dock can be widened by hand.
        hint = super().sizeHint()
        return QSize(min(hint.width(), PREFERRED_WIDTH), hint.height())

    def _all_alarm_lamps(self) -> list[AlarmLamp]:
        return [*self.alarm_lamps.values(), self.other_alarm_lamp]

    def _layout_alarms(self, columns: int) -> None:
        if columns == self._alarm_columns:
            return
        self._alarm_columns = columns
        grid = self._alarm_grid
        lamps = self._all_alarm_lamps()
        for lamp in lamps:
            grid.removeWidget(lamp)
        for i, lamp in enumerate(lamps):
            grid.addWidget(lamp, i // columns, i % columns)
        for column in range(2):
            grid.setColumnStretch(column, 1 if column < columns else 0)

    @property
    def alarm_columns(self) -> int:
        return self._alarm_columns

    def resizeEvent(self, event: QResizeEvent) -> None:
        self._reflow_alarms(event.size().width())
        super().resizeEvent(event)

    def _reflow_alarms(self, width: int) -> None:
        """Two columns of lamps only when two of the widest fit side by side in ``width`` (what
        the panel's, the box's and the grid's margins and the grid's spacing leave), lit or not;
        the box keeps one column's width. Measured, not guessed: a guessed margin cut
        "编码器角度报警" by 2-6 px in a dock of 284-292 px."""
        widest = max(lamp.width_needed() for lamp in self._all_alarm_lamps())
        box = self._alarm_box.contentsMargins()
        grid = self._alarm_grid.contentsMargins()
        layout = self.layout()
        outer = layout.contentsMargins() if layout is not None else QMargins()
        around = box.left() + box.right() + grid.left() + grid.right()
        self._alarm_box.setMinimumWidth(widest + around)
        spacing = max(0, self._alarm_grid.horizontalSpacing())
        two = 2 * widest + spacing + around + outer.left() + outer.right()
        self._layout_alarms(2 if width >= two else 1)

    def _row_label(self, key: str) -> QLabel:
        # As tall as a lamp and centred, so the caption lines up with the lamp's text.
        label = QLabel(self)
        label.setMinimumHeight(28)
        label.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)
        self._row_labels[key] = label
        return label

    def retranslate(self) -> None:
        """(Re)set every user-visible text: at construction and on a language change."""
        self._link_box.setTitle(self.tr("Link"))
        self._ctrl_box.setTitle(self.tr("Controller"))
        self._alarm_box.setTitle(self.tr("Alarms") if self._fresh else self.tr("Alarms (last known)"))
        rows = self._row_labels
        rows["state"].setText(self.tr("State:"))
        rows["rtt"].setText(self.tr("RTT:"))
        rows["mode"].setText(self.tr("Mode:"))
        rows["program"].setText(self.tr("Program:"))
        rows["command"].setText(self.tr("Last command:"))
        rows["clock"].setText(self.tr("Clock:"))
        rows["drift"].setText(self.tr("Drift:"))
        self.rtt_label.setToolTip(self.tr("Round-trip time of the last poll"))
        self.rtt_label.fit_texts([self.tr("{ms} ms").format(ms="9999.9")])
        # a drift of up to ~3 years keeps the label's width (a wider one grows it once)
        drift = self.tr("{drift} s").format(drift="-99999999")
        self.drift_label.fit_texts([drift, self.tr("{value} (stale)").format(value=drift)])
        for bit in ALARM_BITS:
            lamp = self.alarm_lamps[int(bit)]
            lamp.setText(_protocol_tr(ALARM_TEXT[bit]))
            lamp.setToolTip(self.tr("Register 562 bit {bit}").format(bit=int(bit).bit_length() - 1))
        self.other_alarm_lamp.setToolTip(self.tr("Register 562 bits with no documented meaning"))
        if self.layout() is not None:  # (built once the texts are set; a new language reflows)
            self._reflow_alarms(self.width())
        # Redraw what the slots showed, in the new language.
        if self._connection is None:
            self.link_lamp.setText(self.tr("disconnected"))
        else:
            self._render_connection()
        self._render_rtt()
        self._render_status()
        self._render_alarms()
        if self._refusal is not None:
            self._render_refusal()
        elif self._result is None:
            self.command_label.setText(self.tr("none yet"))
        else:
            self._render_result()
        if self._clock is not None:
            self._render_clock()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- slots ------------------------------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Show ``state``'s fields from now on, starting with their current values."""
        state.connectionChanged.connect(self.on_connection)
        state.statusChanged.connect(self.on_status)
        state.alarmsChanged.connect(self.on_alarms)
        state.rttChanged.connect(self.on_rtt)
        state.lastResultChanged.connect(self.on_command_result)
        state.freshnessChanged.connect(self.on_freshness)
        self._fresh = state.fresh
        self.on_connection(state.connection)
        if state.status is not None:
            self.on_status(state.status)
        if state.rtt is not None:
            self.on_rtt(state.rtt)
        if state.last_result is not None:
            self.on_command_result(state.last_result)

    @Slot(object)
    def on_status(self, status: ControllerStatus) -> None:
        """Mode, program state, alarm bits and (when read along) the clock."""
        self._status = status
        self._render_status()
        self.on_alarms(int(status.alarms))
        if status.clock is not None:
            self.on_clock(status.clock)

    @Slot(bool)
    def on_freshness(self, fresh: bool) -> None:
        """Grey out (or bring back) what only a fresh poll can confirm."""
        if fresh == self._fresh:
            return
        self._fresh = fresh
        self._alarm_box.setTitle(self.tr("Alarms") if fresh else self.tr("Alarms (last known)"))
        self._render_status()
        if self._clock is not None:
            self._render_clock()

    @property
    def fresh(self) -> bool:
        return self._fresh

    @Slot(int)
    def on_alarms(self, alarms: int) -> None:
        alarms = int(alarms) & 0xFFFF
        if alarms != self._alarms:
            self._alarms = alarms
            self._render_alarms()

    @Slot(ConnectionState)
    def on_connection(self, connection: ConnectionState) -> None:
        self._connection = connection
        self._render_connection()
        self._render_rtt()

    @Slot(float)
    def on_rtt(self, ms: float) -> None:
        self._rtt = ms
        self._render_rtt()

    @Slot(object)
    def on_command_result(self, result: CommandResult) -> None:
        self._result = result
        self._refusal = None
        self._render_result()

    @Slot(str)
    def show_refusal(self, text: str) -> None:
        """A command the guard rails refused before it went out, or a jog they stopped ("X =
        560.2 mm is outside the allowed work space ..."): the operator's last command, in amber
        (until the next command's result)."""
        self._refusal = text
        self._render_refusal()

    def _render_refusal(self) -> None:
        text = self._refusal or ""
        self.command_label.setText(text)
        self.command_label.setProperty("ok", False)
        self.command_label.setStyleSheet(f"color: {COLOR_WARN}; font-weight: bold;")
        self.command_label.setToolTip(text)

    @Slot(object)
    def on_clock(self, clock: ControllerClock, now: dt.datetime | None = None) -> None:
        """Controller date/time, its drift from the PC clock (``now``, default: local now)."""
        self._clock = clock
        if clock.value is None:
            self._drift = None
        else:
            self._drift = (clock.value - (now or dt.datetime.now())).total_seconds()
        self._render_clock()

    def alarm_lamp_for(self, bit: int) -> AlarmLamp:
        return self.alarm_lamps[int(bit)]

    # --- drawing ----------------------------------------------------------------------
    def _render_status(self) -> None:
        status = self._status
        if status is None or not self._fresh:
            for lamp in (self.mode_label, self.program_label):
                lamp.setText("—" if status is None else self.tr("unknown"))
                lamp.set_level(LEVEL_OFF)
            return
        mode, text = _enum_text(ControllerMode, CONTROLLER_MODE_TEXT, int(status.mode))
        self.mode_label.setText(text)
        self.mode_label.set_level(_MODE_LEVEL.get(mode, LEVEL_ERROR))
        state, text = _enum_text(ProgramState, PROGRAM_STATE_TEXT, int(status.program_state))
        self.program_label.setText(text)
        self.program_label.set_level(_PROGRAM_LEVEL.get(state, LEVEL_ERROR))

    def _render_alarms(self) -> None:
        alarms = self._alarms or 0
        for bit, lamp in self.alarm_lamps.items():
            lamp.set_active(bool(alarms & bit))
        unknown = alarms & ~ALARM_MASK
        self.other_alarm_lamp.set_active(bool(unknown))
        if unknown:
            bits = join_names(str(b) for b in range(16) if unknown & (1 << b))
            self.other_alarm_lamp.setText(self.tr("other bits: {bits}").format(bits=bits))
        else:
            self.other_alarm_lamp.setText(self.tr("other bits"))
        if self.layout() is not None:
            self._reflow_alarms(self.width())  # the undocumented bits' lamp names them

    def _render_connection(self) -> None:
        connection = self._connection
        assert connection is not None
        text, level = connection_display(connection)
        self.link_lamp.setText(text)
        self.link_lamp.set_level(level)
        parts = [p for p in (connection.endpoint, connection_text(connection)) if p]
        if connection.monitor_only:
            parts.append(self.tr("monitor only: writes blocked"))
        self.link_message.setText(" — ".join(parts))
        self.link_message.setVisible(bool(parts))

    def _render_rtt(self) -> None:
        ms, connection = self._rtt, self._connection
        answering = connection is None or connection.state is LinkState.CONNECTED
        stale = ms is None or not math.isfinite(ms) or not answering  # down or silent: no round trip
        text = "—" if stale else self.tr("{ms} ms").format(ms=f"{ms:.1f}")
        if text != self.rtt_label.text():
            self.rtt_label.setText(text)

    def _render_result(self) -> None:
        result = self._result
        assert result is not None
        self.command_label.setText(result_text(result))  # one sentence, the operator's language
        self.command_label.setProperty("ok", bool(result.ok))
        level = result_level(result)  # the operator's own stop is not a failure
        color = {
            messages.LEVEL_INFO: COLOR_OK if result.ok else COLOR_NEUTRAL,
            messages.LEVEL_WARNING: COLOR_WARN,
        }.get(level, COLOR_ERROR)
        self.command_label.setStyleSheet(f"color: {color}; font-weight: bold;")
        tip = []
        if result.status is not None:
            tip.append(self.tr("GV291 code: {code}").format(code=result.status.code))
        tip.extend(f"{key} = {value:g}" for key, value in result.details.items())
        self.command_label.setToolTip("\n".join(tip))

    def _render_clock(self) -> None:
        clock = self._clock
        assert clock is not None
        last = _CLOCK_FIRST_REGISTER + len(clock.raw) - 1
        tip = self.tr("Raw words {first}..{last}: {words}").format(
            first=_CLOCK_FIRST_REGISTER, last=last, words=clock.raw_hex
        )
        _set_tip(self.clock_label, tip)
        _set_tip(self.drift_label, self.tr("Controller clock minus PC clock") + "\n" + tip)
        drift = self._drift
        self.drift_label.setProperty("drift", drift)
        if clock.value is None or drift is None:
            self.clock_label.setText(self.tr("invalid date/time"))
            self.clock_label.set_style(f"color: {COLOR_ERROR};")
            self.drift_label.setText("—")
            self.drift_label.set_style(f"color: {COLOR_NEUTRAL};")
            return
        stamp = clock.value.strftime("%Y-%m-%d %H:%M:%S")
        drift_text = self.tr("{drift} s").format(drift=f"{round(drift):+d}")  # never "-0"
        if not self._fresh:  # the last reading, no longer ticking: grey, italic, marked stale
            self.clock_label.setText(stamp)
            self.drift_label.setText(self.tr("{value} (stale)").format(value=drift_text))
            self.clock_label.set_style(f"color: {COLOR_NEUTRAL}; font-style: italic;")
            self.drift_label.set_style(f"color: {COLOR_NEUTRAL}; font-style: italic;")
            return
        self.drift_label.setText(drift_text)
        self.clock_label.setText(stamp)
        self.clock_label.set_style("")
        if abs(drift) > CLOCK_DRIFT_ERROR_S:
            color = COLOR_ERROR
        elif abs(drift) > CLOCK_DRIFT_WARN_S:
            color = COLOR_WARN
        else:
            color = COLOR_OK
        self.drift_label.set_style(f"color: {color};")


def _set_tip(label: QLabel, tip: str) -> None:
    if label.toolTip() != tip:  # each setToolTip sends the label an event
        label.setToolTip(tip)

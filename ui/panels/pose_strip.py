"""The pose strip: where the arm is, in what mode, and whether that is fresh, on every tab.

One row above the work tabs: X Y Z (mm) A B C (°), the controller's mode and program state, and
the link's freshness ("live", "stale 3 s", "not answering", "disconnected"). Bound to a
:class:`~app.link.state.RobotState` only. Every part has a fixed width computed from the widest
value (the widest digit of the font in use) or text in every shipped language, so nothing moves
when a text changes; a value wider than its room (-12345.67, a garbled float) reads ``######``,
the whole value in its tooltip, never a cut number.

When the values are not fresh (no good poll within the state's freshness limit, or the link
not CONNECTED) the numbers keep their last known value but turn grey and italic, the chips say
"unknown", and the freshness part counts the age up once a second. Nothing looks live that isn't.

Width: the strip asks for its compact width (no units, no chip captions) and takes what it is
given; given less than its full width (a 1024 px window) it hides the units and the captions.
That depends on the width only, never on a text, and a toolbar never moves it to its overflow.
"""

from __future__ import annotations

import math

from PySide6.QtCore import QCoreApplication, QEvent, QSize, Qt, QTimer, Slot
from PySide6.QtGui import QFont, QHideEvent, QResizeEvent, QShowEvent
from PySide6.QtWidgets import QFrame, QHBoxLayout, QLabel, QSizePolicy, QWidget

from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState
from app.models import ControllerStatus, Pose
from app.protocol.enums import (
    CARTESIAN_AXIS_NAMES,
    CONTROLLER_MODE_TEXT,
    PROGRAM_STATE_TEXT,
    QT_TRANSLATE_NOOP,
    TR_CONTEXT,
    UNKNOWN_STATUS_TEXT,
    ControllerMode,
    ProgramState,
)
from ui.display_clock import DisplayClock
from ui.palette import (
    COLOR_BORDER,
    COLOR_ERROR,
    COLOR_INFO,
    COLOR_INK,
    COLOR_NEUTRAL,
    COLOR_NEUTRAL_BG,
    COLOR_OK,
    COLOR_STALE,
    COLOR_STALE_BG,
    COLOR_WARN,
    COLOR_WHITE,
)
from ui.text_fit import both_languages, fit_in_every_language, fit_width
from ui.widgets.number_text import fit_number, number_room, number_text
from ui.widgets_common import monospace_font, neutral_text

__all__ = ["AGE_TICK_MS", "PoseStrip"]

CTX = "PoseStrip"
AGE_TICK_MS = 1000  # the stale age counts up at this period (only while stale and shown)
VALUE_INTEGER_DIGITS = 4  # the strip keeps room for -8888.88 in the widest digit of its font
VALUE_DECIMALS = 2
VALUE_PADDING = 4  # px
VALUE_POINTS = 12.0
CHIP_PADDING = 20  # px: the chips' left + right padding and border
CHIP_SLACK = 4  # px more than the widest text: elision measures a pixel or two wider
# Freshness texts (the "stale" one gets its age).
_LIVE = QT_TRANSLATE_NOOP("PoseStrip", "live")
_STALE = QT_TRANSLATE_NOOP("PoseStrip", "stale {age} s")
_STALE_NO_AGE = QT_TRANSLATE_NOOP("PoseStrip", "stale")
_UNKNOWN = QT_TRANSLATE_NOOP("PoseStrip", "unknown")
_LINK_TEXT = {
    LinkState.DISCONNECTED: QT_TRANSLATE_NOOP("PoseStrip", "disconnected"),
    LinkState.CONNECTING: QT_TRANSLATE_NOOP("PoseStrip", "connecting"),
    LinkState.NOT_ANSWERING: QT_TRANSLATE_NOOP("PoseStrip", "not answering"),
    LinkState.DOWN: QT_TRANSLATE_NOOP("PoseStrip", "link down"),
}
_MODE_COLORS = {  # background, text
    ControllerMode.MANUAL: (COLOR_BORDER, COLOR_INK),
    ControllerMode.AUTO: (COLOR_INFO, COLOR_WHITE),
    ControllerMode.MODBUS_TEACH: (COLOR_WARN, COLOR_WHITE),
}
_PROGRAM_COLORS = {
    ProgramState.STOPPED: (COLOR_BORDER, COLOR_INK),
    ProgramState.RUNNING: (COLOR_OK, COLOR_WHITE),
    ProgramState.PAUSED: (COLOR_WARN, COLOR_WHITE),
}
_UNKNOWN_COLORS = (COLOR_NEUTRAL_BG, COLOR_NEUTRAL)


def _tr(text: str) -> str:
    return QCoreApplication.translate(CTX, text)


def _chip_style(background: str, color: str) -> str:
    return (
        f"QLabel {{ background-color: {background}; color: {color}; border: 1px solid {COLOR_BORDER};"
        " border-radius: 5px; padding: 2px 8px; }"
    )


class PoseStrip(QFrame):
    """See the module docstring. ``is_live()``: the strip shows fresh values now."""

    def __init__(self, parent: QWidget | None = None, *, clock: DisplayClock | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("PoseStrip")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.setAutoFillBackground(True)  # opaque: a new value repaints the strip, not the window under it
        self._state: RobotState | None = None
        self._age_timer = QTimer(self)
        self._age_timer.setInterval(AGE_TICK_MS)
        self._age_timer.timeout.connect(self._show_freshness)
        # Poses arrive at the poll rate; the numbers are redrawn in the display clock's frames
        # (with the monitor's): the first pose after a quiet spell at once, then the latest one
        # per frame. Hidden, nothing is drawn until shown.
        self._clock = clock if clock is not None else DisplayClock.shared()
        self._shown_style: bool | None = None  # the liveness the value labels are styled for

        bold = QFont(self.font())
        bold.setBold(True)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(6, 2, 6, 2)
        layout.setSpacing(4)
        self.captions: dict[str, QLabel] = {}
        self.values: dict[str, QLabel] = {}
        self.units: dict[str, QLabel] = {}
        for name in CARTESIAN_AXIS_NAMES:
            caption = QLabel(name, self)
            caption.setFont(bold)
            neutral_text(caption)
            value = QLabel("—", self)
            value.setObjectName(f"PoseStripValue{name}")
            value.setFont(monospace_font(VALUE_POINTS, bold=True))
            value.setAlignment(Qt.AlignmentFlag.AlignRight | Qt.AlignmentFlag.AlignVCenter)
            # a fixed size: a new value repaints the label only, never re-lays out the window;
            # opaque (it fills its own background, the strip's colour while live): the strip
            # under it is not repainted with it at every new value
            room = number_room(value.fontMetrics(), VALUE_INTEGER_DIGITS, VALUE_DECIMALS)
            value.setFixedSize(room + VALUE_PADDING, value.sizeHint().height())
            value.setAutoFillBackground(True)
            unit = QLabel(self)
            neutral_text(unit)
            self.captions[name], self.values[name], self.units[name] = caption, value, unit
            layout.addWidget(caption)
            layout.addWidget(value)
            layout.addWidget(unit)
            layout.addSpacing(2)
        layout.addStretch(1)
        self.mode_caption = QLabel(self)
        self.mode_chip = QLabel(self)
        self.program_caption = QLabel(self)
        self.program_chip = QLabel(self)
        self.freshness = QLabel(self)
        self.freshness.setObjectName("PoseStripFreshness")
        for chip in (self.mode_chip, self.program_chip, self.freshness):
            chip.setFont(bold)
            chip.setAlignment(Qt.AlignmentFlag.AlignCenter)
        for caption_label in (self.mode_caption, self.program_caption):
            neutral_text(caption_label)
        fit_in_every_language(self._fix_widths)
        for widget in (
            self.mode_caption,
            self.mode_chip,
            self.program_caption,
            self.program_chip,
            self.freshness,
        ):
            layout.addWidget(widget)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.retranslate()
        self._optional = [*self.units.values(), self.mode_caption, self.program_caption]
        self._full_width = layout.sizeHint().width()
        spacing = layout.spacing()
        self._compact_width = self._full_width - sum(w.maximumWidth() + spacing for w in self._optional)
        self._compact = False

    def sizeHint(self) -> QSize:
        return QSize(self._compact_width, super().sizeHint().height())

    def minimumSizeHint(self) -> QSize:
        return QSize(self._compact_width, super().minimumSizeHint().height())

    @property
    def compact(self) -> bool:
        """Units and chip captions hidden: the strip has less than its full width."""
        return self._compact

    def resizeEvent(self, event: QResizeEvent) -> None:
        compact = event.size().width() < self._full_width
        if compact != self._compact:
            self._compact = compact
            for widget in self._optional:
                widget.setVisible(not compact)
        super().resizeEvent(event)

    def _fix_widths(self) -> None:
        units = [*both_languages("PoseStrip", "mm"), "°"]
        for unit in self.units.values():
            unit.setFixedWidth(fit_width(unit, units, padding=2))
        # an undocumented mode code ("unknown status 7") is rare: it elides, the tooltip has it
        proto = [t for text in CONTROLLER_MODE_TEXT.values() for t in both_languages(TR_CONTEXT, text)]
        unknown = both_languages(CTX, _UNKNOWN)
        pad = CHIP_PADDING + CHIP_SLACK
        self.mode_chip.setFixedWidth(fit_width(self.mode_chip, [*proto, *unknown], pad))
        program = [t for text in PROGRAM_STATE_TEXT.values() for t in both_languages(TR_CONTEXT, text)]
        self.program_chip.setFixedWidth(fit_width(self.program_chip, [*program, *unknown], pad))
        fresh = [
            t for text in (_LIVE, _STALE_NO_AGE, *_LINK_TEXT.values()) for t in both_languages(CTX, text)
        ]
        fresh += [t.format(age=888) for t in both_languages(CTX, _STALE)]
        self.freshness.setFixedWidth(fit_width(self.freshness, fresh, pad))
        self.mode_caption.setFixedWidth(fit_width(self.mode_caption, both_languages(CTX, "Mode"), 4))
        self.program_caption.setFixedWidth(fit_width(self.program_caption, both_languages(CTX, "Program"), 4))

    def retranslate(self) -> None:
        for i, name in enumerate(CARTESIAN_AXIS_NAMES):
            self.units[name].setText(self.tr("mm") if i < 3 else "°")
        self.mode_caption.setText(self.tr("Mode"))
        self.program_caption.setText(self.tr("Program"))
        self.mode_chip.setToolTip(self.tr("The controller's work mode (register 560)"))
        self.program_chip.setToolTip(self.tr("The controller's program state (register 561)"))
        self.freshness.setToolTip(
            self.tr("Whether the values shown were confirmed by the controller within the freshness limit")
        )
        self._refresh()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- the model ------------------------------------------------------------------------
    def bind(self, state: RobotState) -> None:
        """Show ``state`` from now on, starting with its current values."""
        self._state = state
        state.poseChanged.connect(self._on_pose)
        state.statusChanged.connect(self._on_status)
        state.freshnessChanged.connect(self._on_freshness)
        state.connectionChanged.connect(self._on_connection)
        self._refresh()

    def is_live(self) -> bool:
        return self._state is not None and self._state.fresh

    def freshness_text(self) -> str:
        return self.freshness.text()

    def value_text(self, axis: str) -> str:
        return self.values[axis].text()

    @Slot(Pose)
    def _on_pose(self, _pose: Pose) -> None:
        if self.isVisible():  # hidden: showEvent draws the latest
            self._clock.run_or_request(self._show_pose)

    @Slot(ControllerStatus)
    def _on_status(self, _status: ControllerStatus) -> None:
        self._show_status()

    @Slot(bool)
    def _on_freshness(self, _fresh: bool) -> None:
        self._refresh()

    @Slot(ConnectionState)
    def _on_connection(self, _connection: ConnectionState) -> None:
        self._refresh()

    # --- drawing --------------------------------------------------------------------------
    def _refresh(self) -> None:
        self._show_pose()
        self._show_status()
        self._show_freshness()
        self._update_timer()

    def _show_pose(self) -> None:
        pose = self._state.pose if self._state is not None else None
        live = self.is_live()
        if live != self._shown_style:
            self._shown_style = live
            color = COLOR_INK if live else COLOR_STALE
            style = "normal" if live else "italic"
            # live: no background of its own, so the label fills with the strip's (an opaque
            # label); a transparent one repainted the strip under it at every new value
            background = "" if live else f" background: {COLOR_STALE_BG};"
            sheet = f"QLabel {{ color: {color}; font-style: {style};{background} }}"
            for label in self.values.values():
                label.setStyleSheet(sheet)
                label.setProperty("stale", not live)
        values = pose.xyzabc if pose is not None else (math.nan,) * len(CARTESIAN_AXIS_NAMES)
        for name, value in zip(CARTESIAN_AXIS_NAMES, values, strict=True):
            self._show_value(name, number_text(value, VALUE_DECIMALS) if math.isfinite(value) else "—")

    def _show_value(self, name: str, text: str) -> None:
        """``text`` whole, or ``######`` with the whole value in the tooltip: never a cut number."""
        label = self.values[name]
        shown = fit_number(text, label.fontMetrics(), label.contentsRect().width())
        if label.text() != shown:
            label.setText(shown)
        tip = "" if shown == text else f"{name} = {text} {self.units[name].text()}"
        if label.toolTip() != tip:
            label.setToolTip(tip)

    def _show_status(self) -> None:
        status = self._state.status if self._state is not None else None
        if status is None or not self.is_live():
            self._set_chip(self.mode_chip, self.tr("unknown"), _UNKNOWN_COLORS)
            self._set_chip(self.program_chip, self.tr("unknown"), _UNKNOWN_COLORS)
            return
        try:
            mode: ControllerMode | None = ControllerMode(int(status.mode))
        except ValueError:
            mode = None
        text = (
            QCoreApplication.translate(TR_CONTEXT, CONTROLLER_MODE_TEXT[mode])
            if mode is not None
            else QCoreApplication.translate(TR_CONTEXT, UNKNOWN_STATUS_TEXT).format(code=int(status.mode))
        )
        self._set_chip(
            self.mode_chip,
            text,
            _MODE_COLORS.get(mode, (COLOR_ERROR, COLOR_WHITE))
            if mode is not None
            else (COLOR_ERROR, COLOR_WHITE),
        )
        try:
            program: ProgramState | None = ProgramState(int(status.program_state))
        except ValueError:
            program = None
        text = (
            QCoreApplication.translate(TR_CONTEXT, PROGRAM_STATE_TEXT[program])
            if program is not None
            else QCoreApplication.translate(TR_CONTEXT, UNKNOWN_STATUS_TEXT).format(
                code=int(status.program_state)
            )
        )
        self._set_chip(
            self.program_chip,
            text,
            _PROGRAM_COLORS[program] if program is not None else (COLOR_ERROR, COLOR_WHITE),
        )

    def _set_chip(self, chip: QLabel, text: str, colors: tuple[str, str]) -> None:
        metrics = chip.fontMetrics()
        room = chip.maximumWidth() - CHIP_PADDING
        shown = metrics.elidedText(text, Qt.TextElideMode.ElideRight, max(room, 10))
        if chip.text() != shown:
            chip.setText(shown)
        if shown != text and chip.toolTip() != text:  # each setToolTip sends the chip an event
            chip.setToolTip(text)
        sheet = _chip_style(*colors)
        if chip.styleSheet() != sheet:
            chip.setStyleSheet(sheet)

    @Slot()
    def _show_freshness(self) -> None:
        state = self._state
        if state is None:
            text, colors = _tr(_LINK_TEXT[LinkState.DISCONNECTED]), _UNKNOWN_COLORS
        elif state.connection.state is not LinkState.CONNECTED:
            state_kind = state.connection.state
            text = _tr(_LINK_TEXT[state_kind])
            colors = (
                (COLOR_ERROR, COLOR_WHITE)
                if state_kind in (LinkState.NOT_ANSWERING, LinkState.DOWN)
                else _UNKNOWN_COLORS
            )
        elif state.fresh:
            text, colors = _tr(_LIVE), (COLOR_OK, COLOR_WHITE)
        else:
            age = state.age()
            text = _tr(_STALE_NO_AGE) if age is None else _tr(_STALE).format(age=f"{min(age, 999):.0f}")
            colors = (COLOR_WARN, COLOR_WHITE)
        self.freshness.setProperty("live", bool(state is not None and state.fresh))
        self._set_chip(self.freshness, text, colors)

    def _update_timer(self) -> None:
        want = (
            self._state is not None
            and not self._state.fresh
            and self._state.connection.state is LinkState.CONNECTED
            and self.isVisible()
        )
        if want and not self._age_timer.isActive():
            self._age_timer.start()
        elif not want:
            self._age_timer.stop()

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self._refresh()

    def hideEvent(self, event: QHideEvent) -> None:
        self._age_timer.stop()
        self._clock.cancel(self._show_pose)
        super().hideEvent(event)

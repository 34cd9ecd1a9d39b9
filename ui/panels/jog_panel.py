"""Jog (teach, function 4): hold a ± button or a key to move, let go to stop.

The speed slider shows the ratio the jog goes out at: when the envelope caps it (reduced-speed
mode, or the envelope's maximum jog speed; :meth:`JogPanel.set_ratio_cap`) the value reads
"50 % → 10 % (reduced speed)" (or "50 % → 40 %"), highlighted, with the reason in its tooltip.

Dead-man everywhere: a jog lasts exactly as long as the button or key is held. It also ends
when the panel loses the keyboard focus, when the window is deactivated or closed, and when
the link goes down (the main window calls :meth:`JogPanel.release_all`). A button that was
cancelled that way needs a fresh press: dragging back onto it does not restart the motion.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from PySide6.QtCore import QEvent, QObject, Qt, Signal, Slot
from PySide6.QtGui import QKeyEvent, QMouseEvent
from PySide6.QtWidgets import (
    QApplication,
    QCheckBox,
    QComboBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSizePolicy,
    QSlider,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.link.types import HaltKind, JogRequest, UnconfirmedHalt
from app.protocol.enums import CARTESIAN_AXIS_NAMES, JOINT_AXIS_NAMES, TeachFrame
from app.protocol.registers import NUM_AXES_TOTAL, NUM_ROBOT_AXES, TOOL_NONE
from ui.touch import MOTION_MIN_HEIGHT, RowsScrollArea, mark_motion
from ui.widgets_common import neutral_text

DEFAULT_RATIO = 20
# Keyboard jog: axis n (1..6) plus / minus. Letters on two rows of a QWERTY keyboard.
PLUS_KEYS: tuple[Qt.Key, ...] = (
    Qt.Key.Key_Q,
    Qt.Key.Key_W,
    Qt.Key.Key_E,
    Qt.Key.Key_R,
    Qt.Key.Key_T,
    Qt.Key.Key_Y,
)
MINUS_KEYS: tuple[Qt.Key, ...] = (
    Qt.Key.Key_A,
    Qt.Key.Key_S,
    Qt.Key.Key_D,
    Qt.Key.Key_F,
    Qt.Key.Key_G,
    Qt.Key.Key_H,
)
_FRAMES: tuple[TeachFrame, ...] = (TeachFrame.BASE, TeachFrame.USER, TeachFrame.TOOL, TeachFrame.JOINT)
BUTTON_WIDTH = 44  # px, the least width of a ± button (two columns of them fit the control column)
EXTERNAL_COLUMN = 4  # grid column where the external axes start (joint frame: J7..J11 on the right)


_HOLD_STYLE = "QLabel { color: #ef8f00; font-weight: bold; font-size: 15px; }"
_HALT_STYLE = "QLabel { color: #ffffff; background: #c62828; font-weight: bold; font-size: 15px; }"


@dataclass(frozen=True)
class _Held:
    source: str  # "mouse" or "key:<code>"
    axis: int
    direction: int


class JogButton(QPushButton):
    """A hold-to-move button: ``held`` on press, ``letGo`` on release or when the pointer leaves."""

    held = Signal()
    letGo = Signal()

    def __init__(self, text: str, parent: QWidget | None = None) -> None:
        super().__init__(text, parent)
        self._held = False
        self.setAutoRepeat(False)
        self.setFocusPolicy(Qt.FocusPolicy.NoFocus)  # keep the keyboard focus on the panel
        self.setMinimumSize(BUTTON_WIDTH, MOTION_MIN_HEIGHT)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        mark_motion(self)
        font = self.font()
        font.setPointSizeF(font.pointSizeF() * 1.3)
        font.setBold(True)
        self.setFont(font)

    @property
    def is_held(self) -> bool:
        return self._held

    def mousePressEvent(self, event: QMouseEvent) -> None:
        if event.button() != Qt.MouseButton.LeftButton or not self.isEnabled():
            event.ignore()
            return
        event.accept()
        self._held = True
        self.setDown(True)
        self.held.emit()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        event.accept()
        if event.button() == Qt.MouseButton.LeftButton:
            self._let_go()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        event.accept()
        if self._held and not self.rect().contains(event.position().toPoint()):
            self._let_go()  # sliding off the button is letting go

    def cancel(self) -> None:
        """Drop the hold without a signal (the panel already released the jog)."""
        self._held = False
        self.setDown(False)

    def _let_go(self) -> None:
        if self._held:
            self._held = False
            self.setDown(False)
            self.letGo.emit()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.EnabledChange and not self.isEnabled():
            self._let_go()
        super().changeEvent(event)


class JogPanel(QWidget):
    """Frame, ± buttons per axis, speed slider, keyboard jogging; emits press / release."""

    jogPressed = Signal(JogRequest)
    jogReleased = Signal()
    ratioChanged = Signal(float)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("JogPanel")
        self.setFocusPolicy(Qt.FocusPolicy.StrongFocus)
        self._held: _Held | None = None
        #: when the jog was let go (``time.monotonic()``): set while jogReleased is emitted for that
        #: release, None otherwise
        self.released_at: float | None = None
        self._motion_enabled = False
        self._halt: UnconfirmedHalt | None = None  # a stop the controller has not confirmed
        self._ratio_cap: float | None = None  # the envelope's cap in force (None: no envelope)
        self._reduced = False  # the cap is reduced-speed mode's
        self._room = False  # the motion area's refusal line is shown under the panel (make_room)

        # compact rows: 6 rows of 40 px buttons fit a 1280×800 screen under the docks
        self.frame_box = QWidget(self)
        self.frame_caption = QLabel(self.frame_box)
        self.frame_combo = QComboBox(self.frame_box)
        for frame in _FRAMES:
            self.frame_combo.addItem("", int(frame))
        self.frame_combo.currentIndexChanged.connect(self._on_frame_changed)
        self.frame_combo.installEventFilter(self)
        self.user_label = QLabel(self.frame_box)
        self.user_spin = QSpinBox(self.frame_box)
        self.user_spin.setRange(0, 0xFFFF)
        self.tool_label = QLabel(self.frame_box)
        self.tool_spin = QSpinBox(self.frame_box)
        self.tool_spin.setRange(0, TOOL_NONE - 1)
        frame_row = QHBoxLayout(self.frame_box)
        frame_row.setContentsMargins(0, 0, 0, 0)
        frame_row.addWidget(self.frame_caption)
        frame_row.addWidget(self.frame_combo, 1)
        frame_row.addWidget(self.user_label)
        frame_row.addWidget(self.user_spin)
        frame_row.addWidget(self.tool_label)
        frame_row.addWidget(self.tool_spin)
        # touch mode, joint frame: the rows show J1..J6 or, checked, J7..J11 (see _arrange)
        self.external_check = QCheckBox(self.frame_box)
        self.external_check.setObjectName("JogExternalAxes")
        self.external_check.toggled.connect(self._on_external_toggled)
        frame_row.addWidget(self.external_check)
        self._touch = False

        # the rows scroll only where they cannot fit (touch mode on a 800 px screen)
        self.axes_box = QGroupBox(self)
        self.axes_rows = QWidget()
        self.axes_rows.setObjectName("JogAxes")
        self.axes_scroll = RowsScrollArea(self.axes_rows, self.axes_box)
        box_layout = QVBoxLayout(self.axes_box)
        box_layout.setContentsMargins(4, 0, 4, 2)  # 11 joint axes fit 1280×800 in Chinese too
        box_layout.addWidget(self.axes_scroll)
        grid = QGridLayout(self.axes_rows)
        grid.setContentsMargins(0, 0, 0, 0)
        grid.setHorizontalSpacing(8)
        grid.setVerticalSpacing(2)
        self.axis_labels: list[QLabel] = []
        self.minus_buttons: list[JogButton] = []
        self.plus_buttons: list[JogButton] = []
        for axis in range(NUM_AXES_TOTAL):
            label = QLabel(self.axes_rows)
            label.setAlignment(Qt.AlignmentFlag.AlignCenter)
            label.setMinimumWidth(label.fontMetrics().horizontalAdvance("J11") + 8)
            font = label.font()
            font.setBold(True)
            font.setPointSizeF(font.pointSizeF() * 1.2)
            label.setFont(font)
            minus = JogButton("−", self.axes_rows)
            plus = JogButton("+", self.axes_rows)
            minus.setObjectName(f"jog_minus_{axis}")
            plus.setObjectName(f"jog_plus_{axis}")
            minus.held.connect(lambda a=axis: self._press("mouse", a, 0))
            plus.held.connect(lambda a=axis: self._press("mouse", a, 1))
            minus.letGo.connect(lambda: self._release("mouse"))
            plus.letGo.connect(lambda: self._release("mouse"))
            self.axis_labels.append(label)
            self.minus_buttons.append(minus)
            self.plus_buttons.append(plus)
        self.external_caption = QLabel(self.axes_rows)
        neutral_text(self.external_caption)
        self.external_caption.setAlignment(Qt.AlignmentFlag.AlignCenter)
        grid.addWidget(self.external_caption, 0, EXTERNAL_COLUMN, 1, 3)
        grid.setColumnMinimumWidth(EXTERNAL_COLUMN - 1, 8)
        grid.setRowStretch(NUM_ROBOT_AXES, 1)  # spare height below the rows, not between them
        self._grid = grid
        self._arrange()

        self.hold_label = QLabel(self)
        self.hold_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.hold_label.setWordWrap(True)
        self.hold_label.setStyleSheet(_HOLD_STYLE)

        self.speed_caption = QLabel(self)
        self.speed_slider = QSlider(Qt.Orientation.Horizontal, self)
        self.speed_slider.setRange(1, 100)
        self.speed_slider.setValue(DEFAULT_RATIO)
        self.speed_slider.setPageStep(10)
        self.speed_slider.installEventFilter(self)
        self.speed_value = QLabel(self)
        self.speed_value.setObjectName("JogSpeedValue")
        self.speed_value.setMinimumWidth(self.speed_value.fontMetrics().horizontalAdvance("100 %") + 8)
        self.speed_slider.valueChanged.connect(self._on_speed_changed)
        speed_row = QHBoxLayout()
        speed_row.addWidget(self.speed_caption)
        speed_row.addWidget(self.speed_slider, 1)
        speed_row.addWidget(self.speed_value)

        self.keys_label = QLabel(self)  # one short line; the whole hint is its tooltip
        neutral_text(self.keys_label)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 4)
        layout.setSpacing(4)
        layout.addWidget(self.frame_box)
        layout.addLayout(speed_row)
        layout.addWidget(self.hold_label)
        layout.addWidget(self.axes_box, 1)
        layout.addWidget(self.keys_label)

        app = QApplication.instance()
        if isinstance(app, QApplication):
            app.focusChanged.connect(self._on_focus_changed)
        self.set_motion_enabled(False)
        self.retranslate()

    # --- texts ------------------------------------------------------------------------
    def retranslate(self) -> None:
        self.frame_caption.setText(self.tr("Frame:"))
        names = {
            TeachFrame.BASE: self.tr("Base frame"),
            TeachFrame.USER: self.tr("User frame"),
            TeachFrame.TOOL: self.tr("Tool frame"),
            TeachFrame.JOINT: self.tr("Joint frame"),
        }
        for i, frame in enumerate(_FRAMES):
            self.frame_combo.setItemText(i, names[frame])
        self.user_label.setText(self.tr("User no.:"))
        self.tool_label.setText(self.tr("Tool no.:"))
        self.external_caption.setText(self.tr("External axes"))
        self.external_check.setText(self.tr("J7–J11"))
        self.external_check.setToolTip(self.tr("Touch mode: the rows show the external axes J7–J11"))
        self._show_halt()
        self.speed_caption.setText(self.tr("Speed:"))
        self._show_speed()
        plus = " ".join(k.name[-1] for k in PLUS_KEYS)
        minus = " ".join(k.name[-1] for k in MINUS_KEYS)
        keys = self.tr(
            "Keyboard: click this panel, then hold {plus} (+) or {minus} (−) for axes 1–6; "
            "releasing the key stops."
        ).format(plus=plus, minus=minus)
        short = self.tr("Keys: hold {plus} (+) or {minus} (−)")
        self.keys_label.setText(short.format(plus=plus, minus=minus))
        self.keys_label.setToolTip(keys)
        self.setToolTip(keys)
        self._update_axes()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public -----------------------------------------------------------------------
    @property
    def frame(self) -> TeachFrame:
        return TeachFrame(int(self.frame_combo.currentData()))

    def set_frame(self, frame: TeachFrame) -> None:
        self.frame_combo.setCurrentIndex(_FRAMES.index(TeachFrame(frame)))

    @property
    def ratio(self) -> int:
        return int(self.speed_slider.value())

    def set_ratio(self, ratio: int) -> None:
        self.speed_slider.setValue(int(ratio))

    def set_ratio_cap(self, cap: float | None, *, reduced: bool = False) -> None:
        """The jog ratio the envelope allows now (None: no envelope); ``reduced``: it is reduced-
        speed mode's cap. Shown at the slider whenever the slider is above it."""
        self._ratio_cap = cap
        self._reduced = reduced
        self._show_speed()

    @property
    def sent_ratio(self) -> float:
        """The ratio a jog goes out at: the slider's, capped by the envelope."""
        cap = self._ratio_cap
        return float(self.ratio) if cap is None else min(float(self.ratio), cap)

    @property
    def is_jogging(self) -> bool:
        return self._held is not None

    def axis_count(self) -> int:
        return NUM_AXES_TOTAL if self.frame is TeachFrame.JOINT else NUM_ROBOT_AXES

    def button(self, axis: int, direction: int) -> JogButton:
        return (self.plus_buttons if direction else self.minus_buttons)[axis]

    def set_motion_enabled(self, enabled: bool) -> None:
        """Off while the link is down or monitor-only: any jog is released at once."""
        self._motion_enabled = bool(enabled)
        if not enabled:
            self.release_all()
        self.axes_box.setEnabled(self._motion_enabled)
        self.hold_label.setEnabled(self._motion_enabled)

    @property
    def halt(self) -> UnconfirmedHalt | None:
        return self._halt

    @Slot(object)
    def show_halt(self, halt: UnconfirmedHalt | None) -> None:
        """A jog's stop (or a Stop) the controller has not confirmed: said where the jog is held,
        until the controller has answered and the arm is seen still (app/link/halt.py)."""
        self._halt = halt
        self._show_halt()

    @Slot(bool)
    def make_room(self, on: bool) -> None:
        """The motion area's refusal line is shown under the panel (ui/panels/jog_refusal.py): the
        keys hint and the standing "hold to move" instruction give it their height, so the six
        rows still fit a 1280×800 screen without a scroll bar; an unconfirmed stop stays shown."""
        self._room = on
        self.keys_label.setVisible(not on)
        self._show_halt()

    def _show_halt(self) -> None:
        halt = self._halt
        self.hold_label.setVisible(halt is not None or not self._room)
        if halt is None:
            self.hold_label.setStyleSheet(_HOLD_STYLE)
            self.hold_label.setText(self.tr("HOLD TO MOVE — release to stop"))
            self.hold_label.setToolTip("")
            return
        self.hold_label.setStyleSheet(_HALT_STYLE)
        if halt.kind is HaltKind.RELEASE:
            text = self.tr("Releasing — the controller has not confirmed")
        elif halt.kind is HaltKind.PAUSE:
            text = self.tr("Pausing — the controller has not confirmed; press STOP")
        else:
            text = self.tr("Stopping — the controller has not confirmed")
        tip = self.tr(
            "The controller refused or did not answer the write that stops the arm. TeachPad sends "
            "it again at every poll until the controller answers and the arm is seen still."
        )
        if halt.escalated:
            tip += "\n" + (
                self.tr("The Pause was not confirmed in time: Stop was sent instead.")
                if halt.kind is HaltKind.PAUSE
                else self.tr("Stop was sent too.")
            )
        self.hold_label.setText(text)
        self.hold_label.setToolTip(tip)

    @Slot()
    def release_all(self) -> None:
        """End any jog (focus loss, deactivation, close, link loss). Buttons need a new press."""
        for button in (*self.minus_buttons, *self.plus_buttons):
            button.cancel()
        if self._held is not None:
            self._held = None
            self._emit_release()

    # --- keyboard ---------------------------------------------------------------------
    def _key_axis(self, key: int) -> tuple[int, int] | None:
        for axis, (plus, minus) in enumerate(zip(PLUS_KEYS, MINUS_KEYS, strict=True)):
            if key == plus:
                return axis, 1
            if key == minus:
                return axis, 0
        return None

    def _handle_key(self, event: QKeyEvent) -> bool:
        mapping = self._key_axis(event.key())
        if mapping is None or event.modifiers() & ~Qt.KeyboardModifier.KeypadModifier:
            return False
        if event.isAutoRepeat():
            return True  # a held key repeats: the jog is already running
        axis, direction = mapping
        source = f"key:{event.key()}"
        if event.type() == QEvent.Type.KeyPress:
            self._press(source, axis, direction)
        else:
            self._release(source)
        return True

    def keyPressEvent(self, event: QKeyEvent) -> None:
        if not self._handle_key(event):
            super().keyPressEvent(event)

    def keyReleaseEvent(self, event: QKeyEvent) -> None:
        if not self._handle_key(event):
            super().keyReleaseEvent(event)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        # The frame combo and the slider would eat letters (keyboard search): jog keys win.
        if event.type() in (QEvent.Type.KeyPress, QEvent.Type.KeyRelease) and isinstance(event, QKeyEvent):
            return self._handle_key(event)
        return super().eventFilter(watched, event)

    # --- internals --------------------------------------------------------------------
    def _press(self, source: str, axis: int, direction: int) -> None:
        if not self._motion_enabled or axis >= self.axis_count():
            if source == "mouse":
                self.button(axis, direction).cancel()
            return
        held = _Held(source, axis, direction)
        if self._held == held:
            return
        self._light(self._held, False)
        self._held = held
        self._light(held, True)
        frame = self.frame
        self.jogPressed.emit(
            JogRequest(
                frame,
                axis,
                direction,
                float(self.ratio),
                user=self.user_spin.value(),
                tool=self.tool_spin.value(),
            )
        )

    def _release(self, source: str) -> None:
        held = self._held
        if held is None or held.source != source:
            return  # an older key let go while a newer one is held: the newer one goes on
        self._light(held, False)
        self._held = None
        self._emit_release()

    def _emit_release(self) -> None:
        # the time first: the release goes out in jogReleased's first slot (the motion controller),
        # the measuring (ui/controllers/stop_timing.py) reads this time after it; cleared after the
        # signal (see ControlBar._on_stop_clicked)
        self.released_at = time.monotonic()
        try:
            self.jogReleased.emit()
        finally:
            self.released_at = None

    def _light(self, held: _Held | None, on: bool) -> None:
        """A key jog shows its button pressed while the key is held (the mouse does that itself)."""
        if held is not None and held.source != "mouse":
            self.button(held.axis, held.direction).setDown(on)

    @Slot(int)
    def _on_frame_changed(self, _index: int) -> None:
        self.release_all()
        self._update_axes()

    def set_touch(self, touch: bool) -> None:
        """Touch mode: the rows in three lines of two (see :meth:`_arrange`)."""
        if touch != self._touch:
            self.release_all()
            self._touch = touch
            self._arrange()
            self._update_axes()

    @Slot(bool)
    def _on_external_toggled(self, _checked: bool) -> None:
        self.release_all()  # a held button may be hidden
        self._update_axes()

    def _arrange(self) -> None:
        """Place the rows. Compact: X..C (J1..J6) one under the other, in the joint frame J7..J11
        beside them under their caption (11 rows of 40 px would not fit a 800 px screen).
        Touch mode (56 px buttons; six rows do not fit under the control bar at 1280×800, issue 21):
        three lines of two, X Y Z beside A B C (J1 J2 J3 beside J4 J5 J6), and in the joint frame
        J7..J11 the same way in place of J1..J6 while *External axes* is checked."""
        grid = self._grid
        for axis in range(NUM_AXES_TOTAL):
            external = axis >= NUM_ROBOT_AXES
            if self._touch:
                index = axis - NUM_ROBOT_AXES if external else axis
                row, column = index % 3, (0 if index < 3 else EXTERNAL_COLUMN)
            else:
                row = axis - NUM_ROBOT_AXES + 1 if external else axis
                column = EXTERNAL_COLUMN if external else 0
            widgets = (self.minus_buttons[axis], self.axis_labels[axis], self.plus_buttons[axis])
            for offset, widget in enumerate(widgets):
                grid.removeWidget(widget)
                grid.addWidget(widget, row, column + offset)

    def _axis_shown(self, axis: int, joint: bool) -> bool:
        if not joint:
            return axis < NUM_ROBOT_AXES
        if not self._touch:
            return True
        return (axis >= NUM_ROBOT_AXES) == self.external_check.isChecked()

    def _update_axes(self) -> None:
        frame = self.frame
        joint = frame is TeachFrame.JOINT
        names = JOINT_AXIS_NAMES if joint else CARTESIAN_AXIS_NAMES
        for axis, label in enumerate(self.axis_labels):
            visible = self._axis_shown(axis, joint)
            if visible:
                label.setText(names[axis])
                unit = self.tr("°") if joint or axis >= 3 else self.tr("mm")
                self.minus_buttons[axis].setToolTip(
                    self.tr("Hold: {axis} − ({unit})").format(axis=names[axis], unit=unit)
                )
                self.plus_buttons[axis].setToolTip(
                    self.tr("Hold: {axis} + ({unit})").format(axis=names[axis], unit=unit)
                )
            for widget in (label, self.minus_buttons[axis], self.plus_buttons[axis]):
                widget.setVisible(visible)
        self.external_caption.setVisible(joint and not self._touch)
        self.external_check.setVisible(joint and self._touch)
        self.user_label.setVisible(frame is TeachFrame.USER)
        self.user_spin.setVisible(frame is TeachFrame.USER)
        self.tool_label.setVisible(frame is TeachFrame.TOOL)
        self.tool_spin.setVisible(frame is TeachFrame.TOOL)

    def _show_speed(self) -> None:
        sent = self.sent_ratio
        if sent >= self.ratio:
            self.speed_value.setText(self.tr("{ratio} %").format(ratio=self.ratio))
            self.speed_value.setStyleSheet("")
            self.speed_value.setToolTip("")
            return
        shown = (
            self.tr("{ratio} % → {cap} % (reduced speed)")
            if self._reduced
            else self.tr("{ratio} % → {cap} %")
        )
        self.speed_value.setText(shown.format(ratio=self.ratio, cap=f"{sent:g}"))
        self.speed_value.setStyleSheet("QLabel { color: #ef8f00; font-weight: bold; }")
        why = (
            self.tr("Capped at {cap} % (reduced speed): the jog goes out at {cap} %, not {ratio} %")
            if self._reduced
            else self.tr(
                "Capped at {cap} % (the safety envelope's maximum): "
                "the jog goes out at {cap} %, not {ratio} %"
            )
        )
        self.speed_value.setToolTip(why.format(cap=f"{sent:g}", ratio=self.ratio))

    @Slot(int)
    def _on_speed_changed(self, value: int) -> None:
        self._show_speed()
        if self._held is not None:
            self.ratioChanged.emit(float(value))

    @Slot(object, object)
    def _on_focus_changed(self, _old: QWidget | None, new: QWidget | None) -> None:
        if self._held is None:
            return
        if new is None or (new is not self and not self.isAncestorOf(new)):
            self.release_all()

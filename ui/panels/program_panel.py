"""Run a controller program (440 <- 0x01 with 446..449) and go to zero (445).

Both move the arm along a path the operator did not jog, so both ask for confirmation first
(the ``confirm`` attribute; tests replace it). Both need the controller in auto mode: in manual
mode (:meth:`ProgramPanel.set_controller_mode`) the confirmation says that it will be switched to
auto, and only a yes to that sends the request with ``switch_to_auto`` (the client refuses a
manual controller otherwise). In reduced-speed mode (:meth:`ProgramPanel.set_caps`) the speed
field shows the cap the run goes out at, and go to zero is held (it runs at the controller's own
speed, which nothing caps).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from PySide6.QtCore import QEvent, Signal, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.protocol.enums import JOINT_AXIS_NAMES, PROGRAM_MOTION_MODE_TEXT, ControllerMode, ProgramMotionMode
from app.protocol.registers import NUM_AXES_TOTAL
from app.safety.caps import MotionCaps
from ui.dialogs.confirm import ConfirmFn, ask_confirmation
from ui.i18n import protocol_text
from ui.touch import mark_motion

_MODES: tuple[ProgramMotionMode, ...] = (
    ProgramMotionMode.SINGLE_STEP,
    ProgramMotionMode.SINGLE_RUN,
    ProgramMotionMode.CYCLE,
)


@dataclass(frozen=True)
class ProgramRequest:
    program_id: int
    mode: ProgramMotionMode
    cycles: int  # 0: endless (cycle mode)
    speed_ratio: int  # 1..100 %
    switch_to_auto: bool = False  # the operator said yes to switching a manual controller to auto


@dataclass(frozen=True)
class ZeroRequest:
    axis: int | None  # 0..10 = J1..J11, None: all axes
    switch_to_auto: bool = False


class ProgramPanel(QWidget):
    """Emits ``programRequested(ProgramRequest)`` and ``goZeroRequested(ZeroRequest)``."""

    programRequested = Signal(ProgramRequest)
    goZeroRequested = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("ProgramPanel")
        self.confirm: ConfirmFn = ask_confirmation(self)
        self._mode: ControllerMode | int | None = None  # the controller's, as last read (None: unknown)
        self._caps: MotionCaps | None = None
        self._motion_enabled = True

        self.program_box = QGroupBox(self)
        form = QFormLayout(self.program_box)
        self.id_spin = QSpinBox(self.program_box)
        self.id_spin.setRange(0, 0xFFFF)
        self.id_spin.setValue(1)
        self.mode_combo = QComboBox(self.program_box)
        for mode in _MODES:
            self.mode_combo.addItem("", int(mode))
        self.mode_combo.setCurrentIndex(_MODES.index(ProgramMotionMode.SINGLE_RUN))
        self.mode_combo.currentIndexChanged.connect(self._update_cycles)
        self.cycles_spin = QSpinBox(self.program_box)
        self.cycles_spin.setRange(0, 0xFFFF)
        self.cycles_spin.setValue(1)
        self.speed_spin = QSpinBox(self.program_box)
        self.speed_spin.setRange(1, 100)
        self.speed_spin.setValue(50)
        self.speed_spin.setSuffix(" %")
        self.speed_spin.valueChanged.connect(self._show_cap)
        self.speed_cap = QLabel(self.program_box)  # the cap in force (reduced speed), else hidden
        self.speed_cap.setObjectName("ProgramSpeedCap")
        self.speed_cap.setStyleSheet("QLabel { color: #ef8f00; font-weight: bold; }")
        self.speed_cap.hide()
        speed_row = QHBoxLayout()
        speed_row.setContentsMargins(0, 0, 0, 0)
        speed_row.addWidget(self.speed_spin)
        speed_row.addWidget(self.speed_cap, 1)
        self.run_button = QPushButton(self.program_box)
        mark_motion(self.run_button)
        self.run_button.clicked.connect(self._run)
        self.captions = [QLabel(self.program_box) for _ in range(4)]
        for caption, field in zip(
            self.captions, (self.id_spin, self.mode_combo, self.cycles_spin, self.speed_spin), strict=True
        ):
            caption.setBuddy(field)
            if field is self.speed_spin:
                form.addRow(caption, speed_row)
            else:
                form.addRow(caption, field)
        form.addRow(self.run_button)

        self.zero_box = QGroupBox(self)
        zero_row = QHBoxLayout(self.zero_box)
        self.zero_combo = QComboBox(self.zero_box)
        for axis in range(NUM_AXES_TOTAL):
            self.zero_combo.addItem(JOINT_AXIS_NAMES[axis], axis)
        self.zero_combo.addItem("", None)
        self.zero_combo.setCurrentIndex(NUM_AXES_TOTAL)  # all axes
        self.zero_button = QPushButton(self.zero_box)
        mark_motion(self.zero_button)
        self.zero_button.clicked.connect(self._go_zero)
        zero_row.addWidget(self.zero_combo, 1)
        zero_row.addWidget(self.zero_button)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addWidget(self.program_box)
        layout.addWidget(self.zero_box)
        layout.addStretch(1)
        self._update_cycles()
        self.retranslate()

    # --- texts ------------------------------------------------------------------------
    def retranslate(self) -> None:
        self.program_box.setTitle(self.tr("Program"))
        captions = (self.tr("Program no.:"), self.tr("Run mode:"), self.tr("Cycles:"), self.tr("Speed:"))
        for label, caption in zip(self.captions, captions, strict=True):
            label.setText(caption)
        for i, mode in enumerate(_MODES):
            self.mode_combo.setItemText(i, protocol_text(PROGRAM_MOTION_MODE_TEXT[mode]))
        self.cycles_spin.setSpecialValueText(self.tr("endless"))
        self.cycles_spin.setToolTip(self.tr("Number of cycles in cycle mode; 0 runs until stopped"))
        self.run_button.setText(self.tr("Run program"))
        self.zero_box.setTitle(self.tr("Go to zero"))
        self.zero_combo.setItemText(NUM_AXES_TOTAL, self.tr("All axes"))
        self.zero_button.setText(self.tr("Go to zero"))
        self._show_cap()
        self._apply_zero()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public -----------------------------------------------------------------------
    def request(self) -> ProgramRequest:
        mode = _MODES[self.mode_combo.currentIndex()]
        cycles = self.cycles_spin.value() if mode is ProgramMotionMode.CYCLE else 1
        return ProgramRequest(self.id_spin.value(), mode, cycles, self.speed_spin.value())

    def set_motion_enabled(self, enabled: bool) -> None:
        self._motion_enabled = bool(enabled)
        self.run_button.setEnabled(enabled)
        self._apply_zero()

    def set_controller_mode(self, mode: ControllerMode | int | None) -> None:
        """The controller's mode as last read (None: not known); the confirmations name a switch."""
        self._mode = mode

    def set_caps(self, caps: MotionCaps | None) -> None:
        """Reduced-speed mode's caps (None: off): the speed field shows the cap, go to zero is held."""
        self._caps = caps
        self._show_cap()
        self._apply_zero()

    def sent_ratio(self) -> int:
        """The speed ratio a run goes out at (the field's, capped in reduced-speed mode)."""
        ratio = self.speed_spin.value()
        return ratio if self._caps is None else self._caps.program_ratio(ratio)

    def zero_axis(self) -> int | None:
        data = self.zero_combo.currentData()
        return None if data is None else int(data)

    def set_zero_axis(self, axis: int | None) -> None:
        self.zero_combo.setCurrentIndex(NUM_AXES_TOTAL if axis is None else axis)

    # --- internals --------------------------------------------------------------------
    @Slot()
    def _update_cycles(self) -> None:
        self.cycles_spin.setEnabled(_MODES[self.mode_combo.currentIndex()] is ProgramMotionMode.CYCLE)

    def _manual(self) -> bool:
        """The controller reads manual (or a mode that is not auto / Modbus teach)."""
        return self._mode is not None and self._mode not in (ControllerMode.AUTO, ControllerMode.MODBUS_TEACH)

    def _speed_text(self, asked: int) -> str:
        sent = self.sent_ratio()
        if sent == asked:
            return self.tr("{speed} %").format(speed=sent)
        return self.tr("{speed} % (capped by reduced speed; {asked} % set)").format(speed=sent, asked=asked)

    @Slot()
    def _run(self) -> None:
        request = self.request()
        mode = protocol_text(PROGRAM_MOTION_MODE_TEXT[request.mode])
        speed = self._speed_text(request.speed_ratio)
        manual = self._manual()
        if manual:
            text = self.tr(
                "The controller is in Manual mode. Switch it to Auto and run program {id} ({mode}) at "
                "{speed}? The arm will move."
            )
        else:
            text = self.tr("Run program {id} ({mode}) at {speed}? The arm will move.")
        text = text.format(id=request.program_id, mode=mode, speed=speed)
        if self.confirm(self.tr("Confirm program run"), text):
            self.programRequested.emit(dataclasses.replace(request, switch_to_auto=manual))

    @Slot()
    def _go_zero(self) -> None:
        if self._caps is not None:
            return  # held in reduced-speed mode (the button is disabled; a late click does nothing)
        axis = self.zero_axis()
        which = self.tr("all axes") if axis is None else JOINT_AXIS_NAMES[axis]
        manual = self._manual()
        if manual:
            text = self.tr(
                "The controller is in Manual mode. Switch it to Auto and move {which} to zero? "
                "The arm will move."
            )
        else:
            text = self.tr("Move {which} to zero? The arm will move.")
        if self.confirm(self.tr("Confirm go to zero"), text.format(which=which)):
            self.goZeroRequested.emit(ZeroRequest(axis, switch_to_auto=manual))

    @Slot()
    def _show_cap(self) -> None:
        asked = self.speed_spin.value()
        capped = self._caps is not None and self.sent_ratio() < asked
        self.speed_cap.setVisible(capped)
        if capped:
            self.speed_cap.setText(self.tr("→ {cap} % (reduced speed)").format(cap=self.sent_ratio()))
            self.speed_cap.setToolTip(
                self.tr("Reduced-speed mode: the program runs at {cap} % at most").format(
                    cap=self.sent_ratio()
                )
            )

    def _apply_zero(self) -> None:
        held = self._caps is not None
        self.zero_button.setEnabled(self._motion_enabled and not held)
        self.zero_button.setToolTip(
            self.tr(
                "Not in reduced-speed mode: go to zero runs at the controller's own speed, "
                "which TeachPad cannot cap"
            )
            if held
            else ""
        )

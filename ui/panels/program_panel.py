"""Run a controller program (440 <- 0x01 with 446..449) and go to zero (445).

Both move the arm along a path the operator did not jog, so both ask for confirmation first
(the ``confirm`` attribute; tests replace it).
"""

from __future__ import annotations

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

from app.protocol.enums import JOINT_AXIS_NAMES, PROGRAM_MOTION_MODE_TEXT, ProgramMotionMode
from app.protocol.registers import NUM_AXES_TOTAL
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


class ProgramPanel(QWidget):
    """Emits ``programRequested(ProgramRequest)`` and ``goZeroRequested(axis or None)``."""

    programRequested = Signal(ProgramRequest)
    goZeroRequested = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("ProgramPanel")
        self.confirm: ConfirmFn = ask_confirmation(self)

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
        self.run_button = QPushButton(self.program_box)
        mark_motion(self.run_button)
        self.run_button.clicked.connect(self._run)
        self.captions = [QLabel(self.program_box) for _ in range(4)]
        for caption, field in zip(
            self.captions, (self.id_spin, self.mode_combo, self.cycles_spin, self.speed_spin), strict=True
        ):
            caption.setBuddy(field)
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
        self.run_button.setEnabled(enabled)
        self.zero_button.setEnabled(enabled)

    def zero_axis(self) -> int | None:
        data = self.zero_combo.currentData()
        return None if data is None else int(data)

    def set_zero_axis(self, axis: int | None) -> None:
        self.zero_combo.setCurrentIndex(NUM_AXES_TOTAL if axis is None else axis)

    # --- internals --------------------------------------------------------------------
    @Slot()
    def _update_cycles(self) -> None:
        self.cycles_spin.setEnabled(_MODES[self.mode_combo.currentIndex()] is ProgramMotionMode.CYCLE)

    @Slot()
    def _run(self) -> None:
        request = self.request()
        mode = protocol_text(PROGRAM_MOTION_MODE_TEXT[request.mode])
        text = self.tr("Run program {id} ({mode}) at {speed} %? The arm will move.").format(
            id=request.program_id, mode=mode, speed=request.speed_ratio
        )
        if self.confirm(self.tr("Confirm program run"), text):
            self.programRequested.emit(request)

    @Slot()
    def _go_zero(self) -> None:
        axis = self.zero_axis()
        which = self.tr("all axes") if axis is None else JOINT_AXIS_NAMES[axis]
        text = self.tr("Move {which} to zero? The arm will move.").format(which=which)
        if self.confirm(self.tr("Confirm go to zero"), text):
            self.goZeroRequested.emit(axis)

"""Incremental move (function 1): joint or base frame, preset or exact offsets, speed GV225.

A ± button moves one axis by the selected preset (0.1 / 1 / 10 mm or °). "Move by values"
sends every exact value at once; a move longer than :data:`CONFIRM_ABOVE` asks first (the
``confirm`` attribute, replaceable in tests). Speed is rpm in the joint frame and mm/s in the
base frame (the controller's unit for GV225 depends on the frame). In reduced-speed mode
(:meth:`StepPanel.set_caps`) the speed field shows the cap the step goes out at: the TCP cap in the
base frame, in the joint frame the rpm at which one joint keeps the arm under it (less when
several joints move together: :class:`~app.safety.caps.MotionCaps`).

The exact-offset fields follow the axes' own limits (:meth:`StepPanel.set_limits`, the safety
envelope's): a joint's offset lies within its limits' span, X Y Z within the keep-in box's, a
rotation within a turn; the on-screen keypad offers what keeps the axis inside its limits from
where it stands (:meth:`StepPanel.set_pose`), and says so. External axes (no limits known) keep
:data:`OFFSET_LIMIT`.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from PySide6.QtCore import QEvent, Qt, Signal, Slot
from PySide6.QtWidgets import (
    QButtonGroup,
    QCheckBox,
    QComboBox,
    QDoubleSpinBox,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QLabel,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from app.link.types import StepFrame
from app.models import Pose
from app.protocol.enums import CARTESIAN_AXIS_NAMES, JOINT_AXIS_NAMES
from app.protocol.registers import NUM_AXES_TOTAL, NUM_EXTERNAL_AXES, NUM_ROBOT_AXES
from app.safety.box import Box
from app.safety.caps import MotionCaps
from ui.dialogs.confirm import ConfirmFn, ask_confirmation
from ui.joins import join_names
from ui.keypad_range import KeypadRange
from ui.touch import RowsScrollArea, mark_motion, mark_touch_target

PRESETS: tuple[float, ...] = (0.1, 1.0, 10.0)
DEFAULT_PRESET = 1.0
OFFSET_LIMIT = 10_000.0  # mm or degrees, per axis and move, where no limit of the axis is known
ROTATION_LIMIT = 360.0  # degrees: a step rotates A, B or C by at most a turn
CONFIRM_ABOVE = 10.0  # an exact-values move with any |offset| above this asks first
SPEED_DEFAULT = {StepFrame.JOINT: 5.0, StepFrame.BASE: 50.0}  # rpm, mm/s
SPEED_MAX = {StepFrame.JOINT: 100.0, StepFrame.BASE: 2000.0}


def _figure(speed: float) -> str:
    """A capped speed as shown: whole from 10 up, else two decimals at most (1.72 rpm)."""
    return f"{speed:.0f}" if speed >= 10 else f"{speed:.2f}".rstrip("0").rstrip(".")


class OffsetSpin(QDoubleSpinBox):
    """An axis's exact offset: the keypad asks ``reach`` what it may offer now (see
    :class:`~ui.keypad_range.RangedField`); the panel sets it."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.reach: Callable[[], KeypadRange | None] | None = None

    def keypad_range(self) -> KeypadRange | None:
        return self.reach() if self.reach is not None else None


@dataclass(frozen=True)
class StepRequest:
    frame: StepFrame
    offsets: tuple[float, float, float, float, float, float]
    ext_offsets: tuple[float, float, float, float, float]
    speed: float


class StepPanel(QWidget):
    """Emits ``stepRequested(StepRequest)``."""

    stepRequested = Signal(StepRequest)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("StepPanel")
        self.confirm: ConfirmFn = ask_confirmation(self)
        self._speeds = dict(SPEED_DEFAULT)
        self._frame = StepFrame.JOINT
        self._caps: MotionCaps | None = None
        self._joint_limits: tuple[tuple[float, float], ...] = ()  # J1.. (the envelope's; () none)
        self._keep_in: Box | None = None
        self._pose: Pose | None = None

        self.frame_caption = QLabel(self)
        self.frame_combo = QComboBox(self)
        self.frame_combo.addItem("", StepFrame.JOINT.value)
        self.frame_combo.addItem("", StepFrame.BASE.value)
        self.frame_combo.currentIndexChanged.connect(self._on_frame_changed)
        self.speed_caption = QLabel(self)
        self.speed_spin = QDoubleSpinBox(self)
        self.speed_spin.setDecimals(1)
        self.speed_spin.setMinimum(0.1)
        self.speed_spin.valueChanged.connect(self._on_speed_changed)
        self.speed_cap = QLabel(self)  # the cap in force (reduced speed), else hidden
        self.speed_cap.setObjectName("StepSpeedCap")
        self.speed_cap.setStyleSheet("QLabel { color: #ef8f00; font-weight: bold; }")
        self.speed_cap.hide()
        top = QHBoxLayout()
        top.addWidget(self.frame_caption)
        top.addWidget(self.frame_combo, 1)
        top.addSpacing(12)
        top.addWidget(self.speed_caption)
        top.addWidget(self.speed_spin)
        self.speed_cap.setAlignment(Qt.AlignmentFlag.AlignRight)  # its own line: the top row is full

        self.preset_box = QGroupBox(self)
        preset_row = QHBoxLayout(self.preset_box)
        preset_row.setContentsMargins(6, 2, 6, 4)  # touch mode: 56 px buttons fit 1280×800 (issue 21)
        self.preset_group = QButtonGroup(self)
        self.preset_buttons: list[QPushButton] = []
        for i, value in enumerate(PRESETS):
            button = QPushButton(f"{value:g}", self.preset_box)
            button.setCheckable(True)
            button.setChecked(value == DEFAULT_PRESET)
            self.preset_group.addButton(button, i)
            preset_row.addWidget(button)
            mark_touch_target(button)  # touch mode: finger size (issue 21)
            self.preset_buttons.append(button)

        # 11 rows of 40 px buttons do not fit a 800 px screen: the rows scroll (the robot axes
        # fit without scrolling; the external axes are shown on demand)
        self.axes_box = QGroupBox(self)
        self.axes_rows = QWidget()
        self.axes_rows.setObjectName("StepAxes")
        self.axes_scroll = RowsScrollArea(self.axes_rows, self.axes_box)
        box_layout = QVBoxLayout(self.axes_box)
        box_layout.setContentsMargins(4, 4, 4, 4)
        box_layout.addWidget(self.axes_scroll)
        grid = QGridLayout(self.axes_rows)
        grid.setContentsMargins(0, 0, 0, 0)
        self.axis_labels: list[QLabel] = []
        self.minus_buttons: list[QPushButton] = []
        self.plus_buttons: list[QPushButton] = []
        self.value_spins: list[OffsetSpin] = []
        self.value_caption = QLabel(self.axes_rows)
        grid.addWidget(self.value_caption, 0, 3)
        for axis in range(NUM_AXES_TOTAL):
            label = QLabel(self.axes_rows)
            minus = QPushButton("−", self.axes_rows)
            plus = QPushButton("+", self.axes_rows)
            mark_motion(minus, plus)
            minus.setObjectName(f"step_minus_{axis}")
            plus.setObjectName(f"step_plus_{axis}")
            minus.clicked.connect(lambda _=False, a=axis: self._step_one(a, -1.0))
            plus.clicked.connect(lambda _=False, a=axis: self._step_one(a, 1.0))
            spin = OffsetSpin(self.axes_rows)
            spin.reach = lambda a=axis: self._offset_reach(a)
            spin.setDecimals(3)
            spin.setSingleStep(DEFAULT_PRESET)
            row = axis + 1 if axis < NUM_ROBOT_AXES else axis + 2  # external axes below their switch
            grid.addWidget(label, row, 0)
            grid.addWidget(minus, row, 1)
            grid.addWidget(plus, row, 2)
            grid.addWidget(spin, row, 3)
            self.axis_labels.append(label)
            self.minus_buttons.append(minus)
            self.plus_buttons.append(plus)
            self.value_spins.append(spin)
        self.external_check = QCheckBox(self.axes_rows)
        self.external_check.toggled.connect(self._show_external)
        grid.addWidget(self.external_check, NUM_ROBOT_AXES + 1, 0, 1, 4)  # between J6 and J7
        grid.setRowStretch(NUM_AXES_TOTAL + 2, 1)
        self.move_button = QPushButton(self)
        mark_motion(self.move_button)
        self.move_button.clicked.connect(self._move_by_values)
        self.clear_button = QPushButton(self)
        self.clear_button.clicked.connect(self.clear_values)
        actions = QHBoxLayout()
        actions.addStretch(1)
        actions.addWidget(self.clear_button)
        actions.addWidget(self.move_button)

        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addLayout(top)
        layout.addWidget(self.speed_cap)
        layout.addWidget(self.preset_box)
        layout.addWidget(self.axes_box, 1)
        layout.addLayout(actions)
        self.preset_group.idClicked.connect(self._on_preset)
        self._show_external(False)
        self._apply_frame()
        self.retranslate()

    # --- texts ------------------------------------------------------------------------
    def retranslate(self) -> None:
        self.frame_caption.setText(self.tr("Frame:"))
        self.frame_combo.setItemText(0, self.tr("Joint frame"))
        self.frame_combo.setItemText(1, self.tr("Base frame"))
        self.speed_caption.setText(self.tr("Speed:"))
        self.speed_spin.setToolTip(self.tr("Expected speed of the incremental move (GV225)"))
        self.preset_box.setTitle(self.tr("Increment per click (mm or °)"))
        self.axes_box.setTitle(self.tr("Incremental move"))
        self.value_caption.setText(self.tr("Exact offset"))
        self.move_button.setText(self.tr("Move by values"))
        self.move_button.setToolTip(self.tr("Move every axis by its exact offset in one incremental move"))
        self.clear_button.setText(self.tr("Clear values"))
        self.external_check.setText(self.tr("External axes J7–J11"))
        self.external_check.setToolTip(self.tr("Show the external axes; while hidden their offsets are 0"))
        self._apply_units()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- public -----------------------------------------------------------------------
    @property
    def frame(self) -> StepFrame:
        return self._frame

    def set_frame(self, frame: StepFrame) -> None:
        self.frame_combo.setCurrentIndex(0 if frame is StepFrame.JOINT else 1)

    @property
    def preset(self) -> float:
        return PRESETS[max(0, self.preset_group.checkedId())]

    def set_preset(self, value: float) -> None:
        self.preset_buttons[PRESETS.index(value)].setChecked(True)
        self._on_preset(PRESETS.index(value))

    @property
    def speed(self) -> float:
        return float(self.speed_spin.value())

    def speed_unit(self) -> str:
        return self.tr("rpm") if self._frame is StepFrame.JOINT else self.tr("mm/s")

    def set_values(self, values: list[float]) -> None:
        for spin, value in zip(self.value_spins, values, strict=False):
            spin.setValue(value)

    @Slot()
    def clear_values(self) -> None:
        for spin in self.value_spins:
            spin.setValue(0.0)

    def set_motion_enabled(self, enabled: bool) -> None:
        self.axes_box.setEnabled(enabled)
        self.move_button.setEnabled(enabled)

    def set_limits(self, joint_limits: Sequence[tuple[float, float]], keep_in: Box | None) -> None:
        """The axes' limits (the safety envelope's joint limits and keep-in box; empty / None: not
        checked): the offset fields' ranges and what the keypad offers follow them."""
        self._joint_limits = tuple((float(lo), float(hi)) for lo, hi in joint_limits)
        self._keep_in = keep_in
        self._apply_ranges()

    def set_pose(self, pose: Pose | None) -> None:
        """Where the arm is (the keypad offers each axis's offsets from there to its limits)."""
        self._pose = pose

    def axis_limits(self, axis: int) -> tuple[float, float] | None:
        """Axis ``axis``'s limits in the frame in force (degrees or mm), None when not known."""
        if self._frame is StepFrame.JOINT:
            return self._joint_limits[axis] if axis < len(self._joint_limits) else None
        if axis < 3 and self._keep_in is not None:
            return (self._keep_in.lo[axis], self._keep_in.hi[axis])
        return None

    def _position(self, axis: int) -> float | None:
        pose = self._pose
        if pose is None:
            return None
        if self._frame is StepFrame.JOINT:
            return pose.joints[axis] if pose.joints is not None and axis < len(pose.joints) else None
        return pose.xyzabc[axis] if axis < 3 else None

    def _offset_range(self, axis: int) -> tuple[float, float]:
        """The offset field's fixed range: the span of the axis's limits, a turn for a rotation."""
        limits = self.axis_limits(axis)
        if limits is not None:
            span = limits[1] - limits[0]
            return (-span, span)
        if self._frame is StepFrame.BASE and 3 <= axis < NUM_ROBOT_AXES:
            return (-ROTATION_LIMIT, ROTATION_LIMIT)
        return (-OFFSET_LIMIT, OFFSET_LIMIT)

    def _offset_reach(self, axis: int) -> KeypadRange | None:
        """What the keypad offers for ``axis`` now: from where it stands to each of its limits."""
        limits = self.axis_limits(axis)
        if limits is None:
            return None
        lo, hi = limits
        name = self._axis_names()[axis]
        unit = self.tr("°") if self._frame is StepFrame.JOINT else self.tr("mm")
        at = self._position(axis)
        if at is None:
            note = self.tr("{axis} limits {lo} … {hi} {unit} (its position is not known)")
            return KeypadRange(
                lo - hi, hi - lo, note.format(axis=name, lo=f"{lo:g}", hi=f"{hi:g}", unit=unit)
            )
        note = self.tr("{axis} limits {lo} … {hi} {unit}, now at {at} {unit}")
        text = note.format(axis=name, lo=f"{lo:g}", hi=f"{hi:g}", at=f"{at:.1f}", unit=unit)
        return KeypadRange(lo - at, hi - at, text)

    def _apply_ranges(self) -> None:
        for axis, spin in enumerate(self.value_spins):
            low, high = self._offset_range(axis)
            spin.setRange(low, high)

    def set_caps(self, caps: MotionCaps | None) -> None:
        """Reduced-speed mode's caps (None: off), shown beside the speed field."""
        self._caps = caps
        self._show_cap()

    def sent_speed(self, offsets: list[float] | None = None) -> float:
        """The speed a step by ``offsets`` goes out at (a one-axis step when None): the field's,
        capped in reduced-speed mode."""
        caps = self._caps
        if caps is None:
            return self.speed
        if self._frame is StepFrame.BASE:
            return caps.linear_speed(self.speed)
        return caps.joint_speed(self.speed, offsets if offsets is not None else [1.0])

    # --- internals --------------------------------------------------------------------
    def _request(self, offsets: list[float]) -> None:
        robot = offsets[:NUM_ROBOT_AXES]
        ext = offsets[NUM_ROBOT_AXES:NUM_AXES_TOTAL] if self.external_check.isChecked() else [0.0] * 5
        self.stepRequested.emit(
            StepRequest(
                self._frame,
                (robot[0], robot[1], robot[2], robot[3], robot[4], robot[5]),
                (ext[0], ext[1], ext[2], ext[3], ext[4]),
                self.speed,
            )
        )

    def _step_one(self, axis: int, sign: float) -> None:
        offsets = [0.0] * NUM_AXES_TOTAL
        offsets[axis] = sign * self.preset
        self._request(offsets)

    @Slot(bool)
    def _show_external(self, shown: bool) -> None:
        for axis in range(NUM_ROBOT_AXES, NUM_AXES_TOTAL):
            for widget in (
                self.axis_labels[axis],
                self.minus_buttons[axis],
                self.plus_buttons[axis],
                self.value_spins[axis],
            ):
                widget.setVisible(shown)
        if shown:
            self.axes_scroll.ensureWidgetVisible(self.minus_buttons[NUM_ROBOT_AXES])

    @Slot()
    def _move_by_values(self) -> None:
        offsets = [spin.value() for spin in self.value_spins]
        if not self.external_check.isChecked():
            offsets[NUM_ROBOT_AXES:] = [0.0] * NUM_EXTERNAL_AXES
        if not any(offsets):
            return
        if max(abs(v) for v in offsets) > CONFIRM_ABOVE:
            names = self._axis_names()
            moves = join_names(f"{names[i]} {v:+g}" for i, v in enumerate(offsets) if v)
            sent = self.sent_speed(offsets)
            speed = _figure(sent) if sent < self.speed else f"{self.speed:g}"
            text = self.tr("Move by {moves} at {speed} {unit}?").format(
                moves=moves, speed=speed, unit=self.speed_unit()
            )
            if sent < self.speed:
                text += " " + self.tr("(capped by reduced speed; {asked} {unit} set)").format(
                    asked=f"{self.speed:g}", unit=self.speed_unit()
                )
            if not self.confirm(self.tr("Confirm incremental move"), text):
                return
        self._request(offsets)

    def _axis_names(self) -> tuple[str, ...]:
        robot = JOINT_AXIS_NAMES[:NUM_ROBOT_AXES] if self._frame is StepFrame.JOINT else CARTESIAN_AXIS_NAMES
        return (*robot, *JOINT_AXIS_NAMES[NUM_ROBOT_AXES : NUM_ROBOT_AXES + NUM_EXTERNAL_AXES])

    @Slot(int)
    def _on_frame_changed(self, index: int) -> None:
        self._frame = StepFrame.JOINT if index == 0 else StepFrame.BASE
        self._apply_frame()

    def _apply_frame(self) -> None:
        frame = self._frame
        self.speed_spin.blockSignals(True)
        self.speed_spin.setMaximum(SPEED_MAX[frame])
        self.speed_spin.setValue(self._speeds[frame])
        self.speed_spin.blockSignals(False)
        self._apply_units()
        self._apply_ranges()
        self._show_cap()

    def _apply_units(self) -> None:
        self.speed_spin.setSuffix(" " + self.speed_unit())
        names = self._axis_names()
        deg, mm = self.tr("°"), self.tr("mm")
        for axis, label in enumerate(self.axis_labels):
            linear = self._frame is StepFrame.BASE and axis < 3
            unit = mm if linear else deg
            # the unit is in the field ("0.000 mm"): "X (mm)" left the field's arrows clipped at
            # 1280×800 in the base frame (issue 21)
            label.setText(names[axis])
            label.setToolTip(f"{names[axis]} ({unit})")
            self.value_spins[axis].setSuffix(f" {unit}")

    @Slot(float)
    def _on_speed_changed(self, value: float) -> None:
        self._speeds[self._frame] = float(value)
        self._show_cap()

    def _show_cap(self) -> None:
        sent = self.sent_speed()
        capped = sent < self.speed
        self.speed_cap.setVisible(capped)
        if not capped:
            return
        self.speed_cap.setText(self.tr("→ {cap} {unit}").format(cap=_figure(sent), unit=self.speed_unit()))
        tip = (
            self.tr(
                "Reduced speed: a step goes out at {cap} {unit} at most (one joint; less when several "
                "joints move together)"
            )
            if self._frame is StepFrame.JOINT
            else self.tr("Reduced speed: a step goes out at {cap} {unit} at most")
        )
        self.speed_cap.setToolTip(tip.format(cap=_figure(sent), unit=self.speed_unit()))

    @Slot(int)
    def _on_preset(self, index: int) -> None:
        for spin in self.value_spins:
            spin.setSingleStep(PRESETS[index])

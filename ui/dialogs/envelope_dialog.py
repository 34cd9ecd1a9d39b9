"""Edit the safety envelope: joint limits, the keep-in box, keep-out boxes, speed caps.

Saved with :meth:`SafetyController.save_envelope` (role checked, audited, the profile written
atomically with its next revision). A value that does not make a valid envelope is refused with
the reason and the dialog stays open.
"""

from __future__ import annotations

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.errors import TeachPadError
from app.safety.box import Box
from app.safety.envelope import Envelope
from ui.controllers.safety import SafetyController

JOINTS = 6
LIMIT_MM = 10000.0
_BOX_COLUMNS = 7  # name, X min, Y min, Z min, X max, Y max, Z max


def _spin(lo: float, hi: float, value: float, suffix: str, decimals: int = 1) -> QDoubleSpinBox:
    spin = QDoubleSpinBox()
    spin.setRange(lo, hi)
    spin.setDecimals(decimals)
    spin.setValue(value)
    spin.setSuffix(suffix)
    return spin


class EnvelopeDialog(QDialog):
    def __init__(self, safety: SafetyController, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("EnvelopeDialog")
        self._safety = safety
        env = safety.envelope
        self.setWindowTitle(self.tr("Safety envelope"))
        # joint limits
        self.joints_on = QCheckBox(self.tr("Check joint limits"), self)
        self.joints_on.setChecked(bool(env.joint_limits))
        self.joint_table = QTableWidget(JOINTS, 2, self)
        self.joint_table.setHorizontalHeaderLabels([self.tr("Min (°)"), self.tr("Max (°)")])
        self.joint_table.setVerticalHeaderLabels([f"J{i + 1}" for i in range(JOINTS)])
        for i in range(JOINTS):
            lo, hi = env.joint_limits[i] if i < len(env.joint_limits) else (-180.0, 180.0)
            self.joint_table.setItem(i, 0, QTableWidgetItem(f"{lo:g}"))
            self.joint_table.setItem(i, 1, QTableWidgetItem(f"{hi:g}"))
        # keep-in box
        self.keep_in_on = QCheckBox(self.tr("Keep the TCP inside this box"), self)
        self.keep_in_on.setChecked(env.keep_in is not None)
        box = env.keep_in or Box("cell", (-1000.0, -1000.0, 0.0), (1000.0, 1000.0, 1500.0))
        self.keep_in_lo = [_spin(-LIMIT_MM, LIMIT_MM, v, " mm") for v in box.lo]
        self.keep_in_hi = [_spin(-LIMIT_MM, LIMIT_MM, v, " mm") for v in box.hi]
        # keep-out boxes
        self.keep_out = QTableWidget(0, _BOX_COLUMNS, self)
        self.keep_out.setHorizontalHeaderLabels(
            [
                self.tr("Name"),
                *(self.tr("{axis} min").format(axis=axis) for axis in "XYZ"),
                *(self.tr("{axis} max").format(axis=axis) for axis in "XYZ"),
            ]
        )
        self.keep_out.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Stretch)
        self.keep_out.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        for zone in env.keep_out:
            self._add_row(zone)
        self.add_button = QPushButton(self.tr("Add zone"), self)
        self.add_button.clicked.connect(lambda: self._add_row(None))
        self.remove_button = QPushButton(self.tr("Remove zone"), self)
        self.remove_button.clicked.connect(self._remove_rows)
        # speeds
        self.max_jog = _spin(1, 100, env.max_jog_ratio, " %", 0)
        self.max_speed = _spin(1, 5000, env.max_speed, " mm/s", 0)
        self.reduced_jog = _spin(1, 100, env.reduced_jog_ratio, " %", 0)
        self.reduced_speed = _spin(1, 5000, env.reduced_speed, " mm/s", 0)
        self.error = QLabel(self)
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #c62828;")
        self.revision = QLabel(self.tr("Revision {n}").format(n=safety.profile.revision), self)
        self._lay_out()

    def _lay_out(self) -> None:
        joints = QGroupBox(self.tr("Joint limits"), self)
        jl = QVBoxLayout(joints)
        jl.addWidget(self.joints_on)
        jl.addWidget(self.joint_table)
        keep_in = QGroupBox(self.tr("Work space (keep-in box)"), self)
        kl = QFormLayout(keep_in)
        kl.addRow(self.keep_in_on)
        for label, lo, hi in zip("XYZ", self.keep_in_lo, self.keep_in_hi, strict=True):
            row = QHBoxLayout()
            row.addWidget(lo)
            row.addWidget(QLabel("…"))
            row.addWidget(hi)
            kl.addRow(label, row)
        zones = QGroupBox(self.tr("Keep-out zones"), self)
        zl = QVBoxLayout(zones)
        zl.addWidget(self.keep_out)
        zb = QHBoxLayout()
        zb.addWidget(self.add_button)
        zb.addWidget(self.remove_button)
        zb.addStretch(1)
        zl.addLayout(zb)
        speeds = QGroupBox(self.tr("Speeds"), self)
        sl = QFormLayout(speeds)
        sl.addRow(self.tr("Max jog speed:"), self.max_jog)
        sl.addRow(self.tr("Max TCP speed (moves, plans):"), self.max_speed)
        sl.addRow(self.tr("Reduced mode jog speed:"), self.reduced_jog)
        sl.addRow(self.tr("Reduced mode TCP speed:"), self.reduced_speed)
        std = QDialogButtonBox.StandardButton
        buttons = QDialogButtonBox(std.Save | std.Cancel, self)
        buttons.accepted.connect(self.save)
        buttons.rejected.connect(self.reject)
        top = QHBoxLayout()
        left = QVBoxLayout()
        left.addWidget(keep_in)
        left.addWidget(speeds)
        top.addLayout(left)
        top.addWidget(joints)
        layout = QVBoxLayout(self)
        layout.addLayout(top)
        layout.addWidget(zones, 1)
        layout.addWidget(self.error)
        bottom = QHBoxLayout()
        bottom.addWidget(self.revision)
        bottom.addWidget(buttons, 1, Qt.AlignmentFlag.AlignRight)
        layout.addLayout(bottom)

    def _add_row(self, zone: Box | None) -> None:
        zone = zone or Box(
            self.tr("zone {n}").format(n=self.keep_out.rowCount() + 1), (0.0, 0.0, 0.0), (100.0, 100.0, 100.0)
        )
        row = self.keep_out.rowCount()
        self.keep_out.insertRow(row)
        for col, text in enumerate([zone.name, *(f"{v:g}" for v in zone.lo), *(f"{v:g}" for v in zone.hi)]):
            self.keep_out.setItem(row, col, QTableWidgetItem(text))

    def _remove_rows(self) -> None:
        for row in sorted({i.row() for i in self.keep_out.selectedIndexes()}, reverse=True):
            self.keep_out.removeRow(row)

    def _cell(self, table: QTableWidget, row: int, col: int, what: str) -> float:
        item = table.item(row, col)
        text = item.text().strip() if item is not None else ""
        try:
            return float(text)
        except ValueError:
            why = self.tr("{what}: '{text}' is not a number").format(what=what, text=text[:20])
            raise ValueError(why) from None

    def envelope(self) -> Envelope:
        """The envelope as edited; ValueError / TeachPadError says what is wrong."""
        limits: tuple[tuple[float, float], ...] = ()
        if self.joints_on.isChecked():
            limits = tuple(
                (
                    self._cell(self.joint_table, i, 0, f"J{i + 1}"),
                    self._cell(self.joint_table, i, 1, f"J{i + 1}"),
                )
                for i in range(JOINTS)
            )
        keep_in = None
        if self.keep_in_on.isChecked():
            lo, hi = (s.value() for s in self.keep_in_lo), (s.value() for s in self.keep_in_hi)
            keep_in = Box("cell", (next(lo), next(lo), next(lo)), (next(hi), next(hi), next(hi)))
        zones = []
        for row in range(self.keep_out.rowCount()):
            item = self.keep_out.item(row, 0)
            name = (item.text().strip() if item is not None else "") or self.tr("zone {n}").format(n=row + 1)
            v = [self._cell(self.keep_out, row, col, name) for col in range(1, _BOX_COLUMNS)]
            zones.append(Box(name, (v[0], v[1], v[2]), (v[3], v[4], v[5])))
        return Envelope(
            limits,
            keep_in,
            tuple(zones),
            self.max_jog.value(),
            self.max_speed.value(),
            self.reduced_jog.value(),
            self.reduced_speed.value(),
        )

    def save(self) -> None:
        try:
            self._safety.save_envelope(self.envelope())
        except (ValueError, TeachPadError, OSError) as exc:
            self.error.setText(self._safety.refusal(exc) if isinstance(exc, TeachPadError) else str(exc))
            return
        self.accept()

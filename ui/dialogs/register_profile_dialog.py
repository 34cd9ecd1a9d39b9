"""Safety -> Register profile...: edit, load and save the protocol decisions that vary between
controllers (:class:`~app.safety.register_profile.RegisterProfile`).

The dialog edits a copy. **Save and apply** hands it to ``apply(profile, reconnect)`` (the safety
menu: role check, atomic save, audit, reconnect) and shows the refusal when there is one; **Load…**
fills the form from a profile file (nothing changes until it is saved); **Save as…** writes the
form to a file for another PC. Without the administrator role every field is disabled and the
tooltip says why (the menu entry is disabled too; this is the second line).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QEvent
from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFileDialog,
    QFormLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QVBoxLayout,
    QWidget,
)

from app.errors import TeachPadError
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.safety import register_profile as rp
from app.safety.register_profile import RegisterProfile

#: apply(profile, reconnect) -> None when saved, else the reason (already in the user's language)
ApplyProfile = Callable[[RegisterProfile, bool], str | None]


class RegisterProfileDialog(QDialog):
    """See the module docstring. ``reason``: why the role in force may not change it (None: it may).
    ``open_path`` / ``save_path`` ask for a file (tests replace them)."""

    def __init__(
        self,
        profile: RegisterProfile,
        apply: ApplyProfile,
        parent: QWidget | None = None,
        *,
        reason: str | None = None,
        connected: bool = False,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("RegisterProfileDialog")
        self.profile = profile
        self._apply = apply
        self._reason = reason
        self.open_path: Callable[[], str | None] = self._ask_open
        self.save_path: Callable[[str], str | None] = self._ask_save
        self.revision_label = QLabel(self)
        self.name_edit = QLineEdit(self)
        self.name_edit.setMaxLength(80)
        self.order_combo = QComboBox(self)
        for order in WordOrder:
            self.order_combo.addItem("", order.value)
        self.unit_spin = QSpinBox(self)
        self.unit_spin.setRange(*rp.UNIT_RANGE)
        self.completion_combo = QComboBox(self)
        for mode in rp.COMPLETION_MODES:
            self.completion_combo.addItem("", mode)
        self.unconfirmed_spin = self._seconds_spin(rp.UNCONFIRMED_RANGE, 3)
        self.poll_timeout_spin = self._seconds_spin(rp.POLL_TIMEOUT_RANGE, 2)
        self.clock_combo = QComboBox(self)
        for clock in DateTimeLayout:
            self.clock_combo.addItem("", clock.value)
        self.point_min_spin = QSpinBox(self)
        self.point_max_spin = QSpinBox(self)
        for spin in (self.point_min_spin, self.point_max_spin):
            spin.setRange(*rp.POINT_ID_RANGE)
        self.reconnect_check = QCheckBox(self)
        self.reconnect_check.setChecked(connected)
        self.reconnect_check.setEnabled(connected)
        self.error = QLabel(self)
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #c62828;")
        self.load_button = QPushButton(self)
        self.load_button.clicked.connect(self.load)
        self.save_as_button = QPushButton(self)
        self.save_as_button.clicked.connect(self.save_as)
        self.defaults_button = QPushButton(self)
        self.defaults_button.clicked.connect(
            lambda: self.set_profile(
                dataclasses.replace(RegisterProfile(), name=self.name_edit.text().strip() or "default")
            )
        )
        self.captions = [QLabel(self) for _ in range(9)]
        form = QFormLayout()
        for caption, field in zip(
            self.captions,
            (
                self.name_edit,
                self.order_combo,
                self.unit_spin,
                self.completion_combo,
                self.unconfirmed_spin,
                self.poll_timeout_spin,
                self.clock_combo,
                self.point_min_spin,
                self.point_max_spin,
            ),
            strict=True,
        ):
            form.addRow(caption, field)
        std = QDialogButtonBox.StandardButton
        self.buttons = QDialogButtonBox(std.Save | std.Cancel, self)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        for button in (self.load_button, self.save_as_button, self.defaults_button):
            self.buttons.addButton(button, QDialogButtonBox.ButtonRole.ActionRole)
        layout = QVBoxLayout(self)
        layout.addWidget(self.revision_label)
        layout.addLayout(form)
        layout.addWidget(self.reconnect_check)
        layout.addWidget(self.error)
        layout.addWidget(self.buttons)
        self.set_profile(profile)
        self.retranslate()

    def _seconds_spin(self, bounds: tuple[float, float], decimals: int) -> QDoubleSpinBox:
        """A seconds field whose lowest value means "automatic" (None in the profile)."""
        spin = QDoubleSpinBox(self)
        step = 10.0**-decimals
        spin.setDecimals(decimals)
        spin.setRange(bounds[0] - step, bounds[1])
        spin.setSingleStep(step * 10)
        spin.setSuffix(" s")
        return spin

    @staticmethod
    def _seconds(spin: QDoubleSpinBox) -> float | None:
        return None if spin.value() <= spin.minimum() else round(spin.value(), spin.decimals())

    @property
    def editable(self) -> bool:
        return self._reason is None

    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("Register profile"))
        captions = (
            self.tr("Name:"),
            self.tr("Float word order:"),
            self.tr("Unit id:"),
            self.tr("Command completion:"),
            self.tr("Unconfirmed after:"),
            self.tr("Poll timeout:"),
            self.tr("Date/time layout:"),
            self.tr("Lowest point id:"),
            self.tr("Highest point id:"),
        )
        for label, text in zip(self.captions, captions, strict=True):
            label.setText(text)
        self.order_combo.setItemText(0, self.tr("Low word first (CDAB, default)"))
        self.order_combo.setItemText(1, self.tr("High word first (ABCD)"))
        for i, text in enumerate(
            (
                self.tr("automatic (probe GV291 once)"),
                self.tr("sentinel (GV291 keeps what the host writes)"),
                self.tr("observe (GV291 read-only or ignores writes)"),
            )
        ):
            self.completion_combo.setItemText(i, text)
        self.clock_combo.setItemText(0, self.tr("split words (576 = year, 577 = month·256 + day)"))
        self.clock_combo.setItemText(1, self.tr("packed 32-bit (year in the high word)"))
        self.unconfirmed_spin.setSpecialValueText(self.tr("automatic"))
        self.poll_timeout_spin.setSpecialValueText(self.tr("automatic (by transport)"))
        self.reconnect_check.setText(self.tr("Reconnect now to apply it"))
        self.reconnect_check.setToolTip(self.tr("Otherwise it applies at the next connection"))
        self.load_button.setText(self.tr("Load…"))
        self.save_as_button.setText(self.tr("Save as…"))
        self.defaults_button.setText(self.tr("Defaults"))
        save = self.buttons.button(QDialogButtonBox.StandardButton.Save)
        save.setText(self.tr("Save and apply"))
        self._show_revision()
        tip = self._reason or ""
        for widget in self._editors():
            widget.setEnabled(self.editable)
            widget.setToolTip(tip)
        save.setEnabled(self.editable)
        save.setToolTip(tip)
        if not self.editable:
            self.error.setText(tip)

    def _editors(self) -> list[QWidget]:
        return [
            self.name_edit,
            self.order_combo,
            self.unit_spin,
            self.completion_combo,
            self.unconfirmed_spin,
            self.poll_timeout_spin,
            self.clock_combo,
            self.point_min_spin,
            self.point_max_spin,
            self.load_button,
            self.defaults_button,
            self.reconnect_check,
        ]

    def _show_revision(self) -> None:
        p = self.profile
        if p.revision:
            text = self.tr("In force: \u201c{name}\u201d, revision {rev}, saved {saved}").format(
                name=p.name, rev=p.revision, saved=p.saved.replace("T", " ")[:19]
            )
        else:
            text = self.tr("In force: the remembered connection settings (no register profile saved yet)")
        self.revision_label.setText(text)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- the form -----------------------------------------------------------------------------
    def set_profile(self, p: RegisterProfile) -> None:
        self.name_edit.setText(p.name)
        self.order_combo.setCurrentIndex(max(0, self.order_combo.findData(p.word_order.value)))
        self.unit_spin.setValue(p.unit)
        self.completion_combo.setCurrentIndex(max(0, self.completion_combo.findData(p.completion)))
        for spin, value in (
            (self.unconfirmed_spin, p.unconfirmed_after),
            (self.poll_timeout_spin, p.poll_timeout),
        ):
            spin.setValue(spin.minimum() if value is None else value)
        self.clock_combo.setCurrentIndex(max(0, self.clock_combo.findData(p.datetime_layout.value)))
        self.point_min_spin.setValue(p.point_id_min)
        self.point_max_spin.setValue(p.point_id_max)

    def edited(self) -> RegisterProfile:
        """The form as a profile (keeps the revision in force); raises RegisterProfileError."""
        return RegisterProfile(
            name=self.name_edit.text().strip(),
            word_order=WordOrder(self.order_combo.currentData()),
            unit=self.unit_spin.value(),
            completion=self.completion_combo.currentData(),
            unconfirmed_after=self._seconds(self.unconfirmed_spin),
            poll_timeout=self._seconds(self.poll_timeout_spin),
            datetime_layout=DateTimeLayout(self.clock_combo.currentData()),
            point_id_min=self.point_min_spin.value(),
            point_id_max=self.point_max_spin.value(),
            revision=self.profile.revision,
            saved=self.profile.saved,
        )

    def load(self) -> None:
        path = self.open_path()
        if not path:
            return
        try:
            loaded = rp.load_register_profile(path)
        except TeachPadError as exc:
            from ui.messages import refusal_text  # its code in words (a file's cause), else the English

            self.error.setText(self.tr("Not loaded: {why}").format(why=refusal_text(exc)[:200]))
            return
        self.set_profile(loaded)
        text = self.tr("Loaded \u201c{name}\u201d from {file}; press Save and apply to use it")
        self.error.setText(text.format(name=loaded.name, file=Path(path).name))

    def save_as(self) -> None:
        try:
            profile = self.edited()
        except TeachPadError as exc:
            self.error.setText(str(exc))
            return
        path = self.save_path(f"{profile.name}{rp.PROFILE_SUFFIX}")
        if not path:
            return
        try:
            rp.export_register_profile(path, profile)
        except OSError as exc:
            self.error.setText(
                self.tr("Cannot write {file}: {why}").format(file=Path(path).name, why=exc.strerror or exc)
            )
            return
        self.error.setText(self.tr("Saved to {file}").format(file=Path(path).name))

    def accept(self) -> None:
        try:
            profile = self.edited()
        except TeachPadError as exc:
            self.error.setText(str(exc))
            return
        refused = self._apply(profile, self.reconnect_check.isChecked())
        if refused is not None:
            self.error.setText(refused)
            return
        super().accept()

    # --- files --------------------------------------------------------------------------------
    def _ask_open(self) -> str | None:
        path, _ = QFileDialog.getOpenFileName(
            self, self.tr("Load a register profile"), "", self.tr("Register profiles (*.json)")
        )
        return path or None

    def _ask_save(self, suggested: str) -> str | None:
        path, _ = QFileDialog.getSaveFileName(
            self, self.tr("Save the register profile as"), suggested, self.tr("Register profiles (*.json)")
        )
        return path or None

"""Switch role (operator / engineer / administrator) with a password. The first administrator
password is set here while none exists yet (typed twice, confirmed in words); after that,
passwords and the idle lock time are the administrator's (Safety -> Passwords and lock...,
:mod:`ui.dialogs.password_dialog`)."""

from __future__ import annotations

from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from app.errors import InvalidInput, TeachPadError
from app.safety.roles import Role, WrongPassword
from ui.controllers.safety import SafetyController


class RoleDialog(QDialog):
    def __init__(self, safety: SafetyController, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("RoleDialog")
        self._safety = safety
        self.setWindowTitle(self.tr("Log in"))
        self.role_box = QComboBox(self)
        for role in Role:
            self.role_box.addItem(safety.role_name(role), role)
        self.role_box.setCurrentIndex(int(max(Role.ENGINEER, safety.role)))
        self.password = QLineEdit(self)
        self.password.setEchoMode(QLineEdit.EchoMode.Password)
        self.repeat = QLineEdit(self)  # the first administrator password: typed twice
        self.repeat.setEchoMode(QLineEdit.EchoMode.Password)
        self.current = QLabel(self.tr("Now: {role}").format(role=safety.role_name(safety.role)), self)
        self.error = QLabel(self)
        self.error.setWordWrap(True)
        # only while no administrator password exists (the first one); then Passwords and lock
        self.set_password_button = QPushButton(self.tr("Set this role's password"), self)
        self.set_password_button.clicked.connect(self.set_password)
        self.logout_button = QPushButton(self.tr("Log out (operator)"), self)
        self.logout_button.clicked.connect(self.log_out)
        form = self._form = QFormLayout()
        form.addRow(self.tr("Role:"), self.role_box)
        form.addRow(self.tr("Password:"), self.password)
        form.addRow(self.tr("Repeat:"), self.repeat)
        std = QDialogButtonBox.StandardButton
        buttons = QDialogButtonBox(std.Ok | std.Cancel, self)
        buttons.accepted.connect(self.log_in)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.current)
        layout.addLayout(form)
        layout.addWidget(self.error)
        layout.addWidget(self.set_password_button)
        layout.addWidget(self.logout_button)
        layout.addWidget(buttons)
        self.role_box.currentIndexChanged.connect(self._update)
        self._update()

    def _role(self) -> Role:
        return Role(self.role_box.currentData())

    def _update(self) -> None:
        store = self._safety.session.store
        first = not store.has_password(Role.ADMINISTRATOR)
        self.set_password_button.setVisible(first)
        self.set_password_button.setEnabled(first and self._role() is Role.ADMINISTRATOR)
        self._form.setRowVisible(self.repeat, first)
        hint = ""
        if first:
            hint = self.tr(
                "No administrator password is set yet: choose the administrator role, type a "
                "password twice and press \u201cSet this role's password\u201d."
            )
        elif self._role() is not Role.OPERATOR and not store.has_password(self._role()):
            hint = self.tr("No password is set for this role; an administrator sets it.")
        self._say(hint, error=True)

    def _say(self, text: str, *, error: bool) -> None:
        """A hint or refusal in red; a confirmation in the normal colour."""
        self.error.setStyleSheet("color: #c62828;" if error else "")
        self.error.setText(text)
        self._fit()

    def _fit(self) -> None:
        """Grow for a new line of text: a dialog already shown keeps its size, and the fields
        were squeezed under "Wrong password …" (issue 21)."""
        layout = self.layout()
        if layout is None or not self.isVisible():
            return  # not shown yet: the dialog is sized when it opens
        layout.activate()
        needed = layout.totalHeightForWidth(self.width()) if layout.hasHeightForWidth() else 0
        needed = max(needed, layout.totalMinimumSize().height())
        if self.height() < needed:
            self.resize(self.width(), needed)

    def log_in(self) -> None:
        role = self._role()
        try:
            self._safety.login(role, self.password.text())
        except WrongPassword:
            self._say(
                self.tr("Wrong password for the {role} role").format(role=self._safety.role_name(role))
                if self._safety.session.store.has_password(role)
                else self.tr("No password is set for this role; an administrator sets it."),
                error=True,
            )
            self.password.selectAll()
            return
        self.accept()

    def log_out(self) -> None:
        self._safety.logout()
        self.accept()

    def set_password(self) -> None:
        role = self._role()
        typed, repeated = self.password.text(), self.repeat.text()
        self.password.clear()
        self.repeat.clear()
        if typed != repeated:
            self._say(
                self.tr("The two passwords differ: nothing was set. Type the same password twice."),
                error=True,
            )
            return
        try:
            self._safety.session.set_password(role, typed)
        except InvalidInput as exc:
            self._say(str(exc), error=True)
            return
        except (OSError, TeachPadError) as exc:
            why = str(exc)[:120]
            self._say(self.tr("The password could not be saved: {why}").format(why=why), error=True)
            return
        self._update()  # the first password is set: the repeat row and the button go
        name = self._safety.role_name(role)
        self._say(self.tr("Password set for the {role} role").format(role=name), error=False)

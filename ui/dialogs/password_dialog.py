"""Safety -> Passwords and lock...: the administrator's screen for roles and passwords.

Lists the roles and whether each has a password; sets, changes or clears the selected role's
password (typed twice); sets the idle time before the window locks back to operator. Everything
goes through :class:`~app.safety.session.SafetySession` (administrator only, audited, passwords
stored as salted scrypt hashes and never written anywhere else). The operator cannot open it (the
menu entry is disabled with the reason); opened anyway, every control is disabled with the reason.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, Qt
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.errors import TeachPadError
from app.safety.roles import Action, Role
from app.safety.session import PermissionRefused
from ui.controllers.safety import SafetyController

IDLE_MINUTES_MAX = 240


class PasswordDialog(QDialog):
    def __init__(self, safety: SafetyController, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("PasswordDialog")
        self._safety = safety
        self.table = QTableWidget(len(Role), 2, self)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().hide()
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.Stretch)
        self.table.setWordWrap(False)
        self.table.itemSelectionChanged.connect(self._update_buttons)
        self.password = QLineEdit(self)
        self.repeat = QLineEdit(self)
        for edit in (self.password, self.repeat):
            edit.setEchoMode(QLineEdit.EchoMode.Password)
        self.set_button = QPushButton(self)
        self.set_button.clicked.connect(self.set_password)
        self.clear_button = QPushButton(self)
        self.clear_button.clicked.connect(self.clear_password)
        self.idle = QSpinBox(self)
        self.idle.setRange(1, IDLE_MINUTES_MAX)
        self.idle.setValue(max(1, min(IDLE_MINUTES_MAX, round(safety.session.store.idle_timeout / 60))))
        self.idle.editingFinished.connect(lambda: self.set_idle(self.idle.value()))  # not per keystroke
        self.message = QLabel(self)
        self.message.setWordWrap(True)
        self.password_caption = QLabel(self)
        self.repeat_caption = QLabel(self)
        self.idle_caption = QLabel(self)
        form = QFormLayout()
        form.addRow(self.password_caption, self.password)
        form.addRow(self.repeat_caption, self.repeat)
        row = QHBoxLayout()
        row.addWidget(self.set_button)
        row.addWidget(self.clear_button)
        row.addStretch(1)
        idle_form = QFormLayout()
        idle_form.addRow(self.idle_caption, self.idle)
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        self.buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.table)
        layout.addLayout(form)
        layout.addLayout(row)
        layout.addLayout(idle_form)
        layout.addWidget(self.message)
        layout.addWidget(self.buttons)
        self.retranslate()
        self.table.selectRow(int(Role.ENGINEER))
        self._fit_table()

    def _fit_table(self) -> None:
        """Three rows, shown whole: the table as tall as its rows, the dialog as wide as its text."""
        table = self.table
        table.resizeColumnsToContents()
        rows = sum(table.rowHeight(r) for r in range(table.rowCount()))
        table.setFixedHeight(rows + table.horizontalHeader().sizeHint().height() + 2 * table.frameWidth() + 6)
        texts = [item.text() for r in range(table.rowCount()) if (item := table.item(r, 1)) is not None]
        widest = max((table.fontMetrics().horizontalAdvance(t) for t in texts), default=0)
        table.setMinimumWidth(table.columnWidth(0) + widest + 24 + 2 * table.frameWidth())

    # --- view ---------------------------------------------------------------------------------
    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("Passwords and lock"))
        self.table.setHorizontalHeaderLabels([self.tr("Role"), self.tr("Password")])
        self.password_caption.setText(self.tr("New password:"))
        self.repeat_caption.setText(self.tr("Repeat:"))
        self.set_button.setText(self.tr("Set / change password"))
        self.clear_button.setText(self.tr("Clear password"))
        self.idle_caption.setText(self.tr("Lock back to operator after:"))
        self.idle.setSuffix(self.tr(" min"))
        self.refresh()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def refresh(self) -> None:
        store = self._safety.session.store
        for role in Role:
            if role is Role.OPERATOR:
                state = self.tr("not needed (the pendant starts as operator)")
            elif store.has_password(role):
                state = self.tr("set")
            else:
                state = self.tr("not set (nobody can log in as this role)")
            for column, text in enumerate((self._safety.role_name(role), state)):
                item = QTableWidgetItem(text)
                item.setData(Qt.ItemDataRole.UserRole, int(role))
                self.table.setItem(int(role), column, item)
        self._update_buttons()

    def selected_role(self) -> Role | None:
        rows = self.table.selectionModel().selectedRows() if self.table.selectionModel() else []
        return Role(rows[0].row()) if rows else None

    def _why_not(self) -> str | None:
        return self._safety.reason(Action.MANAGE_ROLES)

    def _update_buttons(self) -> None:
        why = self._why_not()
        role = self.selected_role()
        store = self._safety.session.store
        may = why is None
        self.set_button.setEnabled(may and role not in (None, Role.OPERATOR))
        self.clear_button.setEnabled(
            may and role is not None and role is not Role.ADMINISTRATOR and store.has_password(role)
        )
        inputs: tuple[QWidget, ...] = (self.password, self.repeat, self.idle, self.table)
        for widget in inputs:
            widget.setEnabled(may)
        tip = why or ""
        for widget in (self.set_button, self.clear_button, *inputs[:3]):
            widget.setToolTip(tip)
        if role is Role.ADMINISTRATOR and may:
            self.clear_button.setToolTip(self.tr("The administrator password can be changed, not removed"))
        if not may:
            self.message.setText(tip)

    # --- actions ------------------------------------------------------------------------------
    def _say(self, text: str, *, error: bool = False) -> None:
        self.message.setStyleSheet("color: #c62828;" if error else "")
        self.message.setText(text)

    def set_password(self) -> None:
        role = self.selected_role()
        if role is None or role is Role.OPERATOR:
            return
        if self.password.text() != self.repeat.text():
            self._say(self.tr("The two passwords differ"), error=True)
            return
        try:
            self._safety.session.set_password(role, self.password.text())
        except PermissionRefused:
            self._say(self._why_not() or "", error=True)
            return
        except (OSError, TeachPadError) as exc:
            self._say(self.tr("Not set: {why}").format(why=str(exc)[:160]), error=True)
            return
        finally:
            self.password.clear()
            self.repeat.clear()
        self._say(self.tr("Password set for the {role} role").format(role=self._safety.role_name(role)))
        self.refresh()

    def clear_password(self) -> None:
        role = self.selected_role()
        if role is None:
            return
        try:
            self._safety.session.clear_password(role)
        except PermissionRefused:
            self._say(self._why_not() or "", error=True)
            return
        except (OSError, TeachPadError) as exc:
            self._say(self.tr("Not cleared: {why}").format(why=str(exc)[:160]), error=True)
            return
        self._say(self.tr("Password cleared for the {role} role").format(role=self._safety.role_name(role)))
        self.refresh()

    def set_idle(self, minutes: int) -> None:
        if minutes * 60.0 == self._safety.session.store.idle_timeout:
            return
        try:
            self._safety.session.set_idle_timeout(minutes * 60.0)
        except PermissionRefused:
            self._say(self._why_not() or "", error=True)
            return
        except (OSError, TeachPadError) as exc:
            self._say(self.tr("The setting could not be saved: {why}").format(why=str(exc)[:120]), error=True)
            return
        self._say(self.tr("The window locks back to operator after {n} min without input").format(n=minutes))

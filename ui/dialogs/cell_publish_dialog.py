"""*Plant link…* of the Cell tab: publish the cell to an MQTT broker (Sparkplug B), off by default.

The same edge node as ``teachpad-gateway`` (:mod:`app.cell.publish`): the broker's URL, the
Sparkplug group and node ids. A bad value is said in words in the dialog, which stays open.
"""

from __future__ import annotations

import socket

from PySide6.QtWidgets import (
    QCheckBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QVBoxLayout,
    QWidget,
)

from app.cell.publish import PublishSettings, parse_broker, valid_name
from app.gateway.cli import PASSWORD_ENV

__all__ = ["CellPublishDialog"]

ERROR_STYLE = "color: #b00000;"


class CellPublishDialog(QDialog):
    """Whether and where the GUI publishes its cell; :meth:`values` once accepted."""

    def __init__(self, enabled: bool, settings: PublishSettings, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("CellPublishDialog")
        self.setWindowTitle(self.tr("Plant link"))
        layout = QVBoxLayout(self)
        self.explain = QLabel(
            self.tr(
                "Publish every controller of the cell to an MQTT broker as a Sparkplug B edge node, "
                "as teachpad-gateway does (read only: nothing is written to a controller). "
                "A broker password comes from the environment variable {name}, never from the settings."
            ).format(name=PASSWORD_ENV),
            self,
        )
        self.explain.setWordWrap(True)
        layout.addWidget(self.explain)
        self.enabled_box = QCheckBox(self.tr("Publish this cell"), self)
        self.enabled_box.setChecked(enabled)
        layout.addWidget(self.enabled_box)
        form = QFormLayout()
        self.broker_edit = QLineEdit(settings.broker, self)
        self.broker_edit.setPlaceholderText("mqtt://HOST:1883")
        self.group_edit = QLineEdit(settings.group, self)
        self.node_edit = QLineEdit(settings.node, self)
        self.node_edit.setPlaceholderText(socket.gethostname())
        form.addRow(self.tr("Broker:"), self.broker_edit)
        form.addRow(self.tr("Group:"), self.group_edit)
        form.addRow(self.tr("Node:"), self.node_edit)
        layout.addLayout(form)
        self.error_label = QLabel(self)
        self.error_label.setObjectName("CellPublishError")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet(ERROR_STYLE)
        self.error_label.hide()
        layout.addWidget(self.error_label)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel, parent=self
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.resize(520, self.sizeHint().height())

    def values(self) -> tuple[bool, PublishSettings]:
        settings = PublishSettings(
            broker=self.broker_edit.text().strip(),
            group=self.group_edit.text().strip(),
            node=self.node_edit.text().strip(),
        )
        return self.enabled_box.isChecked(), settings

    def problem(self) -> str | None:
        """What is wrong with the values, in words (None: nothing)."""
        _enabled, settings = self.values()
        if parse_broker(settings.broker) is None:
            return self.tr(
                "The broker must be mqtt://HOST[:PORT] or mqtts://HOST[:PORT] (a user name may come "
                "before the host, USER@HOST; the password only from {name})."
            ).format(name=PASSWORD_ENV)
        if not valid_name(settings.group) or not valid_name(settings.node_id):
            return self.tr("The group and the node must not be empty nor contain '/', '+' or '#'.")
        return None

    def accept(self) -> None:
        problem = self.problem() if self.enabled_box.isChecked() else None
        if problem is not None:
            self.error_label.setText(problem)
            self.error_label.show()
            return
        super().accept()

"""*File → Compare with…* (issue 24): the project's points against a project or a points CSV.

:class:`ComparePoints` owns the action (inserted in the File menu after *Export points*) and the
dialog (:class:`~ui.dialogs.compare_points.ComparePointsDialog`, shown window-modal, not
blocking). Its file chooser and error messages go through the window's project dialogs
(``window.project.dialogs``: tests answer them); a file that cannot be read or is malformed is
said in one message, nothing is compared.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, Slot
from PySide6.QtGui import QAction

from app.errors import InvalidInput
from ui.messages import os_error_text, refusal_text

if TYPE_CHECKING:  # the dialog's and the diff's modules load with the first comparison, not at start-up
    from ui.dialogs.compare_points import ComparePointsDialog

__all__ = ["ComparePoints", "install_compare"]


class ComparePoints(QObject):
    """See the module docstring. ``dialog``: the last comparison shown (None before the first)."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.dialog: ComparePointsDialog | None = None
        self.action = QAction(window)
        self.action.setObjectName("ComparePointsAction")
        self.action.triggered.connect(self.choose)
        menu = window.menus.file_menu
        actions = menu.actions()
        export = window.project.action_export_csv
        after = actions[actions.index(export) + 1] if export in actions[:-1] else None
        menu.insertAction(after, self.action)
        window.installEventFilter(self)
        self.retranslate()

    def retranslate(self) -> None:
        self.action.setText(self.tr("Compare &with…"))
        self.action.setToolTip(
            self.tr(
                "Compare the project's points with another project or a points CSV: added, removed, moved"
            )
        )
        self.action.setStatusTip(self.action.toolTip())

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window and event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        return False

    @Slot()
    def choose(self) -> None:
        path = self.window.project.dialogs.open_path(
            self.tr("Compare with"), self.tr("Projects and points CSV (*.json *.csv);;All files (*)")
        )
        if path:
            self.compare_with(path)

    def compare_with(self, path: str | os.PathLike[str]) -> ComparePointsDialog | None:
        """Compare the project's points (A) with the file's (B) and show the dialog."""
        from app.points.diff import load_points_source

        project = self.window.project
        try:
            other = load_points_source(path, project.project.ledger.limits)
        except InvalidInput as exc:
            project.dialogs.error(self.tr("Cannot compare"), refusal_text(exc))
            return None
        except OSError as exc:
            project.dialogs.error(self.tr("Cannot compare"), os_error_text(path, exc))
            return None
        from ui.dialogs.compare_points import ComparePointsDialog

        if self.dialog is not None:
            self.dialog.close()
            self.dialog.deleteLater()
        dialog = ComparePointsDialog(
            list(project.project.ledger), project.display_name, other, Path(path).name, self.window
        )
        self.dialog = dialog
        dialog.open()
        return dialog


def install_compare(window: Any) -> ComparePoints:
    return ComparePoints(window)

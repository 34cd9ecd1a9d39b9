"""The Qt dialogs of :class:`~ui.controllers.project_controller.ProjectController`: file choosers
and questions. Tests replace this object with one that answers without showing anything.

The Qt dialog classes are imported by the method that shows one: the window's first paint does
not wait for them (each is made ready on its first use)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from app.points.ledger_import import ImportMode

if TYPE_CHECKING:
    from PySide6.QtWidgets import QWidget


class ProjectDialogs:
    """Questions and file choosers of :class:`ProjectController` (Qt dialogs).

    Tests pass an object with the same methods that answers without showing anything."""

    def __init__(self, parent: QWidget | None = None) -> None:
        self.parent = parent

    def tr(self, text: str) -> str:
        from PySide6.QtCore import QCoreApplication

        return QCoreApplication.translate("ProjectDialogs", text)

    def open_path(self, title: str, filters: str) -> str | None:
        from PySide6.QtWidgets import QFileDialog

        path, _ = QFileDialog.getOpenFileName(self.parent, title, "", filters)
        return path or None

    def save_path(self, title: str, filters: str, suggested: str) -> str | None:
        from PySide6.QtWidgets import QFileDialog

        path, _ = QFileDialog.getSaveFileName(self.parent, title, suggested, filters)
        return path or None

    def error(self, title: str, text: str) -> None:
        from PySide6.QtWidgets import QMessageBox

        QMessageBox.critical(self.parent, title, text)

    def ask_save_changes(self, name: str) -> str:
        """ "save", "discard" or "cancel"."""
        from PySide6.QtWidgets import QMessageBox

        box = QMessageBox(
            QMessageBox.Icon.Question,
            self.tr("Unsaved changes"),
            self.tr("Save the changes to {name}?").format(name=name),
            QMessageBox.StandardButton.Save
            | QMessageBox.StandardButton.Discard
            | QMessageBox.StandardButton.Cancel,
            self.parent,
        )
        answer = box.exec()
        if answer == QMessageBox.StandardButton.Save:
            return "save"
        if answer == QMessageBox.StandardButton.Discard:
            return "discard"
        return "cancel"

    def ask_recover(self, autosave: Path, project_path: Path | None) -> bool:
        from PySide6.QtWidgets import QMessageBox

        what = str(project_path) if project_path else self.tr("an unsaved project")
        text = self.tr(
            "TeachPad was not closed properly. An autosave of {what} is newer than the saved "
            "file:\n{autosave}\n\nRecover it?"
        ).format(what=what, autosave=autosave)
        answer = QMessageBox.question(
            self.parent,
            self.tr("Recover autosave"),
            text,
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.Yes,
        )
        return answer == QMessageBox.StandardButton.Yes

    def ask_empty_import(self, existing: int) -> bool:
        """The CSV has no points: replace (delete) all ``existing`` points anyway?"""
        from PySide6.QtWidgets import QMessageBox

        text = self.tr(
            "The file has no points. Importing it in replace mode removes all {n} points of "
            "the project.\n\nRemove them all?"
        ).format(n=existing)
        answer = QMessageBox.warning(
            self.parent,
            self.tr("Import points"),
            text,
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.No,
        )
        return answer == QMessageBox.StandardButton.Yes

    def ask_import_mode(self) -> ImportMode | None:
        from PySide6.QtWidgets import QInputDialog

        replace_text = self.tr("Replace all points")
        merge_text = self.tr("Merge (update the same ids, append new ones)")
        choice, ok = QInputDialog.getItem(
            self.parent,
            self.tr("Import points"),
            self.tr("Import mode:"),
            [replace_text, merge_text],
            0,
            False,
        )
        if not ok:
            return None
        return ImportMode.MERGE if choice == merge_text else ImportMode.REPLACE

"""The widgets the points panel is made of, apart from its logic (:mod:`ui.panels.points_panel`).

* :class:`PointsActionBar`: the primary row (Teach, Upload ▾, Restore all, Move to point and its
  speed: plain buttons, a toolbar would hide them behind » on a narrow screen), then the edit
  toolbar, the filter (id or name) and the J7–J11 switch;
* :class:`RestoreBanner`: "the controller may have lost its points", with Restore all;
* :class:`UploadProgressRow`: the running upload, with Cancel;
* :class:`PointsTable`: the ledger table (rows selected whole, E1..E5 hideable, widths that fit
  the columns) and its context menu.

They show and forward; the panel decides what is enabled. Their texts keep the panel's
translation context ("PointsPanel", literal in each call: lupdate reads it from there).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from PySide6.QtCore import QCoreApplication, QModelIndex, QPoint, Qt
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDoubleSpinBox,
    QFrame,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QMenu,
    QProgressBar,
    QPushButton,
    QTableView,
    QToolBar,
    QToolButton,
    QWidget,
)

from ui.controllers.point_sync import DEFAULT_MOVE_SPEED, MAX_MOVE_SPEED
from ui.models.point_columns import COL_ID, COL_NAME, COL_SYNC, COLUMNS, EXT_COLUMNS
from ui.palette import COLOR_WARN, COLOR_WARN_BG
from ui.touch import MOTION_MIN_HEIGHT, mark_motion

__all__ = ["PointsActionBar", "PointsTable", "RestoreBanner", "UploadProgressRow"]

ROW_HEIGHT = 24  # px, a table row
FIND_MAX_WIDTH = 220  # px


def _bold(widget: QWidget) -> None:
    font = widget.font()
    font.setBold(True)
    widget.setFont(font)


class PointsActionBar:
    """Two rows for the panel's layout: ``primary_row`` (``teach_button``, ``upload_button``
    with its menu, ``restore_all_button``, ``move_to_button``, ``speed``, ``speed_cap``) and ``edit_row``
    (``toolbar`` with the edit actions, ``find_label``, ``find_edit``, ``ext_button``)."""

    def __init__(
        self,
        parent: QWidget,
        *,
        teach: QAction,
        upload_selected: QAction,
        upload_needed: QAction,
        upload_all: QAction,
        restore_all: QAction,
        move_to: QAction,
        show_ext: QAction,
        edits: Sequence[QAction],
    ) -> None:
        self.primary_row = QWidget(parent)
        self.primary_row.setObjectName("PointsPrimary")
        primary = QHBoxLayout(self.primary_row)
        primary.setContentsMargins(0, 0, 0, 0)
        self.teach_button = self._primary_button(teach)
        _bold(self.teach_button)
        self.upload_button = self._primary_button(upload_selected)
        self.upload_button.setPopupMode(QToolButton.ToolButtonPopupMode.MenuButtonPopup)
        upload_menu = QMenu(self.upload_button)
        for action in (upload_selected, upload_needed, upload_all, restore_all):
            upload_menu.addAction(action)
        self.upload_button.setMenu(upload_menu)
        self.restore_all_button = self._primary_button(restore_all)
        self.move_to_button = self._primary_button(move_to)
        mark_motion(self.move_to_button)
        self.speed = QDoubleSpinBox(self.primary_row)
        self.speed.setRange(0.1, MAX_MOVE_SPEED)
        self.speed.setDecimals(1)
        self.speed.setValue(DEFAULT_MOVE_SPEED)
        self.speed.setSuffix(" mm/s")
        self.speed.setKeyboardTracking(False)
        self.speed.setMinimumHeight(MOTION_MIN_HEIGHT)
        for widget in (self.teach_button, self.upload_button, self.restore_all_button):
            primary.addWidget(widget)
        primary.addSpacing(12)
        primary.addWidget(self.move_to_button)
        primary.addWidget(self.speed)
        self.speed_cap = QLabel(self.primary_row)  # reduced speed's cap, when below the speed
        self.speed_cap.setObjectName("PointsSpeedCap")
        self.speed_cap.setStyleSheet("QLabel { color: #ef8f00; font-weight: bold; }")
        self.speed_cap.hide()
        primary.addWidget(self.speed_cap)
        primary.addStretch(1)

        self.edit_row = QWidget(parent)
        self.toolbar = QToolBar(self.edit_row)
        self.toolbar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        for action in edits:
            self.toolbar.addAction(action)
        self.find_label = QLabel(self.edit_row)
        self.find_edit = QLineEdit(self.edit_row)
        self.find_edit.setClearButtonEnabled(True)
        self.find_edit.setMaximumWidth(FIND_MAX_WIDTH)
        self.ext_button = QToolButton(self.edit_row)
        self.ext_button.setDefaultAction(show_ext)
        self.ext_button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        top = QHBoxLayout(self.edit_row)
        top.setContentsMargins(0, 0, 0, 0)
        top.addWidget(self.toolbar, 1)
        top.addWidget(self.find_label)
        top.addWidget(self.find_edit)
        top.addWidget(self.ext_button)

    def _primary_button(self, action: QAction) -> QToolButton:
        button = QToolButton(self.primary_row)
        button.setDefaultAction(action)
        button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        button.setMinimumHeight(MOTION_MIN_HEIGHT)
        return button

    def retranslate(self) -> None:
        self.speed.setToolTip(QCoreApplication.translate("PointsPanel", "Speed of Move to point"))
        self.find_label.setText(QCoreApplication.translate("PointsPanel", "Find:"))
        self.find_edit.setPlaceholderText(QCoreApplication.translate("PointsPanel", "id or name"))

    def focus_find(self) -> None:
        self.find_edit.setFocus()
        self.find_edit.selectAll()


class RestoreBanner(QFrame):
    """Shown while the controller may have lost its points; ``restore_button`` re-creates them."""

    def __init__(self, restore: Callable[[], object], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("restoreBanner")
        self.setStyleSheet(
            f"#restoreBanner {{ background: {COLOR_WARN_BG}; "
            f"border: 1px solid {COLOR_WARN}; border-radius: 4px; }}"
        )
        row = QHBoxLayout(self)
        row.setContentsMargins(8, 4, 8, 4)
        self.label = QLabel(self)
        self.label.setWordWrap(True)
        self.restore_button = QPushButton(self)
        self.restore_button.clicked.connect(restore)
        _bold(self.restore_button)
        row.addWidget(self.label, 1)
        row.addWidget(self.restore_button)

    def retranslate(self) -> None:
        self.label.setText(
            QCoreApplication.translate(
                "PointsPanel",
                "The controller restarted, or it is another controller: it may not hold "
                "these points. Re-create them before running a plan.",
            )
        )
        self.restore_button.setText(QCoreApplication.translate("PointsPanel", "Restore all"))


class UploadProgressRow(QWidget):
    """``progress`` of the running upload and its ``cancel_button``; hidden between uploads."""

    def __init__(self, cancel: Callable[[], object], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        row = QHBoxLayout(self)
        row.setContentsMargins(0, 0, 0, 0)
        self.label = QLabel(self)
        self.progress = QProgressBar(self)
        self.progress.setTextVisible(True)
        self.cancel_button = QPushButton(self)
        self.cancel_button.clicked.connect(cancel)
        row.addWidget(self.label)
        row.addWidget(self.progress, 1)
        row.addWidget(self.cancel_button)
        self.hide()

    def retranslate(self) -> None:
        self.cancel_button.setText(QCoreApplication.translate("PointsPanel", "Cancel"))
        self.label.setText(QCoreApplication.translate("PointsPanel", "Uploading"))

    def show_progress(self, done: int, total: int) -> None:
        self.show()
        self.progress.setRange(0, max(total, 1))
        self.progress.setValue(done)
        self.progress.setFormat(QCoreApplication.translate("PointsPanel", "%v of %m points"))


class PointsTable(QTableView):
    """The ledger table. ``menu_actions`` (None: a separator) make its context menu; a right
    click on an unselected row selects it first."""

    def __init__(self, menu_actions: Sequence[QAction | None], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._menu_actions = list(menu_actions)
        self.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        self.setEditTriggers(
            QAbstractItemView.EditTrigger.DoubleClicked
            | QAbstractItemView.EditTrigger.EditKeyPressed
            | QAbstractItemView.EditTrigger.AnyKeyPressed
        )
        self.setAlternatingRowColors(True)
        self.setWordWrap(False)
        self.verticalHeader().setVisible(False)
        self.verticalHeader().setDefaultSectionSize(ROW_HEIGHT)
        header = self.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        header.setStretchLastSection(True)
        self.setContextMenuPolicy(Qt.ContextMenuPolicy.CustomContextMenu)
        self.customContextMenuRequested.connect(self._context_menu)

    def size_columns(self) -> None:
        """Widths that fit the columns (once the model is set)."""
        widths = {COL_ID: 56, COL_NAME: 150, COL_SYNC: 130, COLUMNS.index("tool"): 70}
        widths.update(dict.fromkeys(EXT_COLUMNS, 62))  # usually zero: narrower than the pose
        for column in range(len(COLUMNS)):
            self.setColumnWidth(column, widths.get(column, 80))

    def show_ext(self, shown: bool) -> None:
        for column in EXT_COLUMNS:
            self.setColumnHidden(column, not shown)

    def _context_menu(self, pos: QPoint) -> None:
        index = self.indexAt(pos)
        if index.isValid() and not self.selectionModel().isRowSelected(index.row(), QModelIndex()):
            self.selectRow(index.row())
        menu = QMenu(self)
        for action in self._menu_actions:
            if action is None:
                menu.addSeparator()
            else:
                menu.addAction(action)
        menu.popup(self.viewport().mapToGlobal(pos))

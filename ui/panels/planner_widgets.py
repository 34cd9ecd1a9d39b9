"""The planner's parts that only draw: the plan list, the segment table with its editors,
the run box (buttons, progress) and the checks bar (summary, Upload now, Check). What they
show is worked out by :mod:`app.plan.presenter`; the panel (``planner_panel.py``) wires them."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from PySide6.QtCore import QAbstractItemModel, QModelIndex, QPersistentModelIndex, Qt
from PySide6.QtGui import QAction, QFontMetrics, QResizeEvent
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QFrame,
    QGridLayout,
    QGroupBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QProgressBar,
    QPushButton,
    QSizePolicy,
    QStyledItemDelegate,
    QStyleOptionViewItem,
    QTableView,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.plan.presenter import CheckSummary, Level, progress_bar
from app.plan.runner import RunEvent, RunProgress
from app.plan.segments import SegmentKind
from ui.joins import join_clauses
from ui.models.plan_columns import (
    COL_END,
    COL_IGNORE,
    COL_INDEX,
    COL_KIND,
    COL_LENGTH,
    COL_ORIENTATION,
    COL_SPEED,
    COL_TOOL,
    COL_VIA,
    PLAN_COL_NAME,
    kind_text,
    orientation_text,
)
from ui.models.plan_model import PlanListModel
from ui.models.points_model import PointsModel
from ui.models.segment_model import SegmentTableModel
from ui.palette import COLOR_ERROR, COLOR_INFO, COLOR_OK, COLOR_WARN, COLOR_WARN_TEXT
from ui.touch import mark_motion
from ui.widgets.lines_label import LinesLabel

ModelIndex = QModelIndex | QPersistentModelIndex

#: Colour of a summary line by level (the status line uses the darker warning text).
SUMMARY_COLOURS: dict[Level, str] = {
    Level.OK: COLOR_OK,
    Level.INFO: COLOR_INFO,
    Level.WARN: COLOR_WARN,
    Level.ERROR: COLOR_ERROR,
}
STATUS_COLOURS: dict[Level, str] = {**SUMMARY_COLOURS, Level.WARN: COLOR_WARN_TEXT, Level.INFO: COLOR_OK}


RUN_LABEL_LINES = 2
RESUME_FROM_MIN_WIDTH = 120  # px: "Resume from segment 12, loop 3" has half the run strip
SEGMENT_BUTTONS_PER_ROW = 6  # Plans (show / hide the list) and the five segment edits
SUMMARY_MIN_WIDTH = 120  # px, the checks' summary beside Upload now / Check (it wraps)
PLAN_LIST_MIN_ROWS = 2  # the plan list scrolls below this; the run box keeps its room


def action_button(action: QAction, *, bold: bool = False) -> QToolButton:
    """A text button for ``action`` that takes the row's width."""
    button = QToolButton()
    button.setDefaultAction(action)
    button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
    button.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
    button.setMinimumHeight(28)
    if bold:
        font = button.font()
        font.setBold(True)
        button.setFont(font)
    return button


class ChoiceDelegate(QStyledItemDelegate):
    """A combo box of fixed choices: ``choices()`` gives ``(value, text)`` pairs."""

    def __init__(
        self, choices: Callable[[], Sequence[tuple[str, str]]], parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self._choices = choices

    def createEditor(self, parent: QWidget, option: QStyleOptionViewItem, index: ModelIndex) -> QWidget:
        combo = QComboBox(parent)
        for value, text in self._choices():
            combo.addItem(text, value)
        return combo

    def setEditorData(self, editor: QWidget, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        found = editor.findData(index.data(Qt.ItemDataRole.EditRole))
        editor.setCurrentIndex(max(found, 0))

    def setModelData(self, editor: QWidget, model: QAbstractItemModel, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        model.setData(index, editor.currentData(), Qt.ItemDataRole.EditRole)


class PointRefDelegate(QStyledItemDelegate):
    """An editable combo box of the ledger's points (``P5  name``); typing an id works too."""

    def __init__(self, points: PointsModel, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self._points = points

    def createEditor(self, parent: QWidget, option: QStyleOptionViewItem, index: ModelIndex) -> QWidget:
        combo = QComboBox(parent)
        combo.setEditable(True)
        combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
        for point in self._points.ledger:
            combo.addItem(f"P{point.id}  {point.name}".rstrip(), str(point.id))
        return combo

    def setEditorData(self, editor: QWidget, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        value = str(index.data(Qt.ItemDataRole.EditRole) or "")
        found = editor.findData(value)
        if found >= 0:
            editor.setCurrentIndex(found)
        else:
            editor.setEditText(value)

    def setModelData(self, editor: QWidget, model: QAbstractItemModel, index: ModelIndex) -> None:
        assert isinstance(editor, QComboBox)
        text = editor.currentText()
        found = editor.findText(text)
        model.setData(index, editor.itemData(found) if found >= 0 else text, Qt.ItemDataRole.EditRole)


class PlanRunBox(QFrame):
    """Run, Run from here, Step, Pause, Resume and Stop in one row; under them Resume from k and
    how the run goes (progress, and the outcome in :data:`RUN_LABEL_LINES` lines).

    A strip across the planner's width: it never scrolls, and nothing in it moves when a stop
    shows Resume from k (its place is kept while it is hidden) or a long reason (the label's
    height is fixed; the whole text is in its tooltip and the planner's status line)."""

    def __init__(
        self,
        run: QAction,
        run_from: QAction,
        step: QAction,
        pause: QAction,
        resume: QAction,
        stop: QAction,
        resume_from: QAction,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("PlanRunBox")
        self.setFrameShape(QFrame.Shape.StyledPanel)  # no title: the buttons say what it is
        stop_button = action_button(stop, bold=True)
        stop_button.setStyleSheet(f"QToolButton:enabled {{ color: {COLOR_ERROR}; }}")
        buttons = QGridLayout()
        buttons.setSpacing(3)
        row = (
            action_button(run, bold=True),
            action_button(run_from),
            action_button(step),
            action_button(pause),
            action_button(resume),
            stop_button,
        )
        for column, button in enumerate(row):
            mark_motion(button)
            buttons.addWidget(button, 0, column)
            buttons.setColumnStretch(column, 1)
        self.resume_from_button = action_button(resume_from)
        mark_motion(self.resume_from_button)
        policy = self.resume_from_button.sizePolicy()
        policy.setRetainSizeWhenHidden(True)  # a stop shows it: nothing beside it moves
        policy.setHorizontalPolicy(QSizePolicy.Policy.Ignored)  # its width: the grid's, not its text's
        self.resume_from_button.setSizePolicy(policy)
        self.resume_from_button.setMinimumWidth(RESUME_FROM_MIN_WIDTH)
        self.resume_from_button.hide()  # until a stopped run can be resumed
        # the outcome of a run (a stop's reason can be long) gets room for RUN_LABEL_LINES
        # lines from the start, so the box does not grow over its neighbours after a stop
        self.run_label = LinesLabel(RUN_LABEL_LINES, self)
        self.run_progress = QProgressBar(self)
        self.run_progress.setTextVisible(False)
        self.run_progress.setMaximumHeight(10)
        how = QVBoxLayout()
        how.setSpacing(2)
        how.addWidget(self.run_progress)
        how.addWidget(self.run_label)
        buttons.addWidget(self.resume_from_button, 1, 0, 1, 3, Qt.AlignmentFlag.AlignTop)
        buttons.addLayout(how, 1, 3, 1, 3)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addLayout(buttons)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Fixed)

    def retranslate(self) -> None:
        pass  # the buttons' words are their actions'; the strip has no title (its height is the table's)

    def show_progress(self, progress: RunProgress) -> None:
        loops = self.tr("endless") if progress.loops == 0 else str(progress.loops)
        self.run_label.setText(
            self.tr("Segment {k} of {n}, loop {i} of {m}").format(
                k=progress.index + 1, n=progress.count, i=progress.loop, m=loops
            )
        )
        bar = progress_bar(
            progress.index,
            progress.count,
            progress.loop,
            progress.loops,
            progress.event is RunEvent.SEGMENT_DONE,
        )
        if bar is None:
            self.run_progress.setRange(0, 0)  # endless: a busy bar
        else:
            done, total = bar
            self.run_progress.setRange(0, total)
            self.run_progress.setValue(done)

    def show_finished(self, segments_done: int) -> None:
        self.run_progress.setRange(0, 1)
        self.run_progress.setValue(1)
        self.run_label.setText(self.tr("Finished: {n} segments run").format(n=segments_done))

    def show_ended(self, text: str) -> None:
        self.run_label.setText(text)

    def show_paused(self, text: str) -> None:
        """Why the run is paused or not resumed (a run that paused itself; issue 19)."""
        self.run_label.setText(text)


class PlanChecksBar(QWidget):
    """The checks across the planner under the segment table and the preview (wrapped at word
    boundaries to the whole width), Upload now and Check on their right."""

    def __init__(
        self, upload: Callable[[], None], check: Callable[[], None], parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.summary = QLabel(self)
        self.summary.setWordWrap(True)
        self.summary.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.upload_button = QPushButton(self)
        self.upload_button.clicked.connect(upload)
        self.check_button = QPushButton(self)
        self.check_button.clicked.connect(check)
        self.summary.setSizePolicy(QSizePolicy.Policy.Ignored, QSizePolicy.Policy.Preferred)
        self.summary.setMinimumWidth(SUMMARY_MIN_WIDTH)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.summary, 1)
        layout.addWidget(self.upload_button, 0, Qt.AlignmentFlag.AlignTop)
        layout.addWidget(self.check_button, 0, Qt.AlignmentFlag.AlignTop)

    def retranslate(self) -> None:
        self.upload_button.setText(self.tr("Upload now"))
        self.check_button.setText(self.tr("Check"))

    def show_checks(self, checks: CheckSummary | None, can_upload: bool, held: bool = False) -> str:
        """Show the summary (None: no plan); returns the text shown. ``held``: an emergency stop
        or servo alarm is set, so a plan that passed is not "ready to run" (said, in amber)."""
        if checks is None:
            text, colour = "", ""
        elif checks.passed and held:
            text = self.tr(
                "Checks passed; the plan cannot run until the emergency stop or servo alarm is cleared"
            )
            colour = SUMMARY_COLOURS[Level.WARN]
        else:
            text = self._words(checks, can_upload)
            colour = SUMMARY_COLOURS[checks.level]
            if checks.whole_plan:
                text += "\n" + "\n".join(checks.whole_plan)
        self.summary.setText(text)
        self.summary.setStyleSheet(f"color: {colour};" if colour else "")
        self.summary.setToolTip(checks.details if checks is not None else "")
        self.upload_button.setVisible(bool(checks and checks.uploads) and can_upload)
        return text

    def _words(self, checks: CheckSummary, can_upload: bool) -> str:
        if checks.passed:
            return self.tr("Checks passed: ready to run")
        parts: list[str] = []
        if checks.errors:
            parts.append(self.tr("%n error(s)", "", checks.errors))
        if checks.uploads:
            parts.append(self.tr("%n point(s) need upload", "", len(checks.uploads)))
        if checks.warnings:
            parts.append(self.tr("%n warning(s)", "", checks.warnings))
        text = join_clauses(parts)
        if checks.uploads and can_upload:
            text += " — " + self.tr("Upload now?")
        if checks.first_row_error:
            text += "\n" + checks.first_row_error
        return text


class PlanListBox(QGroupBox):
    """The project's plans (name, loops, segments) and the plan buttons below them."""

    def __init__(
        self, plans: PlanListModel, actions: Sequence[QAction], parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.plan_view = QTableView(self)
        view = self.plan_view
        view.setModel(plans)
        view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        view.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        view.verticalHeader().setVisible(False)
        view.verticalHeader().setDefaultSectionSize(24)
        header = view.horizontalHeader()
        view.setMinimumHeight(header.sizeHint().height() + PLAN_LIST_MIN_ROWS * 24 + 2 * view.frameWidth())
        header.setSectionResizeMode(PLAN_COL_NAME, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.ResizeToContents)
        buttons = QGridLayout()  # two per row: the plans column stays narrow
        for i, action in enumerate(actions):
            buttons.addWidget(action_button(action), i // 2, i % 2)
        buttons.setSpacing(3)
        layout = QVBoxLayout(self)
        layout.addWidget(view, 1)
        layout.addLayout(buttons)

    def retranslate(self) -> None:
        self.setTitle(self.tr("Plans"))


SEGMENT_COLUMN_WIDTHS: dict[int, int] = {
    COL_INDEX: 50,
    COL_KIND: 50,
    COL_VIA: 104,
    COL_END: 104,
    COL_SPEED: 78,
    COL_ORIENTATION: 78,
    COL_IGNORE: 84,
    COL_TOOL: 60,
    COL_LENGTH: 76,
}


class SegmentEditorBox(QGroupBox):
    """The segment table (combo-box editors for kind, orientation and points) and its buttons
    above it (the checks bar is under the table and the preview: :mod:`ui.panels.planner_layout`)."""

    def __init__(
        self,
        segments: SegmentTableModel,
        points: PointsModel,
        actions: Sequence[QAction],
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.segment_view = QTableView(self)
        view = self.segment_view
        view.setModel(segments)
        view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        view.setSelectionMode(QAbstractItemView.SelectionMode.ExtendedSelection)
        view.setEditTriggers(
            QAbstractItemView.EditTrigger.DoubleClicked
            | QAbstractItemView.EditTrigger.EditKeyPressed
            | QAbstractItemView.EditTrigger.SelectedClicked
        )
        view.verticalHeader().setDefaultSectionSize(24)
        view.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
        view.setWordWrap(False)
        view.setAlternatingRowColors(True)
        self._kind_delegate = ChoiceDelegate(lambda: [(k.value, kind_text(k)) for k in SegmentKind], view)
        self._orientation_delegate = ChoiceDelegate(
            lambda: [("changes", orientation_text(True)), ("kept", orientation_text(False))], view
        )
        self._point_delegate = PointRefDelegate(points, view)
        view.setItemDelegateForColumn(COL_KIND, self._kind_delegate)
        view.setItemDelegateForColumn(COL_ORIENTATION, self._orientation_delegate)
        view.setItemDelegateForColumn(COL_VIA, self._point_delegate)
        view.setItemDelegateForColumn(COL_END, self._point_delegate)
        view.horizontalHeader().setStretchLastSection(True)
        for column in range(segments.columnCount()):
            view.setColumnWidth(column, SEGMENT_COLUMN_WIDTHS.get(column, 60))
        # all five buttons in one row: the box has the work column's width, and every row of
        # height goes to the table at 1280×800
        buttons = QGridLayout()
        buttons.setSpacing(3)
        per_row = SEGMENT_BUTTONS_PER_ROW
        for i, action in enumerate(actions):
            buttons.addWidget(action_button(action), i // per_row, i % per_row)
        buttons.setColumnStretch(per_row, 1)
        layout = QVBoxLayout(self)
        layout.addLayout(buttons)
        layout.addWidget(view, 1)

        self._plan_name = ""
        self.setProperty("elide", True)  # the plan's name is elided in the title, whole in the tooltip

    def retranslate(self) -> None:
        self._show_title()

    def set_plan_name(self, name: str) -> None:
        """The plan on display, named in the title (the plans list can be hidden)."""
        self._plan_name = name
        self._show_title()

    def resizeEvent(self, event: QResizeEvent) -> None:
        super().resizeEvent(event)
        self._show_title()

    def _show_title(self) -> None:
        name = self._plan_name
        title = self.tr("Segments of \u201c{plan}\u201d").format(plan=name) if name else self.tr("Segments")
        metrics = QFontMetrics(self.font())
        room = self.width() - 4 * metrics.horizontalAdvance(" ") - 16
        shown = metrics.elidedText(title, Qt.TextElideMode.ElideRight, max(room, 40))
        self.setTitle(shown)
        self.setToolTip(title if shown != title else "")

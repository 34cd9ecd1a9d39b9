"""Help → Check the controller's register map…: the self-test's report, line by line.

One row per check (:mod:`app.selftest.checks`): the check, its verdict (matches, does not match,
not checked), what was found and the likely fix, in the operator's language
(:mod:`ui.selftest_words`). *Check again* reads the registers again (in the link's worker; nothing
is written). The dialog follows its :class:`~ui.controllers.register_map_check.RegisterMapCheck`: a
report made after every connect shows here too.
"""

from __future__ import annotations

from PySide6.QtCore import QEvent, Qt, QTimer, Slot
from PySide6.QtGui import QBrush, QColor, QShowEvent
from PySide6.QtWidgets import (
    QAbstractItemView,
    QDialog,
    QDialogButtonBox,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.selftest.checks import CheckVerdict, SelfTestReport
from ui.controllers.register_map_check import RegisterMapCheck
from ui.palette import COLOR_ERROR, COLOR_NEUTRAL, COLOR_OK
from ui.selftest_words import check_name, fix_text, found_text, summary_text, verdict_text

__all__ = ["SelfTestDialog"]

_VERDICT_COLOR = {
    CheckVerdict.MATCH: COLOR_OK,
    CheckVerdict.MISMATCH: COLOR_ERROR,
    CheckVerdict.UNCHECKED: COLOR_NEUTRAL,
}
COLUMNS = 4  # check, verdict, found, fix


class SelfTestDialog(QDialog):
    """See the module docstring; ``table`` has one row per line of the last report."""

    def __init__(self, check: RegisterMapCheck, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("SelfTestDialog")
        self.check = check
        self.summary_label = QLabel(self)
        self.summary_label.setObjectName("SelfTestSummary")
        self.summary_label.setWordWrap(True)
        self.note_label = QLabel(self)
        self.note_label.setWordWrap(True)
        self.table = QTableWidget(0, COLUMNS, self)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setWordWrap(True)
        self.table.verticalHeader().setVisible(False)
        header = self.table.horizontalHeader()
        header.setSectionResizeMode(0, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(1, QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(2, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(3, QHeaderView.ResizeMode.Stretch)
        # the wrapped texts' heights follow the columns' widths (known once shown, or resized)
        self._fit_rows = QTimer(self)
        self._fit_rows.setSingleShot(True)
        self._fit_rows.setInterval(0)
        self._fit_rows.timeout.connect(self.table.resizeRowsToContents)
        header.sectionResized.connect(lambda *_: self._fit_rows.start())
        self.again_button = QPushButton(self)
        self.again_button.setObjectName("SelfTestAgain")
        self.again_button.clicked.connect(self._again)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close, self)
        buttons.addButton(self.again_button, QDialogButtonBox.ButtonRole.ActionRole)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(self.summary_label)
        layout.addWidget(self.table, 1)
        layout.addWidget(self.note_label)
        layout.addWidget(buttons)
        check.reported.connect(self._show_report)
        check.failed.connect(self._show_failure)
        check.started.connect(self._show_running)
        self.resize(1000, 520)
        self.retranslate()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        self.table.resizeRowsToContents()

    def retranslate(self) -> None:
        self.setWindowTitle(self.tr("The controller's register map"))
        self.table.setHorizontalHeaderLabels(
            [self.tr("Check"), self.tr("Result"), self.tr("What was read"), self.tr("Likely fix")]
        )
        self.again_button.setText(self.tr("Check &again"))
        self.note_label.setText(
            self.tr(
                "Only reads: nothing is written to the controller and nothing moves. The check runs by "
                "itself after every connect."
            )
        )
        self._refresh()

    def _refresh(self) -> None:
        check = self.check
        if check.running:
            self._show_running()
        elif check.error:
            self._show_failure(check.error)
        elif check.report is not None:
            self._show_report(check.report)
        else:
            self.table.setRowCount(0)
            self.summary_label.setText(self.tr("Not checked yet: connect to a controller first."))
        self.again_button.setEnabled(not check.running)

    @Slot()
    def _again(self) -> None:
        if not self.check.run():
            self.summary_label.setText(self.tr("Not connected to a controller: nothing can be read."))

    @Slot()
    def _show_running(self) -> None:
        self.summary_label.setText(self.tr("Reading the controller's registers…"))
        self.again_button.setEnabled(False)

    @Slot(str)
    def _show_failure(self, text: str) -> None:
        self.summary_label.setText(self.tr("The registers could not be read: {why}").format(why=text))
        self.again_button.setEnabled(True)

    @Slot(object)
    def _show_report(self, report: SelfTestReport) -> None:
        self.again_button.setEnabled(True)
        color = COLOR_OK if report.passed else COLOR_ERROR
        self.summary_label.setText(summary_text(report))
        self.summary_label.setStyleSheet(f"color: {color}; font-weight: bold;")
        self.table.setRowCount(len(report.lines))
        for row, line in enumerate(report.lines):
            verdict = QTableWidgetItem(verdict_text(line.verdict))
            verdict.setForeground(QBrush(QColor(_VERDICT_COLOR[line.verdict])))
            found = found_text(line)
            cells = (
                QTableWidgetItem(check_name(line)),
                verdict,
                QTableWidgetItem(found),
                QTableWidgetItem(fix_text(line)),
            )
            for column, item in enumerate(cells):
                item.setToolTip(line.line if column < 2 else item.text())
                item.setTextAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)
                self.table.setItem(row, column, item)
        self.table.resizeRowsToContents()

"""The audit trail viewer: filter by date, role, command and result; export the rows shown as CSV.
The role "plant" shows the Sparkplug gateway's records, each robot's (``plant (R1)``).

A command's result is the controller's outcome (done, refused -- with its status code, as
"refused:13" --, stopped, unknown; see app/link/outcome.py); other writes read ok when answered.
"""

from __future__ import annotations

import datetime as dt
import io
from collections.abc import Callable
from pathlib import Path
from typing import Any

from PySide6.QtCore import QAbstractTableModel, QDate, QModelIndex, QPersistentModelIndex, Qt
from PySide6.QtWidgets import (
    QComboBox,
    QDateEdit,
    QDialog,
    QFileDialog,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QTableView,
    QVBoxLayout,
    QWidget,
)

from app.points.atomic import atomic_write_bytes
from app.safety.audit_chain import verify_chain
from app.safety.audit_read import AuditFilter, AuditRecord, ReadStats, Result, export_csv, query, result_label
from app.safety.roles import PLANT_ROLE
from ui.audit_words import command_words, detail_words

DEFAULT_DAYS = 7  # the range shown when the viewer opens
MAX_ROWS = 20000  # newest rows kept in the table (the CSV export takes the same rows)

_Index = QModelIndex | QPersistentModelIndex


class AuditModel(QAbstractTableModel):
    COLUMNS = ("time", "role", "kind", "command", "result", "detail")

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.records: list[AuditRecord] = []

    def set_records(self, records: list[AuditRecord]) -> None:
        self.beginResetModel()
        self.records = records[-MAX_ROWS:]
        self.endResetModel()

    def rowCount(self, parent: _Index = QModelIndex()) -> int:  # noqa: B008 - Qt's API
        return 0 if parent.isValid() else len(self.records)

    def columnCount(self, parent: _Index = QModelIndex()) -> int:  # noqa: B008 - Qt's API
        return 0 if parent.isValid() else len(self.COLUMNS)

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if role != Qt.ItemDataRole.DisplayRole or orientation != Qt.Orientation.Horizontal:
            return None
        return (
            self.tr("Time"),
            self.tr("Role"),
            self.tr("Kind"),
            self.tr("Command"),
            self.tr("Result"),
            self.tr("Detail"),
        )[section]

    def data(self, index: _Index, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
        if not index.isValid() or role not in (Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.ToolTipRole):
            return None
        r = self.records[index.row()]
        col = self.COLUMNS[index.column()]
        if col == "time":
            return r.host_time.replace("T", " ")[:23]
        if col == "command":
            return command_words(r)
        if col == "detail":
            return detail_words(r)
        value = str(getattr(r, col))
        if col == "role" and value.startswith(f"{PLANT_ROLE} (") and value.endswith(")"):
            return self.tr("plant ({robot})").format(robot=value[len(PLANT_ROLE) + 2 : -1])
        if col in ("role", "kind", "result"):  # the file keeps English keys; the table shows words
            words = self._words().get(value, value)
            label = result_label(r) if col == "result" else value
            return words + label[len(value) :]  # "refused:13": the controller's code after the word
        return value

    def _words(self) -> dict[str, str]:
        return {
            "operator": self.tr("operator"),
            "engineer": self.tr("engineer"),
            "administrator": self.tr("administrator"),
            "administrator (cli)": self.tr("administrator (CLI)"),
            "write": self.tr("write"),
            "refused": self.tr("refused"),
            "login": self.tr("login"),
            "action": self.tr("action"),
            "ok": self.tr("answered"),  # a plain write: answered (a command reads its outcome)
            "failed": self.tr("failed"),
            "blocked": self.tr("blocked"),
            "unknown": self.tr("unknown"),
            "done": self.tr("done"),
            "stopped": self.tr("stopped"),
        }


class AuditViewer(QDialog):
    """``save_path(suggested) -> path or None`` asks where to export (tests replace it)."""

    def __init__(
        self,
        directory: Path,
        parent: QWidget | None = None,
        *,
        save_path: Callable[[str], str | None] | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("AuditViewer")
        self.setWindowTitle(self.tr("Audit trail"))
        self.directory = directory
        self._save_path = save_path or self._ask_path
        today = QDate.currentDate()
        self.start = QDateEdit(today.addDays(-(DEFAULT_DAYS - 1)), self)
        self.end = QDateEdit(today, self)
        for edit in (self.start, self.end):
            edit.setCalendarPopup(True)
            edit.setDisplayFormat("yyyy-MM-dd")
        self.role_box = QComboBox(self)
        self.role_box.addItem(self.tr("Any role"), None)
        for name, text in (
            ("operator", self.tr("operator")),
            ("engineer", self.tr("engineer")),
            ("administrator", self.tr("administrator")),
            ("administrator (cli)", self.tr("administrator (CLI)")),
            (PLANT_ROLE, self.tr("plant")),  # the gateway's writes, every robot's (plant (R1), ...)
        ):
            self.role_box.addItem(text, name)
        self.command = QLineEdit(self)
        self.command.setPlaceholderText(self.tr("Command contains…"))
        self.result_box = QComboBox(self)
        self.result_box.addItem(self.tr("Any result"), None)
        for value, text in (
            (Result.DONE, self.tr("done")),
            (Result.REFUSED, self.tr("refused")),
            (Result.STOPPED, self.tr("stopped")),
            (Result.UNKNOWN, self.tr("unknown")),
            (Result.OK, self.tr("answered")),
            (Result.FAILED, self.tr("failed")),
            (Result.BLOCKED, self.tr("blocked")),
        ):
            self.result_box.addItem(text, value)
        self.refresh_button = QPushButton(self.tr("Show"), self)
        self.refresh_button.clicked.connect(self.refresh)
        self.export_button = QPushButton(self.tr("Export CSV…"), self)
        self.export_button.clicked.connect(self.export)
        self.model = AuditModel(self)
        self.table = QTableView(self)
        self.table.setModel(self.model)
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.verticalHeader().hide()
        self.status = QLabel(self)
        filters = QHBoxLayout()
        for label, widget in ((self.tr("From"), self.start), (self.tr("to"), self.end)):
            filters.addWidget(QLabel(label, self))
            filters.addWidget(widget)
        for other in (self.role_box, self.command, self.result_box, self.refresh_button):
            filters.addWidget(other)
        bottom = QHBoxLayout()
        bottom.addWidget(self.status, 1)
        bottom.addWidget(self.export_button)
        layout = QVBoxLayout(self)
        layout.addLayout(filters)
        layout.addWidget(self.table, 1)
        layout.addLayout(bottom)
        self.resize(960, 560)
        self.refresh()

    def current_filter(self) -> AuditFilter:
        start = self.start.date().toPython()
        end = self.end.date().toPython()
        assert isinstance(start, dt.date) and isinstance(end, dt.date)
        tz = dt.datetime.now().astimezone().tzinfo
        return AuditFilter(
            start=dt.datetime.combine(start, dt.time.min, tz),
            end=dt.datetime.combine(end, dt.time.max, tz),
            role=self.role_box.currentData(),
            command=self.command.text().strip() or None,
            result=self.result_box.currentData(),
        )

    def refresh(self) -> None:
        stats = ReadStats()
        records = query(self.directory, self.current_filter(), stats)
        self.model.set_records(records)
        n = len(self.model.records)
        text = self.tr("{n} records")
        if stats.skipped:
            text = self.tr("{n} records ({skipped} damaged lines skipped)")
        if stats.unknown:  # sent, and its answer or the controller's outcome was never recorded
            text += " " + self.tr("{unknown} writes whose answer or outcome was not recorded")
        text = text.format(n=n, skipped=stats.skipped, unknown=stats.unknown)
        self.status.setText(" ".join(filter(None, (text, self._chain_text()))))
        self.table.scrollToBottom()

    def _chain_text(self) -> str:
        """Where the chain of hashes breaks in the days shown (a record changed or removed)."""
        report = verify_chain(self.directory, *self.current_filter().days())
        if report.breaks:
            first = report.breaks[0]
            if first.missing:
                where = self.tr(
                    "The chain of hashes breaks at {file} line {line}: records before it were removed."
                )
            else:
                where = self.tr(
                    "The chain of hashes breaks at {file} line {line}: the record before it was changed, or "
                    "records were removed."
                )
            text = where.format(file=first.file, line=first.line)
            if len(report.breaks) > 1:
                text += " " + self.tr("{n} breaks in all.").format(n=len(report.breaks))
            return text
        if report.records and not report.chained:
            return self.tr("(No chain of hashes: records of an older TeachPad.)")
        return ""

    def _ask_path(self, suggested: str) -> str | None:
        path, _ = QFileDialog.getSaveFileName(
            self, self.tr("Export the audit trail"), suggested, self.tr("CSV files (*.csv)")
        )
        return path or None

    def export(self) -> None:
        path = self._save_path(f"audit-{dt.date.today().isoformat()}.csv")
        if not path:
            return
        buffer = io.StringIO(newline="")
        n = export_csv(self.model.records, buffer)
        try:  # atomically, UTF-8 with a BOM: Excel on a Chinese Windows reads it as UTF-8
            atomic_write_bytes(path, buffer.getvalue().encode("utf-8-sig"))
        except OSError as exc:
            self.status.setText(
                self.tr("Cannot write {file}: {why}").format(file=Path(path).name, why=exc.strerror or exc)
            )
            return
        self.status.setText(self.tr("{n} records exported to {file}").format(n=n, file=Path(path).name))

"""Event log: timestamped info / warning / error rows from the link, the alarms and the commands.

``add_event`` is the general entry; ``on_alarms``, ``on_command_result`` and ``on_connection``
turn the worker's payloads into events (alarm bits are logged on their transitions only).

An event logged from a payload keeps that payload (the reason code and its arguments, the alarm
bit, the link state) in a small function that renders its source and text: on a language
change every such line is rendered again, so the log reads in one language.
"""

from __future__ import annotations

import dataclasses
import datetime as dt
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtCore import (
    QAbstractTableModel,
    QCoreApplication,
    QEvent,
    QModelIndex,
    QPersistentModelIndex,
    QSortFilterProxyModel,
    Qt,
    Signal,
    Slot,
)
from PySide6.QtGui import QBrush, QColor, QFont
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QPushButton,
    QTableView,
    QVBoxLayout,
    QWidget,
)

from app.event_store import EventStore, StoredEvent, export_line
from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import CommandResult
from app.points.atomic import atomic_write_bytes
from app.protocol.enums import ALARM_BITS, ALARM_TEXT, TR_CONTEXT
from ui.messages import connection_text, error_text, operation_text, result_level, result_text
from ui.palette import COLOR_ERROR, COLOR_ERROR_BG, COLOR_WARN_BG
from ui.widgets_common import (
    LEVEL_ERROR,
    LEVEL_WARN,
    connection_display,
    export_with_dialog,
    monospace_font,
)

LEVELS: tuple[str, ...] = ("info", "warning", "error")
MAX_EVENTS_DEFAULT = 5000
COL_TIME, COL_LEVEL, COL_SOURCE, COL_MESSAGE = range(4)
_COLUMN_COUNT = 4

Words = str | Callable[[], str]  # a text as written, or a function rendering it in the current language


@dataclass(frozen=True, slots=True)
class LogEvent:
    when: dt.datetime
    level: str  # one of LEVELS
    source: str
    text: str
    # render source / text again in the current language (None: the text was logged as written)
    source_of: Callable[[], str] | None = dataclasses.field(default=None, compare=False, repr=False)
    text_of: Callable[[], str] | None = dataclasses.field(default=None, compare=False, repr=False)

    @property
    def severity(self) -> int:
        return LEVELS.index(self.level)

    def rendered(self) -> LogEvent:
        """This event with its source and text rendered in the current language."""
        if self.source_of is None and self.text_of is None:
            return self
        return dataclasses.replace(
            self,
            source=self.source if self.source_of is None else self.source_of(),
            text=self.text if self.text_of is None else self.text_of(),
        )


class EventLogModel(QAbstractTableModel):
    """Bounded list of events, oldest dropped first. Columns: time, level, source, message."""

    def __init__(self, parent: Any = None, *, max_events: int = MAX_EVENTS_DEFAULT) -> None:
        super().__init__(parent)
        if max_events < 1:
            raise ValueError("max_events must be >= 1")
        self._events: list[LogEvent] = []
        self._max = max_events
        self._mono = monospace_font(9.5)
        self._fg: dict[str, QBrush] = {}  # made by the first warning or error shown (see _brushes)
        self._bg: dict[str, QBrush] = {}
        self._headers: tuple[str, ...] = ()
        self._level_text: dict[str, str] = {}
        self._set_texts()

    def _brushes(self) -> tuple[dict[str, QBrush], dict[str, QBrush]]:
        """(text, background) brushes by level, made by the first row drawn: PySide6 readies
        QGradient, QImage and QPixmap for the first QBrush(QColor), which the window's first paint
        does not need."""
        if not self._fg:
            self._fg = {"warning": QBrush(QColor("#8a5300")), "error": QBrush(QColor(COLOR_ERROR))}
            self._bg = {"warning": QBrush(QColor(COLOR_WARN_BG)), "error": QBrush(QColor(COLOR_ERROR_BG))}
        return self._fg, self._bg

    def _set_texts(self) -> None:
        self._headers = (
            QCoreApplication.translate("EventLogModel", "Time"),
            QCoreApplication.translate("EventLogModel", "Level"),
            QCoreApplication.translate("EventLogModel", "Source"),
            QCoreApplication.translate("EventLogModel", "Message"),
        )
        self._level_text = {
            "info": QCoreApplication.translate("EventLogModel", "Info"),
            "warning": QCoreApplication.translate("EventLogModel", "Warning"),
            "error": QCoreApplication.translate("EventLogModel", "Error"),
        }

    def retranslate(self) -> None:
        """Headers, level names and every event logged from a payload in the current language
        (a text added as written stays as written)."""
        self._set_texts()
        self.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, _COLUMN_COUNT - 1)
        if self._events:
            self._events = [event.rendered() for event in self._events]
            last = len(self._events) - 1
            self.dataChanged.emit(
                self.index(0, 0),
                self.index(last, _COLUMN_COUNT - 1),
                [Qt.ItemDataRole.DisplayRole, Qt.ItemDataRole.ToolTipRole],
            )

    @property
    def max_events(self) -> int:
        return self._max

    def add(self, event: LogEvent) -> None:
        if len(self._events) >= self._max:
            drop = min(len(self._events), max(1, self._max // 20))
            self.beginRemoveRows(QModelIndex(), 0, drop - 1)
            del self._events[:drop]
            self.endRemoveRows()
        row = len(self._events)
        self.beginInsertRows(QModelIndex(), row, row)
        self._events.append(event)
        self.endInsertRows()

    def prepend(self, events: list[LogEvent]) -> None:
        """Put ``events`` (older than every row, oldest first) before the rows, as many as fit."""
        events = events[max(0, len(events) - (self._max - len(self._events))) :]
        if not events:
            return
        self.beginInsertRows(QModelIndex(), 0, len(events) - 1)
        self._events[:0] = events
        self.endInsertRows()

    def clear(self) -> None:
        self.beginResetModel()
        self._events.clear()
        self.endResetModel()

    def event_at(self, row: int) -> LogEvent:
        return self._events[row]

    def events(self) -> Iterable[LogEvent]:
        return iter(self._events)

    def level_text(self, level: str) -> str:
        return self._level_text.get(level, level)

    def rowCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(self._events)

    def columnCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else _COLUMN_COUNT

    def data(
        self, index: QModelIndex | QPersistentModelIndex, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        if not index.isValid():
            return None
        r, column = index.row(), index.column()
        if not (0 <= r < len(self._events) and 0 <= column < _COLUMN_COUNT):
            return None
        by_role = _DATA_BY_ROLE.get(role)
        return None if by_role is None else by_role(self, self._events[r], column)

    def _display(self, event: LogEvent, column: int) -> str:
        if column == COL_TIME:
            return event.when.strftime("%H:%M:%S.") + f"{event.when.microsecond // 1000:03d}"
        if column == COL_LEVEL:
            return self.level_text(event.level)
        if column == COL_SOURCE:
            return event.source
        return event.text

    def _foreground(self, event: LogEvent, _column: int) -> QBrush | None:
        return self._brushes()[0].get(event.level)

    def _background(self, event: LogEvent, _column: int) -> QBrush | None:
        return self._brushes()[1].get(event.level)

    def _font(self, _event: LogEvent, column: int) -> QFont | None:
        return self._mono if column == COL_TIME else None

    def _tooltip(self, event: LogEvent, column: int) -> str | None:
        if column == COL_TIME:
            return event.when.isoformat(sep=" ", timespec="milliseconds")
        if column == COL_MESSAGE:
            return event.text
        return None

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        horizontal = orientation == Qt.Orientation.Horizontal
        if horizontal and role == Qt.ItemDataRole.DisplayRole and 0 <= section < _COLUMN_COUNT:
            return self._headers[section]
        return None


# what data() answers for each role it answers: the row's event and the column in, the value out
_DATA_BY_ROLE: dict[int, Callable[[EventLogModel, LogEvent, int], Any]] = {
    Qt.ItemDataRole.DisplayRole: EventLogModel._display,
    Qt.ItemDataRole.ForegroundRole: EventLogModel._foreground,
    Qt.ItemDataRole.BackgroundRole: EventLogModel._background,
    Qt.ItemDataRole.FontRole: EventLogModel._font,
    Qt.ItemDataRole.ToolTipRole: EventLogModel._tooltip,
}


class _LevelFilter(QSortFilterProxyModel):
    def __init__(self, parent: Any = None) -> None:
        super().__init__(parent)
        self._min = 0

    def set_min_severity(self, severity: int) -> None:
        if severity != self._min:
            self.beginFilterChange()
            self._min = severity
            self.endFilterChange(QSortFilterProxyModel.Direction.Rows)

    def filterAcceptsRow(self, source_row: int, source_parent: QModelIndex | QPersistentModelIndex) -> bool:
        model = self.sourceModel()
        assert isinstance(model, EventLogModel)
        return self._min == 0 or model.event_at(source_row).severity >= self._min


class EventLogPanel(QWidget):
    """Timestamped, colour-coded event list with a level filter, clear and export."""

    eventAdded = Signal(object)

    def __init__(self, parent: QWidget | None = None, *, max_events: int = MAX_EVENTS_DEFAULT) -> None:
        super().__init__(parent)
        self.setObjectName("EventLogPanel")
        self._alarms: int | None = None
        self._last_connection: tuple[LinkState, str] | None = None
        self._store: EventStore | None = None  # kept across restarts once attach_store is called
        self.model = EventLogModel(self, max_events=max_events)
        self.proxy = _LevelFilter(self)
        self.proxy.setSourceModel(self.model)

        self.level_combo = QComboBox(self)
        for severity in range(len(LEVELS)):
            self.level_combo.addItem("", severity)
        self.level_combo.currentIndexChanged.connect(
            lambda i: self.proxy.set_min_severity(int(self.level_combo.itemData(i)))
        )
        self.clear_button = QPushButton(self)
        self.clear_button.clicked.connect(self.clear)
        self.export_button = QPushButton(self)
        self.export_button.clicked.connect(self._export_dialog)

        self.view = QTableView(self)
        self.view.setModel(self.proxy)
        self.view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.view.setWordWrap(False)
        self.view.setTextElideMode(Qt.TextElideMode.ElideRight)
        vheader = self.view.verticalHeader()
        vheader.setVisible(False)
        vheader.setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
        vheader.setDefaultSectionSize(self.fontMetrics().height() + 6)
        header = self.view.horizontalHeader()
        header.setStretchLastSection(True)
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        digit = self.view.fontMetrics().horizontalAdvance("0")
        self.view.setColumnWidth(COL_TIME, digit * 15)
        self.view.setColumnWidth(COL_LEVEL, digit * 10)
        self.view.setColumnWidth(COL_SOURCE, digit * 12)

        bar = QHBoxLayout()
        bar.setContentsMargins(0, 0, 0, 0)
        self._show_label = QLabel(self)
        self._show_label.setBuddy(self.level_combo)
        bar.addWidget(self._show_label)
        bar.addWidget(self.level_combo)
        bar.addStretch(1)
        bar.addWidget(self.clear_button)
        bar.addWidget(self.export_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addLayout(bar)
        layout.addWidget(self.view, 1)
        self.retranslate()

    def retranslate(self) -> None:
        """(Re)set every user-visible text: at construction and on a language change."""
        self._show_label.setText(self.tr("Show:"))
        self.level_combo.setItemText(0, self.tr("All events"))
        self.level_combo.setItemText(1, self.tr("Warnings and errors"))
        self.level_combo.setItemText(2, self.tr("Errors only"))
        self.clear_button.setText(self.tr("Clear"))
        self.export_button.setText(self.tr("Export…"))
        self.model.retranslate()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- entries ----------------------------------------------------------------------
    def add_event(self, level: str, source: Words, text: Words, when: dt.datetime | None = None) -> LogEvent:
        """Log one event; ``level`` is "info", "warning" or "error"; ``when`` defaults to now.

        ``source`` and ``text`` are texts as written, or functions that render them in the
        current language (called now and again after a language change)."""
        if level not in LEVELS:
            raise ValueError(f"level must be one of {LEVELS}, got {level!r}")
        source_of = source if callable(source) else None
        text_of = text if callable(text) else None
        event = LogEvent(
            when or dt.datetime.now(),
            level,
            source if isinstance(source, str) else "",
            text if isinstance(text, str) else "",
            source_of,
            text_of,
        ).rendered()
        bar = self.view.verticalScrollBar()
        follow = bar.value() >= bar.maximum() - 2
        self.model.add(event)
        if follow:
            self.view.scrollToBottom()
        if self._store is not None:
            self._store.append(_stored(event))
        self.eventAdded.emit(event)
        return event

    def keep_across_restarts(self, directory: Path | None = None) -> int:
        """Keep the log in ``directory`` (default: the events folder in TeachPad's data folder):
        :meth:`attach_store` with a store that says in the log when it cannot write."""

        def failed(why: str) -> None:
            self.add_event(
                "warning",
                lambda: self.tr("event log"),
                lambda: self.tr("The event log is not saved for the next start: {why}").format(why=why),
            )

        return self.attach_store(EventStore(directory, on_error=failed))

    def attach_store(self, store: EventStore) -> int:
        """Keep the log across restarts: show ``store``'s recent events (of earlier sessions,
        as they were written) before this session's, and save every event from now on (this
        session's so far too). Returns how many events were restored."""
        self._store = store
        session = list(self.model.events())
        restored = [
            LogEvent(e.when, e.level, e.source, e.text)
            for e in store.recent(limit=self.model.max_events)
            if not session or e.when <= session[0].when
        ]
        for event in session:
            store.append(_stored(event))
        self.model.prepend(restored)
        self.view.scrollToBottom()
        return len(restored)

    def bind(self, state: RobotState) -> None:
        """Log ``state``'s link changes, alarm edges and command results from now on."""
        state.connectionChanged.connect(self.on_connection)
        state.alarmsChanged.connect(self.on_alarms)
        state.lastResultChanged.connect(self.on_command_result)
        if state.alarms is not None:
            self._alarms = state.alarms  # edges from here on; the lamps show what is set now
        self._last_connection = (state.connection.state, state.connection.message)

    @Slot(int)
    def on_alarms(self, alarms: int) -> None:
        """Log each alarm bit that was raised or cleared since the last call."""
        alarms = int(alarms) & 0xFFFF
        previous = self._alarms or 0
        self._alarms = alarms
        changed = alarms ^ previous
        if not changed:
            return
        for bit in range(16):
            mask = 1 << bit
            if changed & mask:
                self._log_alarm(mask, bool(alarms & mask))

    def _log_alarm(self, mask: int, raised: bool) -> None:
        def text() -> str:
            words = self.tr("Alarm raised: {name}") if raised else self.tr("Alarm cleared: {name}")
            return words.format(name=self._alarm_name(mask))

        self.add_event("error" if raised else "info", lambda: self.tr("alarm"), text)

    def _alarm_name(self, mask: int) -> str:
        for bit in ALARM_BITS:
            if int(bit) == mask:
                return QCoreApplication.translate(TR_CONTEXT, ALARM_TEXT[bit])
        return self.tr("bit {n}").format(n=mask.bit_length() - 1)

    @Slot(object)
    def on_command_result(self, result: CommandResult) -> None:
        self.add_event(result_level(result), lambda: self.tr("command"), lambda: result_text(result))

    @Slot(WorkerError)
    def on_error(self, error: WorkerError) -> None:
        self.add_event("error", lambda: self.operation_text(error.operation), lambda: error_text(error))

    def operation_text(self, operation: str) -> str:
        """The operator's word for a link operation (:class:`~app.link.types.Operation`)."""
        return operation_text(operation)

    @Slot(ConnectionState)
    def on_connection(self, connection: ConnectionState) -> None:
        """Log link state changes (a repeat of the same state and message is not logged)."""
        key = (connection.state, connection.message)
        if key == self._last_connection:
            return
        self._last_connection = key
        _text, lamp = connection_display(connection)

        def text() -> str:
            parts = [
                connection_display(connection)[0],
                *(p for p in (connection.endpoint, connection_text(connection)) if p),
            ]
            return " — ".join(parts)

        if lamp == LEVEL_ERROR:
            level = "error"
        elif lamp == LEVEL_WARN and connection.state is not LinkState.CONNECTING:  # connecting is routine
            level = "warning"
        else:
            level = "info"
        self.add_event(level, lambda: self.tr("link"), text)

    @Slot()
    def clear(self) -> None:
        self.model.clear()

    # --- export -----------------------------------------------------------------------
    def export_to(self, path: str | os.PathLike[str], *, shown_only: bool = False) -> int:
        """Write the events as tab-separated text, atomically, UTF-8 with a BOM (Excel on a
        Chinese Windows reads it as UTF-8); every event, or with ``shown_only`` those the level
        filter shows ("Errors only": the errors). Returns the number of events written."""
        events = self.model.events()
        if shown_only:
            events = (
                self.model.event_at(self.proxy.mapToSource(self.proxy.index(row, 0)).row())
                for row in range(self.proxy.rowCount())
            )
        lines = [export_line(_stored(e)) for e in events]  # one line per event
        atomic_write_bytes(path, "".join(line + "\n" for line in lines).encode("utf-8-sig"))
        return len(lines)

    @Slot()
    def _export_dialog(self) -> None:
        export_with_dialog(
            self,
            self.tr("Export event log"),
            "events.txt",
            self.tr("Text files (*.txt *.log);;All files (*)"),
            lambda path: self.export_to(path, shown_only=True),
        )


def _stored(event: LogEvent) -> StoredEvent:
    return StoredEvent(event.when, event.level, event.source, event.text)

"""The alarm list: every alarm bit with its meaning, what to do, and when it was raised and cleared.

One row per documented bit of register 562 (and one per undocumented bit once seen); the times
come from an :class:`~app.alarm_history.AlarmHistory` fed by ``RobotState.alarmsChanged``. An
active alarm's row is red. The full history of raises and clears is in each row's tooltip.
"""

from __future__ import annotations

import datetime as dt

from PySide6.QtCore import QCoreApplication, QEvent, Slot
from PySide6.QtGui import QBrush, QColor
from PySide6.QtWidgets import (
    QAbstractItemView,
    QHeaderView,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from app.alarm_history import ALARM_MEANING, TR_ALARMS, UNKNOWN_MEANING, AlarmHistory
from app.link.state import RobotState
from app.protocol.enums import ALARM_BITS
from ui.palette import COLOR_ERROR, COLOR_ERROR_BG
from ui.panels.alarm_banner import alarm_advice, alarm_name

__all__ = ["AlarmListPanel"]

COL_NAME, COL_MEANING, COL_ADVICE, COL_RAISED, COL_CLEARED = range(5)
TIME_FORMAT = "%H:%M:%S"


def _meaning(bit: int) -> str:
    for alarm, text in ALARM_MEANING.items():
        if int(alarm) == bit:
            return QCoreApplication.translate(TR_ALARMS, text)
    return QCoreApplication.translate(TR_ALARMS, UNKNOWN_MEANING)


class AlarmListPanel(QWidget):
    """See the module docstring. ``history`` is the Qt-free model it shows."""

    def __init__(self, parent: QWidget | None = None, history: AlarmHistory | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("AlarmListPanel")
        self.history = history or AlarmHistory()
        self._bits: list[int] = [int(b) for b in ALARM_BITS]
        self.table = QTableWidget(0, 5, self)
        self.table.setObjectName("AlarmTable")
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.NoSelection)
        self.table.verticalHeader().setVisible(False)
        # the meaning and what to do read whole: rows as tall as their wrapped text (issue 21:
        # "Make the cell safe, release the emergency stop button, …" was elided at 1280×800)
        self.table.setWordWrap(True)
        self.table.verticalHeader().setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header = self.table.horizontalHeader()
        for column in (COL_NAME, COL_RAISED, COL_CLEARED):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.ResizeToContents)
        for column in (COL_MEANING, COL_ADVICE):
            header.setSectionResizeMode(column, QHeaderView.ResizeMode.Stretch)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.table)
        self.retranslate()

    def bind(self, state: RobotState) -> None:
        state.alarmsChanged.connect(self.on_alarms)
        if state.alarms is not None:
            self.on_alarms(state.alarms)

    @Slot(int)
    def on_alarms(self, alarms: int, when: dt.datetime | None = None) -> None:
        changed = self.history.update(alarms, when)
        for bit in changed:
            if bit not in self._bits:
                self._bits.append(bit)
        if changed:
            self._render()

    def row_of(self, bit: int) -> int:
        return self._bits.index(int(bit))

    def cell(self, bit: int, column: int) -> str:
        item = self.table.item(self.row_of(bit), column)
        return item.text() if item is not None else ""

    def retranslate(self) -> None:
        self.table.setHorizontalHeaderLabels(
            [
                self.tr("Alarm"),
                self.tr("Meaning"),
                self.tr("What to do"),
                self.tr("Raised"),
                self.tr("Cleared"),
            ]
        )
        self._render()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def _render(self) -> None:
        table = self.table
        table.setRowCount(len(self._bits))
        for row, bit in enumerate(self._bits):
            latest = self.history.latest(bit)
            active = latest is not None and latest.active
            raised = latest.raised.strftime(TIME_FORMAT) if latest is not None else "—"
            if latest is None:
                cleared = "—"
            elif latest.cleared is None:
                cleared = self.tr("active")
            else:
                cleared = latest.cleared.strftime(TIME_FORMAT)
            texts = (alarm_name(bit), _meaning(bit), alarm_advice(bit), raised, cleared)
            history = [o for o in self.history.occurrences() if o.bit == bit]
            tip = "\n".join(
                self.tr("raised {raised}, cleared {cleared}").format(
                    raised=o.raised.strftime(TIME_FORMAT),
                    cleared=o.cleared.strftime(TIME_FORMAT) if o.cleared else self.tr("active"),
                )
                for o in history[:20]
            )
            for column, text in enumerate(texts):
                item = table.item(row, column)
                if item is None:
                    item = QTableWidgetItem()
                    table.setItem(row, column, item)
                item.setText(text)
                item.setToolTip(tip or (text if column in (COL_MEANING, COL_ADVICE) else ""))
                item.setForeground(QBrush(QColor(COLOR_ERROR)) if active else QBrush())
                item.setBackground(QBrush(QColor(COLOR_ERROR_BG)) if active else QBrush())

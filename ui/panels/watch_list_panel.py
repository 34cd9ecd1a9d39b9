"""*View → Watch list*: any GVs or registers, their live values and freshness, a plot over time.

The panel shows and asks; it keeps no state of its own beyond the widgets: the entries and their
values are the model's (:class:`~ui.models.watch_list_model.WatchListModel`, fed from a
:class:`~app.watchlist.history.WatchHistory`), and every change is an intent signal the window's
:class:`~ui.window_watch_list.WatchListHost` carries out (``entriesEdited``: the new list, saved
with the project and sent to the link; ``writeRequested``: an engineer's write of one value;
``exportRequested``: the CSV). Adding or removing a watched value only reads, so every role may;
*Write value…* is enabled for a role that may write, on a writable link, one row selected
(:meth:`set_edit_permission` / :meth:`set_writable`, the tooltip says why not).

The plot (pyqtgraph, built when the panel is first shown, like the monitor's) draws the last
:data:`PLOT_WINDOW` seconds of every entry, up to :data:`MAX_CURVES`, redrawn by the panel's own
clock (:data:`REFRESH_MS`), never per poll.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QShowEvent
from PySide6.QtWidgets import (
    QAbstractItemView,
    QComboBox,
    QHBoxLayout,
    QHeaderView,
    QLabel,
    QLineEdit,
    QPushButton,
    QSpinBox,
    QSplitter,
    QTableView,
    QVBoxLayout,
    QWidget,
)

from app.errors import InvalidInput
from app.watchlist.entry import GV_MAX, MAX_ENTRIES, REGISTER_MAX, Source, ValueType, WatchEntry
from app.watchlist.history import WatchHistory
from ui.messages import error_text
from ui.models.watch_list_model import COL_NAME, COL_VALUE, COL_WHERE, WatchListModel
from ui.palette import COLOR_ERROR

if TYPE_CHECKING:  # imported when the plot is built
    import pyqtgraph as pg

__all__ = ["MAX_CURVES", "PLOT_WINDOW", "REFRESH_MS", "WatchListPanel"]

REFRESH_MS = 250  # the values, their ages and the plot: 4 times a second
PLOT_WINDOW = 60.0  # s shown in the plot
MAX_CURVES = 8
_COLORS = ("#1565c0", "#c62828", "#2e7d32", "#ef8f00", "#6a1b9a", "#00838f", "#5d4037", "#455a64")


class WatchListPanel(QWidget):
    """See the module docstring."""

    entriesEdited = Signal(tuple)
    writeRequested = Signal(object)
    exportRequested = Signal()

    def __init__(self, history: WatchHistory, fresh: Any, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("WatchListPanel")
        self.history = history
        self.model = WatchListModel(history, fresh, self)
        self._edit_reason: str | None = None  # why the role in force may not write (None: it may)
        self._writable = False
        self._plot: pg.PlotWidget | None = None
        self._curves: list[Any] = []

        self.source_box = QComboBox(self)
        self.source_box.setObjectName("WatchSource")
        self.source_box.addItem("GV", Source.GV)
        self.source_box.addItem("", Source.REGISTER)
        self.number_box = QSpinBox(self)
        self.number_box.setObjectName("WatchNumber")
        self.number_box.setRange(0, GV_MAX)
        self.type_box = QComboBox(self)
        self.type_box.setObjectName("WatchType")
        for kind in ValueType:
            self.type_box.addItem("", kind)
        self.name_edit = QLineEdit(self)
        self.name_edit.setObjectName("WatchName")
        self.name_edit.setMaxLength(60)
        self.add_button = QPushButton(self)
        self.add_button.setObjectName("WatchAdd")
        self.remove_button = QPushButton(self)
        self.write_button = QPushButton(self)
        self.write_button.setObjectName("WatchWrite")
        self.export_button = QPushButton(self)
        self.message = QLabel(self)
        self.message.setObjectName("WatchMessage")
        self.message.setStyleSheet(f"color: {COLOR_ERROR};")
        self.message.setWordWrap(True)
        self.message.hide()  # shown with a problem only

        self.view = QTableView(self)
        self.view.setObjectName("WatchTable")
        self.view.setModel(self.model)
        self.view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.view.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.view.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.view.verticalHeader().hide()
        header = self.view.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.ResizeToContents)
        header.setSectionResizeMode(COL_NAME, QHeaderView.ResizeMode.Stretch)
        header.setSectionResizeMode(COL_VALUE, QHeaderView.ResizeMode.Stretch)

        add_row = QHBoxLayout()
        for widget in (self.source_box, self.number_box, self.type_box):
            add_row.addWidget(widget)
        add_row.addWidget(self.name_edit, 1)
        add_row.addWidget(self.add_button)
        buttons = QHBoxLayout()
        for button in (self.remove_button, self.write_button, self.export_button):
            buttons.addWidget(button)
        buttons.addStretch(1)
        table_part = QWidget(self)
        table_layout = QVBoxLayout(table_part)
        table_layout.setContentsMargins(0, 0, 0, 0)
        table_layout.addLayout(add_row)
        table_layout.addWidget(self.message)
        table_layout.addWidget(self.view, 1)
        table_layout.addLayout(buttons)
        self.splitter = QSplitter(Qt.Orientation.Horizontal, self)
        self.splitter.addWidget(table_part)
        self.plot_host = QWidget(self)
        self.plot_host.setObjectName("WatchPlotHost")
        QVBoxLayout(self.plot_host).setContentsMargins(0, 0, 0, 0)
        self.splitter.addWidget(self.plot_host)
        self.splitter.setStretchFactor(0, 3)
        self.splitter.setStretchFactor(1, 2)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        layout.addWidget(self.splitter)

        self.source_box.currentIndexChanged.connect(self._on_source)
        self.add_button.clicked.connect(self.add_from_fields)
        self.name_edit.returnPressed.connect(self.add_from_fields)
        self.remove_button.clicked.connect(self.remove_selected)
        self.write_button.clicked.connect(self._on_write)
        self.export_button.clicked.connect(self.exportRequested)
        self.view.selectionModel().selectionChanged.connect(self._update_buttons)
        self.timer = QTimer(self)
        self.timer.setInterval(REFRESH_MS)
        self.timer.timeout.connect(self.refresh)
        self.retranslate()
        self._update_buttons()

    # --- what the host sets
    def set_entries(self, entries: tuple[WatchEntry, ...]) -> None:
        self.model.set_entries(entries)
        self._make_curves()
        self._update_buttons()

    def set_edit_permission(self, reason: str | None) -> None:
        """Write value… for the roles that may (``reason``: why not, translated)."""
        self._edit_reason = reason
        self._update_buttons()

    def set_writable(self, writable: bool) -> None:
        """The link takes writes (connected, not monitor-only)."""
        self._writable = writable
        self._update_buttons()

    def show_problem(self, text: str) -> None:
        self.message.setText(text)
        self.message.setVisible(bool(text))

    # --- the operator's edits
    def entry_from_fields(self) -> WatchEntry:
        source = self.source_box.currentData()
        return WatchEntry.make(
            source, self.number_box.value(), self.type_box.currentData(), self.name_edit.text()
        )

    @Slot()
    def add_from_fields(self) -> None:
        try:
            entry = self.entry_from_fields()
        except InvalidInput as exc:
            self.show_problem(error_text(exc))
            return
        entries = self.model.entries
        if any(e.same_place(entry) for e in entries):
            self.show_problem(self.tr("{what} is in the list already").format(what=entry.label))
            return
        if len(entries) >= MAX_ENTRIES:
            self.show_problem(self.tr("At most {n} values can be watched").format(n=MAX_ENTRIES))
            return
        self.show_problem("")
        self.name_edit.clear()
        self.entriesEdited.emit((*entries, entry))

    @Slot()
    def remove_selected(self) -> None:
        row = self.selected_row()
        if row is None:
            return
        entries = list(self.model.entries)
        del entries[row]
        self.entriesEdited.emit(tuple(entries))

    def selected_row(self) -> int | None:
        rows = self.view.selectionModel().selectedRows()
        return rows[0].row() if rows else None

    def select_row(self, row: int) -> None:
        self.view.selectRow(row)

    @Slot()
    def _on_write(self) -> None:
        row = self.selected_row()
        if row is not None:
            self.writeRequested.emit(self.model.entries[row])

    @Slot(int)
    def _on_source(self, _index: int) -> None:
        source = self.source_box.currentData()
        self.number_box.setRange(0, GV_MAX if source is Source.GV else REGISTER_MAX)
        self.type_box.setCurrentIndex(
            self.type_box.findData(ValueType.FLOAT32 if source is Source.GV else ValueType.INT16)
        )

    @Slot()
    def _update_buttons(self) -> None:
        selected = self.selected_row() is not None
        self.remove_button.setEnabled(selected)
        self.write_button.setEnabled(selected and self._writable and self._edit_reason is None)
        if self._edit_reason is not None:
            self.write_button.setToolTip(self._edit_reason)
        elif not self._writable:
            self.write_button.setToolTip(self.tr("Not connected, or monitor-only: nothing can be written"))
        else:
            self.write_button.setToolTip(
                self.tr("Write a value to the selected GV or register (confirmed, audited)")
            )
        self.export_button.setEnabled(bool(self.model.entries))

    # --- the clock: values, ages, plot
    @Slot()
    def refresh(self) -> None:
        self.model.refresh_values()
        self._draw()

    def _make_curves(self) -> None:
        plot = self._plot
        if plot is None:
            return
        import pyqtgraph as pg

        item = plot.getPlotItem()
        for curve in self._curves:
            item.removeItem(curve)
        legend = item.legend
        if legend is not None:
            legend.clear()
        self._curves = [
            plot.plot([], [], pen=pg.mkPen(_COLORS[i % len(_COLORS)], width=1), name=entry.title)
            for i, entry in enumerate(self.model.entries[:MAX_CURVES])
        ]

    def _draw(self) -> None:
        if self._plot is None or not self.isVisible():
            return
        import numpy as np

        now = time.time()
        for curve, entry in zip(self._curves, self.model.entries, strict=False):
            series = [(t - now, v) for t, v in self.history.series(entry) if t >= now - PLOT_WINDOW]
            if series:
                data = np.asarray(series, dtype=float)
                curve.setData(data[:, 0], data[:, 1])
            else:
                curve.setData([], [])

    def _build_plot(self) -> None:
        import pyqtgraph as pg

        from ui.panels.monitor_plots import style_plot

        plot = pg.PlotWidget(self.plot_host)
        plot.setObjectName("WatchPlot")
        style_plot(plot)
        plot.setXRange(-PLOT_WINDOW, 0, padding=0)
        plot.getPlotItem().addLegend(
            offset=(-4, 2),
            colCount=3,
            labelTextColor="#263238",
            brush=pg.mkBrush(255, 255, 255, 150),
            verSpacing=-6,
            horSpacing=8,
        )
        layout = self.plot_host.layout()
        if layout is not None:
            layout.addWidget(plot)
        self._plot = plot
        self._make_curves()
        self._retranslate_plot()

    # --- Qt
    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        if self._plot is None:
            self._build_plot()
            width = max(self.width(), 400)
            self.splitter.setSizes([width * 3 // 5, width * 2 // 5])
        self.timer.start()

    def hideEvent(self, event: Any) -> None:
        super().hideEvent(event)
        self.timer.stop()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    def retranslate(self) -> None:
        self.source_box.setItemText(1, self.tr("Register"))
        for i, text in enumerate((self.tr("float32"), self.tr("int16"), self.tr("bits"))):
            self.type_box.setItemText(i, text)
        self.source_box.setToolTip(
            self.tr("A GV (two registers, 2n and 2n+1) or a holding register by its address")
        )
        self.type_box.setToolTip(
            self.tr(
                "float32: two registers in the register profile's word order; "
                "int16: one register, signed; bits: one register as 16 bits"
            )
        )
        self.name_edit.setPlaceholderText(self.tr("Name (optional)"))
        self.add_button.setText(self.tr("Add"))
        self.remove_button.setText(self.tr("Remove"))
        self.write_button.setText(self.tr("Write value…"))
        self.export_button.setText(self.tr("Export CSV…"))
        self.model.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, COL_WHERE + 3)
        self._retranslate_plot()
        self._update_buttons()

    def _retranslate_plot(self) -> None:
        if self._plot is not None:
            self._plot.getPlotItem().setLabel("bottom", self.tr("seconds ago"))

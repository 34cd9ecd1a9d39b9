"""Modbus traffic inspector: every frame on the wire, decoded on demand.

``on_traffic(records)`` takes a batch of ``TrafficRecord``-like objects (``t``, ``direction``,
``frame``, ``transport``). While the panel is shown, batches are gathered and inserted with one
``beginInsertRows`` at most every ``FLUSH_INTERVAL_MS``, in a frame of the display clock (so the
table repaints together with the monitor and the pose strip, not on its own). The table and its
filter are :mod:`ui.models.traffic_model`: frames are decoded only when a row's meaning is shown,
filtered on or exported, so 100 Hz traffic does not stall the GUI. Hidden, rows go straight into
the model without formatting anything (no count text, no scrolling, no decoding).
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Sequence
from typing import Any

from PySide6.QtCore import (
    QEvent,
    QSignalBlocker,
    Qt,
    QTimer,
    Signal,
    Slot,
)
from PySide6.QtGui import QFontMetrics, QGuiApplication, QHideEvent, QShowEvent
from PySide6.QtWidgets import (
    QAbstractItemView,
    QCheckBox,
    QHBoxLayout,
    QHeaderView,
    QLineEdit,
    QPushButton,
    QTableView,
    QVBoxLayout,
    QWidget,
)

from app.points.atomic import atomic_write_bytes
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from ui.display_clock import DisplayClock
from ui.models.traffic_model import (
    COL_BYTES,
    COL_DIRECTION,
    COL_TIME,
    MAX_ROWS_DEFAULT,
    TrafficFilter,
    TrafficModel,
)
from ui.palette import COLOR_NEUTRAL
from ui.widgets.live_label import LiveLabel
from ui.widgets_common import (
    export_with_dialog,
    monospace_font,
)

FILTER_DEBOUNCE_MS = 200  # typing in the filter box re-filters once the user pauses
# At most 2 table updates a second while the panel is visible, each in a display-clock frame:
# every update scrolls a screenful of new rows whose meaning is decoded when painted (a pose
# answer ~1.5 ms) and repaints the whole table, so the cost follows this rate (20 Hz cost 1.5x
# 10 Hz, 10 Hz 1.6x 5 Hz: python -m benchmarks.traffic; at 5 Hz the table's paint was 12 % of the
# GUI thread while streaming); nobody reads 400 frames a second.
FLUSH_INTERVAL_MS = 500
_BUSY_CURSOR_ROWS = 2000


class TrafficPanel(QWidget):
    """Table of Modbus frames with filter, hide-polls, pause capture, clear and export."""

    captureEnabledChanged = Signal(bool)

    def __init__(
        self,
        parent: QWidget | None = None,
        *,
        max_rows: int = MAX_ROWS_DEFAULT,
        clock: DisplayClock | None = None,
    ) -> None:
        super().__init__(parent)
        self._clock = clock if clock is not None else DisplayClock.shared()
        self.setObjectName("TrafficPanel")
        self._capture = True
        self.model = TrafficModel(self, max_rows=max_rows)
        self.proxy = TrafficFilter(self)
        self.proxy.setSourceModel(self.model)

        self.filter_edit = QLineEdit(self)
        self.filter_edit.setClearButtonEnabled(True)
        self.filter_edit.textChanged.connect(self._on_filter_typed)
        self.filter_edit.returnPressed.connect(self._apply_filter_now)
        self._pending: list[Any] = []  # records gathered while visible, see on_traffic
        self._flush_timer = QTimer(self)
        self._flush_timer.setSingleShot(True)
        self._flush_timer.setInterval(FLUSH_INTERVAL_MS)
        self._flush_timer.timeout.connect(self._flush_in_next_frame)
        self._filter_timer = QTimer(self)
        self._filter_timer.setSingleShot(True)
        self._filter_timer.setInterval(FILTER_DEBOUNCE_MS)
        self._filter_timer.timeout.connect(self._apply_filter_now)

        self.hide_polls_check = QCheckBox(self)
        self.hide_polls_check.toggled.connect(self.set_hide_polls)
        self.pause_button = QPushButton(self)
        self.pause_button.setCheckable(True)
        self.pause_button.toggled.connect(lambda paused: self.set_capture_enabled(not paused))
        self.clear_button = QPushButton(self)
        self.clear_button.clicked.connect(self.clear)
        self.export_button = QPushButton(self)
        self.export_button.clicked.connect(self._export_dialog)
        # its text changes with every flush: a LiveLabel repaints itself only (no re-layout of the
        # dock and the window above it)
        self.count_label = LiveLabel(parent=self, opaque=True)
        self.count_label.setStyleSheet(f"color: {COLOR_NEUTRAL};")

        self.view = QTableView(self)
        self.view.setModel(self.proxy)
        self.view.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.view.setWordWrap(False)
        self.view.setTextElideMode(Qt.TextElideMode.ElideRight)
        self.view.setAlternatingRowColors(True)
        self.view.setHorizontalScrollMode(QAbstractItemView.ScrollMode.ScrollPerPixel)
        # the scroll bars move with every flush: opaque, they repaint alone, not the dock (and its
        # title bar's icons) and the window behind them
        for scroll_bar in (self.view.verticalScrollBar(), self.view.horizontalScrollBar()):
            scroll_bar.setAutoFillBackground(True)
            container = scroll_bar.parentWidget()
            if container is not None:
                container.setAutoFillBackground(True)
        vheader = self.view.verticalHeader()
        vheader.setVisible(False)
        vheader.setSectionResizeMode(QHeaderView.ResizeMode.Fixed)
        vheader.setDefaultSectionSize(self.fontMetrics().height() + 6)
        header = self.view.horizontalHeader()
        header.setSectionResizeMode(QHeaderView.ResizeMode.Interactive)
        header.setStretchLastSection(True)
        mono = monospace_font(9.5)
        digit = QFontMetrics(mono).horizontalAdvance("0")
        self.view.setColumnWidth(COL_TIME, digit * 14)
        self.view.setColumnWidth(COL_DIRECTION, self.fontMetrics().horizontalAdvance("← Rx") + 24)
        self.view.setColumnWidth(COL_BYTES, digit * 3 * 24)  # 24 bytes before eliding

        bar = QHBoxLayout()
        bar.setContentsMargins(0, 0, 0, 0)
        bar.addWidget(self.filter_edit, 1)
        bar.addWidget(self.hide_polls_check)
        bar.addWidget(self.pause_button)
        bar.addWidget(self.clear_button)
        bar.addWidget(self.export_button)
        bar.addWidget(self.count_label)  # in the tool row: the bottom dock is short at 800 px
        layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 6, 6, 6)
        layout.addLayout(bar)
        layout.addWidget(self.view, 1)
        self.retranslate()

    def retranslate(self) -> None:
        """(Re)set every user-visible text: at construction and on a language change."""
        self.filter_edit.setPlaceholderText(self.tr("Filter: bytes or meaning"))
        self.hide_polls_check.setText(self.tr("Hide polls"))
        self.hide_polls_check.setToolTip(
            self.tr("Hide the periodic reads of 412.. (pose) and 560.. (status)")
        )
        self.pause_button.setText(self.tr("Pause capture"))
        self.pause_button.setToolTip(self.tr("Stop recording frames (the worker stops building them)"))
        self.clear_button.setText(self.tr("Clear"))
        self.export_button.setText(self.tr("Export…"))
        self.model.retranslate()
        self.count_label.fit_texts([self.tr("{n} frames").format(n=max(self.model.max_rows, 99_999))])
        self._update_count()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    # --- slots ------------------------------------------------------------------------
    @Slot(object)
    def on_traffic(self, records: Sequence[Any]) -> None:
        """Append a batch of TrafficRecords (ignored while capture is paused).

        While the panel is visible, batches are gathered and inserted at most every
        ``FLUSH_INTERVAL_MS`` (the table repaints at that rate, not at the poll rate); while
        hidden they go straight into the model, which costs no painting.
        """
        if not self._capture or not records:
            return
        if not self.isVisible():
            self.model.append_records(records)  # no painting, no formatting: showEvent catches up
            return
        self._pending.extend(records)
        excess = len(self._pending) - self.model.max_rows
        if excess > 0:  # the table keeps no more than this of them anyway (a long-stalled clock)
            del self._pending[:excess]
        if not self._flush_timer.isActive() and not self._clock.is_requested(self.flush):
            self._flush_timer.start()

    @Slot()
    def _flush_in_next_frame(self) -> None:
        self._clock.request(self.flush)

    @Slot()
    def flush(self) -> None:
        """Insert the gathered records now."""
        self._flush_timer.stop()
        self._clock.cancel(self.flush)
        if self._pending:
            records, self._pending = self._pending, []
            self._insert(records)

    def _insert(self, records: list[Any]) -> None:
        bar = self.view.verticalScrollBar()
        follow = bar.value() >= bar.maximum() - 2
        self.model.append_records(records)
        if follow and not self.view.selectionModel().hasSelection():
            self.view.scrollToBottom()
        self._update_count()

    @Slot(bool)
    def set_capture_enabled(self, enabled: bool) -> None:
        enabled = bool(enabled)
        if enabled == self._capture:
            return
        self._capture = enabled
        if not enabled:
            self.flush()  # what was captured before the pause still shows
        with QSignalBlocker(self.pause_button):
            self.pause_button.setChecked(not enabled)
        self._update_count()
        self.captureEnabledChanged.emit(enabled)

    def capture_enabled(self) -> bool:
        return self._capture

    @Slot(bool)
    def set_hide_polls(self, hide: bool) -> None:
        with QSignalBlocker(self.hide_polls_check):
            self.hide_polls_check.setChecked(bool(hide))
        self.proxy.set_hide_polls(hide)
        self._update_count()

    def set_filter_text(self, text: str) -> None:
        """Filter now (the text box debounces typing)."""
        with QSignalBlocker(self.filter_edit):
            self.filter_edit.setText(text)
        self._filter_timer.stop()
        self._filter(text)

    @Slot()
    def clear(self) -> None:
        self._flush_timer.stop()
        self._pending.clear()
        self.model.clear()
        self._update_count()

    def set_word_order(self, order: WordOrder) -> None:
        """Word order of float32 values, as configured for the connection."""
        self.model.set_word_order(order)

    def set_clock_layout(self, layout: DateTimeLayout) -> None:
        self.model.set_clock_layout(layout)

    # --- export -----------------------------------------------------------------------
    def export_to(self, path: str | os.PathLike[str], *, visible_only: bool = True) -> int:
        """Write the rows (those passing the filter, or all) atomically; returns the row count.

        ``*.csv`` gives CSV with a header; anything else tab-separated text.
        """
        self.flush()
        model = self.model
        if visible_only:
            rows = [
                model.row_at(self.proxy.mapToSource(self.proxy.index(i, 0)).row())
                for i in range(self.proxy.rowCount())
            ]
        else:
            rows = list(model.rows())
        fields = [
            (r.time_text(with_date=True), r.direction.capitalize(), r.hex, model.summary(r)) for r in rows
        ]
        if os.fspath(path).lower().endswith(".csv"):
            buffer = io.StringIO()
            writer = csv.writer(buffer, lineterminator="\n")
            writer.writerow(["time", "direction", "bytes", "meaning"])
            writer.writerows(fields)
            text = buffer.getvalue()
        else:
            text = "".join("\t".join(f) + "\n" for f in fields)
        atomic_write_bytes(path, text.encode("utf-8-sig"))  # with a BOM: Excel reads it as UTF-8
        return len(rows)

    @Slot()
    def _export_dialog(self) -> None:
        export_with_dialog(
            self,
            self.tr("Export traffic"),
            "traffic.csv",
            self.tr("CSV files (*.csv);;Text files (*.txt);;All files (*)"),
            self.export_to,
        )

    # --- internals --------------------------------------------------------------------
    @Slot(str)
    def _on_filter_typed(self, _text: str) -> None:
        self._filter_timer.start()

    @Slot()
    def _apply_filter_now(self) -> None:
        self._filter_timer.stop()
        self._filter(self.filter_edit.text())

    def _filter(self, text: str) -> None:
        # A text filter decodes every row it has not decoded yet (once): say so with the cursor.
        busy = bool(text.strip()) and self.model.rowCount() > _BUSY_CURSOR_ROWS
        if busy:
            QGuiApplication.setOverrideCursor(Qt.CursorShape.WaitCursor)
        try:
            self.proxy.set_text(text)
        finally:
            if busy:
                QGuiApplication.restoreOverrideCursor()
        self._update_count()

    def _update_count(self) -> None:
        total, shown = self.model.rowCount(), self.proxy.rowCount()
        if shown == total:
            text = self.tr("{n} frames").format(n=total)
        else:
            text = self.tr("{shown} of {n} frames shown").format(shown=shown, n=total)
        if not self._capture:
            text += " — " + self.tr("capture paused")
        self.count_label.setText(text)

    def showEvent(self, event: QShowEvent) -> None:
        super().showEvent(event)
        if not self.view.selectionModel().hasSelection():
            self.view.scrollToBottom()  # rows that came while hidden: follow the newest
        self._update_count()

    def hideEvent(self, event: QHideEvent) -> None:
        self.flush()
        if self._filter_timer.isActive():  # don't leave a pending filter (or a live timer) behind
            self._apply_filter_now()
        super().hideEvent(event)

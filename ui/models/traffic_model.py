"""The traffic inspector's table: a bounded ring of frames (:class:`TrafficModel`) and the
filter over it (:class:`TrafficFilter`).

Rows are added in batches; at insertion only a few bytes are peeked at (pairing a response
with its request, spotting polls and run commands) and the frame is stored compactly
(:class:`ui.models.traffic_store.TrafficStore`: raw bytes and a few typed fields, no object
per row). A :class:`TrafficRow` is a view made when a row is shown, filtered on or exported;
the model keeps at most ``VIEW_CACHE_SIZE`` of them (:mod:`ui.models.traffic_row`). The full
decoding (:func:`app.protocol.frames.decode_frame`) runs the first time a row's meaning is
needed and the text is kept with the stored row, so 100 Hz traffic does not stall the GUI.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from typing import Any

from PySide6.QtCore import (
    QAbstractTableModel,
    QCoreApplication,
    QModelIndex,
    QPersistentModelIndex,
    QSortFilterProxyModel,
    Qt,
)
from PySide6.QtGui import QBrush, QColor, QFont

from app.protocol import registers as regs
from app.protocol.codec import WordOrder
from app.protocol.datetime_regs import DateTimeLayout
from app.protocol.enums import CommandKind, RunCommand
from app.protocol.framing import EXCEPTION_FLAG, MBAP_SIZE, FunctionCode
from ui.models.traffic_row import TrafficRow, is_poll_read, wrap_hex
from ui.models.traffic_store import BAD, MAX_FRAME_BYTES, NO_COMMAND, NO_ROW, POLL, RTU, RX, TrafficStore
from ui.palette import COLOR_ERROR, COLOR_INFO, COLOR_INK_SOFT
from ui.traffic_words import MeaningWords
from ui.widgets_common import monospace_font

__all__ = [
    "COL_BYTES",
    "COL_DIRECTION",
    "COL_MEANING",
    "COL_TIME",
    "MAX_ROWS_DEFAULT",
    "VIEW_CACHE_SIZE",
    "TrafficFilter",
    "TrafficModel",
]

# 20,000 rows: the last minute or so of 100 Hz polling (2 reads a poll, each a request and an
# answer). The store takes 165 bytes a row, 3.3 MB, allocated by the first row and never more
# (ui/models/traffic_store.py; before: ~390 bytes a row in Python objects, 7.7 MB).
MAX_ROWS_DEFAULT = 20_000
VIEW_CACHE_SIZE = 256  # row views (with their formatted texts) kept: a few screenfuls
_MAX_PENDING = 256  # unanswered TCP requests remembered for pairing
_SUMMARY_CACHE_SIZE = 2048  # distinct response contents remembered (emptied when full)

COL_TIME, COL_DIRECTION, COL_BYTES, COL_MEANING = range(4)
_COLUMN_COUNT = 4
_DISPLAY = Qt.ItemDataRole.DisplayRole.value
_FOREGROUND = Qt.ItemDataRole.ForegroundRole.value
_FONT = Qt.ItemDataRole.FontRole.value
_TOOLTIP = Qt.ItemDataRole.ToolTipRole.value


class TrafficModel(QAbstractTableModel):
    """Bounded table of frames, oldest dropped first. Columns: time, direction, bytes, meaning."""

    def __init__(
        self,
        parent: Any = None,
        *,
        max_rows: int = MAX_ROWS_DEFAULT,
        word_order: WordOrder = WordOrder.LOW_FIRST,
        clock_layout: DateTimeLayout = DateTimeLayout.SPLIT_WORDS,
    ) -> None:
        super().__init__(parent)
        if max_rows < 1:
            raise ValueError("max_rows must be >= 1")
        self._store = TrafficStore(max_rows)
        self._views: dict[int, TrafficRow] = {}  # absolute row index -> view, oldest first
        self._max_rows = max_rows
        # Dropping a chunk at a time keeps removals (and the proxy's remapping) rare.
        self._drop_chunk = max(1, max_rows // 20)
        self.word_order = word_order
        self.clock_layout = clock_layout
        self._summary_cache: dict[tuple[Any, ...], tuple[str, bool]] = {}
        self._pending: OrderedDict[int, int] = OrderedDict()  # TCP: transaction id -> request row
        self._last_request = NO_ROW  # RTU: half duplex, answers follow requests
        self._last_command: RunCommand | None = None
        self._mono = monospace_font(9.5)
        self._tx_brush = QBrush(QColor(COLOR_INFO))
        self._rx_brush = QBrush(QColor(COLOR_INK_SOFT))
        self._bad_brush = QBrush(QColor(COLOR_ERROR))
        self._headers: tuple[str, ...] = ()
        self._tx_text = self._rx_text = ""
        self._meaning_words = MeaningWords()  # the meaning column in the current language
        self._set_texts()

    def _set_texts(self) -> None:
        self._headers = (
            QCoreApplication.translate("TrafficModel", "Time"),
            QCoreApplication.translate("TrafficModel", "Dir"),
            QCoreApplication.translate("TrafficModel", "Bytes"),
            QCoreApplication.translate("TrafficModel", "Meaning"),
        )
        self._tx_text = QCoreApplication.translate("TrafficModel", "→ Tx")
        self._rx_text = QCoreApplication.translate("TrafficModel", "← Rx")
        self._meaning_words.retranslate()

    def retranslate(self) -> None:
        """Headers, direction texts and the shown meanings in the current language (the stored
        meaning, the filter and the export keep the English decoding)."""
        self._set_texts()
        self.headerDataChanged.emit(Qt.Orientation.Horizontal, 0, _COLUMN_COUNT - 1)
        if len(self._store):
            self.dataChanged.emit(
                self.index(0, COL_DIRECTION),
                self.index(len(self._store) - 1, COL_MEANING),
                [Qt.ItemDataRole.DisplayRole],
            )

    # --- data in ----------------------------------------------------------------------
    @property
    def max_rows(self) -> int:
        return self._max_rows

    def append_records(self, records: Sequence[Any]) -> int:
        """Add a batch (one insert notification); returns how many rows were added."""
        if not records:
            return 0
        records = self._newest_that_fit(records)
        store = self._store
        need = store.room_for([len(r.frame) for r in records])
        if need > 0:
            drop = min(len(store), max(need, self._drop_chunk))
            if (
                drop < len(store)
                and store.request(drop) != NO_ROW
                and store.request(drop) < store.base + drop
            ):
                drop += 1  # an answer is not kept without the request it answers
            self.beginRemoveRows(QModelIndex(), 0, drop - 1)
            store.drop_oldest(drop)
            self.endRemoveRows()
        first = len(store)
        self.beginInsertRows(QModelIndex(), first, first + len(records) - 1)
        for record in records:
            self._add(record)
        self.endInsertRows()
        return len(records)

    def _newest_that_fit(self, records: Sequence[Any]) -> Sequence[Any]:
        """The newest records the table can hold at once (rows and frame bytes)."""
        if len(records) > self._max_rows:
            records = records[len(records) - self._max_rows :]
        budget = self._store.frame_capacity - MAX_FRAME_BYTES  # room for one wasted ring end
        keep = 0
        for record in reversed(records):
            budget -= min(len(record.frame), MAX_FRAME_BYTES)
            if budget < 0:
                break
            keep += 1
        return records[len(records) - keep :] if keep < len(records) else records

    def _add(self, record: Any) -> None:
        frame = bytes(record.frame)
        rtu = record.transport == "rtu"
        offset = 1 if rtu else MBAP_SIZE  # where the PDU starts
        fc = frame[offset] if len(frame) > offset else None
        flags = RTU if rtu else 0
        if record.direction != "rx":
            self._add_request(float(record.t), frame, rtu, offset, fc, flags)
        else:
            self._add_response(float(record.t), frame, rtu, offset, fc, flags)

    def _add_request(
        self, t: float, frame: bytes, rtu: bool, offset: int, fc: int | None, flags: int
    ) -> None:
        """A request: a poll marked, a run command noted, kept for pairing with its answer."""
        flags |= self._peek_request(frame, offset, fc)
        index = self._store.append(t, frame, flags, NO_ROW, self._command_value())
        if not rtu and len(frame) >= 2:
            tid = int.from_bytes(frame[:2], "big")
            self._pending.pop(tid, None)
            self._pending[tid] = index
            while len(self._pending) > _MAX_PENDING:
                self._pending.popitem(last=False)
        else:
            self._last_request = index

    def _peek_request(self, frame: bytes, offset: int, fc: int | None) -> int:
        """POLL for a poll's read (else 0); a write of the run command register is noted."""
        if fc == FunctionCode.READ_HOLDING_REGISTERS and len(frame) >= offset + 5:
            address = int.from_bytes(frame[offset + 1 : offset + 3], "big")
            count = int.from_bytes(frame[offset + 3 : offset + 5], "big")
            if is_poll_read(address, count):
                return POLL
        elif fc == FunctionCode.WRITE_SINGLE_REGISTER and len(frame) >= offset + 5:
            address = int.from_bytes(frame[offset + 1 : offset + 3], "big")
            if address == regs.REG_RUN_COMMAND:
                self._note_command(int.from_bytes(frame[offset + 3 : offset + 5], "big"))
        return 0

    def _add_response(
        self, t: float, frame: bytes, rtu: bool, offset: int, fc: int | None, flags: int
    ) -> None:
        """A response: paired with its request (same function), a poll's answer marked."""
        store = self._store
        flags |= RX
        bad = fc is None or bool(fc & EXCEPTION_FLAG)
        if bad:
            flags |= BAD
        request = self._request_answered(frame, rtu)
        paired = NO_ROW
        if request >= store.base and fc is not None:
            local = request - store.base
            if (fc & ~EXCEPTION_FLAG) == store.byte(local, offset):
                paired = request
                if store.flags(local) & POLL and not bad:
                    flags |= POLL
        store.append(t, frame, flags, paired, self._command_value())

    def _request_answered(self, frame: bytes, rtu: bool) -> int:
        """The row of the request this response answers (NO_ROW: none known). TCP: by its
        transaction id; RTU (half duplex): the last request."""
        if rtu:
            request, self._last_request = self._last_request, NO_ROW
            return request
        if len(frame) >= 2:
            return self._pending.pop(int.from_bytes(frame[:2], "big"), NO_ROW)
        return NO_ROW

    def _command_value(self) -> int:
        return NO_COMMAND if self._last_command is None else int(self._last_command)

    def _note_command(self, value: int) -> None:
        try:
            command = RunCommand(value)
        except ValueError:
            return
        if CommandKind.of(command) is not None:
            self._last_command = command

    def clear(self) -> None:
        self.beginResetModel()
        self._store.clear()
        self._views.clear()
        self._pending.clear()
        self._last_request = NO_ROW
        self.endResetModel()

    def row_at(self, row: int) -> TrafficRow:
        """A view of row ``row`` (0 = oldest); raises IndexError outside the table."""
        if not 0 <= row < len(self._store):
            raise IndexError(f"no traffic row {row}")
        view = self._views.get(self._store.base + row)
        return view if view is not None else self._make_view(row)

    def _make_view(self, row: int) -> TrafficRow:
        store = self._store
        flags = store.flags(row)
        index = store.base + row
        view = TrafficRow(
            store.time(row),
            "rx" if flags & RX else "tx",
            store.frame(row),
            "rtu" if flags & RTU else "tcp",
            index,
        )
        view.poll = bool(flags & POLL)
        view.bad = bool(flags & BAD)
        command = store.command(row)
        view.last_command = None if command == NO_COMMAND else RunCommand(command)
        view._summary = store.meaning(row)
        views = self._views
        if len(views) >= VIEW_CACHE_SIZE:
            del views[next(iter(views))]
        views[index] = view
        request = store.request(row)
        if request != NO_ROW:
            view.request = self.row_at(request - store.base)
        return view

    def rows(self) -> Iterable[TrafficRow]:
        return (self.row_at(i) for i in range(len(self._store)))

    def is_poll(self, row: int) -> bool:
        """Row ``row`` is a poll or its answer (without making a view)."""
        return bool(self._store.flags(row) & POLL)

    def stored_bytes(self) -> int:
        """Bytes allocated for the rows (see :meth:`TrafficStore.nbytes`): fixed once a row came."""
        return self._store.nbytes()

    def view_count(self) -> int:
        return len(self._views)

    def summary(self, row: TrafficRow) -> str:
        """The decoded meaning (cached in the row). Identical answers (a robot standing still
        answers every poll with the same bytes) are decoded once, via a content-keyed cache."""
        if row._summary is not None:
            return row._summary
        request = row.request
        if row.direction != "rx" or request is None:
            return self._keep(row, row.summary(self.word_order, self.clock_layout))
        skip = 2 if row.transport == "tcp" else 0  # the transaction id does not change the meaning
        key = (row.transport, row.frame[skip:], request.frame[skip:], row.last_command)
        cached = self._summary_cache.get(key)
        if cached is None:
            cached = (row.summary(self.word_order, self.clock_layout), row.bad)
            if len(self._summary_cache) >= _SUMMARY_CACHE_SIZE:
                self._summary_cache.clear()
            self._summary_cache[key] = cached
        row._summary, row.bad = cached[0], row.bad or cached[1]
        return self._keep(row, row._summary)

    def _keep(self, row: TrafficRow, text: str) -> str:
        """The meaning (and a malformed frame's red) goes with the stored row, for later views."""
        local = row.index - self._store.base
        if 0 <= local < len(self._store):
            self._store.set_meaning(local, text)
            if row.bad:
                self._store.set_flag(local, BAD)
        return text

    def set_word_order(self, order: WordOrder) -> None:
        """Word order of float32 values (applies to rows decoded from now on)."""
        self.word_order = order
        self._summary_cache.clear()

    def set_clock_layout(self, layout: DateTimeLayout) -> None:
        """Layout of the clock registers (applies to rows decoded from now on)."""
        self.clock_layout = layout
        self._summary_cache.clear()

    def direction_text(self, row: TrafficRow) -> str:
        return self._tx_text if row.direction == "tx" else self._rx_text

    # --- QAbstractTableModel ----------------------------------------------------------
    def rowCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else len(self._store)

    def columnCount(self, parent: QModelIndex | QPersistentModelIndex = QModelIndex()) -> int:  # noqa: B008
        return 0 if parent.isValid() else _COLUMN_COUNT

    def data(self, index: QModelIndex | QPersistentModelIndex, role: int = _DISPLAY) -> Any:
        # Called ~500 times per repaint: cheap role test first, plain int compares, cached texts.
        by_role = _DATA_BY_ROLE.get(role)
        if by_role is None or not index.isValid():
            return None
        r, column = index.row(), index.column()
        store = self._store
        if not (0 <= r < len(store) and 0 <= column < _COLUMN_COUNT):
            return None
        row = self._views.get(store.base + r) or self._make_view(r)
        return by_role(self, row, column)

    def _display(self, row: TrafficRow, column: int) -> str:
        if column == COL_MEANING:
            return self._meaning_words(row._summary if row._summary is not None else self.summary(row))
        if column == COL_BYTES:
            return row.hex_display
        if column == COL_TIME:
            return row.time_display
        return self._tx_text if row.direction == "tx" else self._rx_text

    def _foreground(self, row: TrafficRow, column: int) -> QBrush | None:
        if row.bad:  # exception response, or found malformed when decoded
            return self._bad_brush
        if column == COL_DIRECTION:
            return self._tx_brush if row.direction == "tx" else self._rx_brush
        return None

    def _font(self, _row: TrafficRow, column: int) -> QFont | None:
        return self._mono if column in (COL_TIME, COL_BYTES) else None

    def _tooltip(self, row: TrafficRow, column: int) -> str | None:
        """Rare, may decode again."""
        if column == COL_BYTES:
            size = QCoreApplication.translate("TrafficModel", "{n} bytes").format(n=len(row.frame))
            return f"{size}\n{wrap_hex(row.hex)}"
        if column == COL_MEANING:
            decoded = row.decode(self.word_order, self.clock_layout)
            lines = [item.label for item in decoded.items[:40]]
            if len(decoded.items) > 40:
                lines.append("…")
            lines.extend(decoded.errors)
            return "\n".join(lines) or None
        return None

    def headerData(
        self, section: int, orientation: Qt.Orientation, role: int = Qt.ItemDataRole.DisplayRole
    ) -> Any:
        horizontal = orientation == Qt.Orientation.Horizontal
        if horizontal and role == Qt.ItemDataRole.DisplayRole and 0 <= section < _COLUMN_COUNT:
            return self._headers[section]
        return None


# what data() answers for each role it answers (the others: None at once)
_DATA_BY_ROLE: dict[int, Callable[[TrafficModel, TrafficRow, int], Any]] = {
    _DISPLAY: TrafficModel._display,
    _FOREGROUND: TrafficModel._foreground,
    _FONT: TrafficModel._font,
    _TOOLTIP: TrafficModel._tooltip,
}


class TrafficFilter(QSortFilterProxyModel):
    """Text filter (bytes or meaning, case-insensitive) and "hide polls"."""

    def __init__(self, parent: Any = None) -> None:
        super().__init__(parent)
        self._text = ""
        self._hide_polls = False

    def traffic_model(self) -> TrafficModel:
        model = self.sourceModel()
        assert isinstance(model, TrafficModel)
        return model

    def text(self) -> str:
        return self._text

    def hide_polls(self) -> bool:
        return self._hide_polls

    def set_text(self, text: str) -> None:
        text = text.strip().lower()
        if text != self._text:
            self.beginFilterChange()
            self._text = text
            self.endFilterChange(QSortFilterProxyModel.Direction.Rows)

    def set_hide_polls(self, hide: bool) -> None:
        hide = bool(hide)
        if hide != self._hide_polls:
            self.beginFilterChange()
            self._hide_polls = hide
            self.endFilterChange(QSortFilterProxyModel.Direction.Rows)

    def accepts(self, model: TrafficModel, row: TrafficRow) -> bool:
        if self._hide_polls and row.poll:
            return False
        if not self._text:
            return True
        text = self._text
        return (
            text in row.hex.lower()
            or text in model.summary(row).lower()
            or text in model.direction_text(row).lower()
        )

    def filterAcceptsRow(self, source_row: int, source_parent: QModelIndex | QPersistentModelIndex) -> bool:
        model = self.traffic_model()
        if self._hide_polls and model.is_poll(source_row):
            return False
        return not self._text or self.accepts(model, model.row_at(source_row))

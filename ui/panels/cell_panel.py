"""The Cell tab: a tile per controller of a cell file, each watched by its own monitor-only poller.

Every controller has a :class:`~app.gateway.poller.ControllerPoller` (its own thread, client,
timeouts and backoff: a dead one costs the others nothing). The pollers tell :class:`CellFeed`
from their threads; its signals reach the tiles queued, on the GUI thread, which never waits on
the network. A tile shows the name, the link state, mode, program state, alarms (most severe
first, then oldest), pose and freshness (age of the last answer, RTT, failed polls in the last
minute); one that has not answered for :attr:`CellPanel.stale_after` s, or whose last poll
failed, is greyed and says "not answering N s".

The tiles are full (the address, two buttons) when all of them fit the tab, else compact
(:meth:`CellPanel.arrange`: a smaller font, the link state beside the name, the actions in a menu,
shorter words): 16 fit beside the pendant's controls at 1280×800, in both languages.

*Plant link…* publishes the cell through the gateway's edge node
(:class:`~app.cell.publish.CellPublisher`, set by the host): the pollers feed it from their threads.

Monitor many, command one: the tiles never write (the pollers' clients are monitor-only). *Take
control* asks the window (:class:`ui.window_cell.CellHost`) to make that robot the pendant's.
*History* shows the controller's history (:class:`~app.cell.history.ControllerHistory`) in the
tab, with *Export CSV…*.
"""

from __future__ import annotations

import collections
import time

from PySide6.QtCore import QCoreApplication, QEvent, QObject, Qt, QTimer, Signal, Slot
from PySide6.QtGui import QCloseEvent, QFont
from PySide6.QtWidgets import (
    QApplication,
    QFrame,
    QGridLayout,
    QHBoxLayout,
    QLabel,
    QMenu,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QStackedWidget,
    QTableWidget,
    QTableWidgetItem,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from app.cell.cell_file import Cell, CellController
from app.cell.history import ControllerHistory, alarm_order
from app.cell.publish import CellPublisher
from app.gateway.metrics import Reading
from app.gateway.poller import ControllerPoller, DeviceListener, GatewayTiming
from app.protocol.enums import (
    ALARM_TEXT,
    CONTROLLER_MODE_TEXT,
    PROGRAM_STATE_TEXT,
    Alarm,
    ControllerMode,
    ProgramState,
)
from ui.joins import join_names

__all__ = ["CELL_POLL_HZ", "CellFeed", "CellPanel", "CellTile"]

CELL_POLL_HZ = 5.0  # polls per controller per s in the GUI (the gateway's own rate is app.timing's)
STALE_AFTER = 1.0  # s without an answer: the tile greys
ERROR_WINDOW = 60.0  # s: "errors in the last minute"
SILENT_STYLE = "QFrame#CellTile { background-color: #d4d4d4; }"
SILENT_TEXT_STYLE = "color: #6a0000; font-weight: bold;"
ALARM_STYLE = "color: #b00000;"
TILE_WIDTH = 200  # px: as many columns as fit the tab
COMPACT_WIDTH = 140  # px: a compact tile's least width
COMPACT_FONT_SCALE = 0.9  # the compact tile's font, of the panel's
MENU_BUTTON_STYLE = "QToolButton::menu-indicator { image: none; width: 0px; }"
MODES = frozenset(int(m) for m in ControllerMode)
PROGRAM_STATES = frozenset(int(p) for p in ProgramState)


def _protocol(text: str) -> str:
    return QCoreApplication.translate("Protocol", text)


def _where(controller: CellController) -> str:
    if controller.rtu is not None:
        return f"{controller.rtu} @ {controller.baud}"
    return f"{controller.host}:{controller.port}"


class CellFeed(QObject):
    """The pollers' listener: re-emits what they tell as signals (queued to the GUI thread)."""

    answered = Signal(str, object)  # controller name, Reading
    failed = Signal(str, str)  # controller name, reason

    def answered_from_poller(self, device: str, reading: Reading) -> None:
        self.answered.emit(device, reading)

    def silent_from_poller(self, device: str, reason: str) -> None:
        self.failed.emit(device, reason)


class _Listener:
    """What :class:`ControllerPoller` calls (from its thread): the tiles (queued to the GUI thread)
    and, while the cell is published, the edge node (in the poller's thread: no network I/O on the
    GUI's)."""

    def __init__(self, feed: CellFeed) -> None:
        self._feed = feed
        self.publisher: DeviceListener | None = None

    def answered(self, device: str, reading: Reading) -> None:
        self._feed.answered_from_poller(device, reading)
        publisher = self.publisher
        if publisher is not None:
            publisher.answered(device, reading)

    def silent(self, device: str, reason: str) -> None:
        self._feed.silent_from_poller(device, reason)
        publisher = self.publisher
        if publisher is not None:
            publisher.silent(device, reason)


class CellTile(QFrame):
    """One controller's tile (monitor-only)."""

    takeControl = Signal(str)
    showHistory = Signal(str)

    def __init__(
        self, controller: CellController, parent: QWidget | None = None, *, stale_after: float = STALE_AFTER
    ) -> None:
        super().__init__(parent)
        self.setObjectName("CellTile")
        self.setFrameShape(QFrame.Shape.StyledPanel)
        self.name = controller.name
        self.where = _where(controller)
        self.history = ControllerHistory(controller.name)
        self.reading: Reading | None = None
        self.started_at = time.monotonic()
        self.failed_last = False
        self.reason = ""
        self.error_times: collections.deque[float] = collections.deque()
        self.controlled = False
        self.silent = False
        self.alarmed = False
        self.stale_after = stale_after
        self.compact = False
        self.body = layout = QVBoxLayout(self)
        layout.setContentsMargins(6, 4, 6, 4)
        layout.setSpacing(1)
        self.name_label = QLabel(self)
        self.name_label.setObjectName("CellTileName")
        self.name_label.setTextFormat(Qt.TextFormat.PlainText)
        font = self.name_label.font()
        font.setBold(True)
        self.name_label.setFont(font)
        self.menu_button = QToolButton(self)  # the compact tile's actions (no room for two buttons)
        self.menu_button.setObjectName("CellTileMenu")
        self.menu_button.setAutoRaise(True)
        self.menu_button.setPopupMode(QToolButton.ToolButtonPopupMode.InstantPopup)
        self.menu_button.setText("⋯")
        self.menu_button.setStyleSheet(MENU_BUTTON_STYLE)
        self.menu_button.setVisible(False)
        menu = QMenu(self.menu_button)
        self.control_action = menu.addAction("")
        self.control_action.triggered.connect(lambda: self.takeControl.emit(self.name))
        self.history_action = menu.addAction("")
        self.history_action.triggered.connect(lambda: self.showHistory.emit(self.name))
        self.menu_button.setMenu(menu)
        self.link_label = QLabel(self)
        self.head = head = QHBoxLayout()
        head.setSpacing(2)
        head.addWidget(self.name_label, 1)
        head.addWidget(self.menu_button)
        layout.addLayout(head)
        self.state_label = QLabel(self)
        self.alarm_label = QLabel(self)
        self.pose_label = QLabel(self)
        self.fresh_label = QLabel(self)
        for label in (self.link_label, self.state_label, self.alarm_label, self.pose_label, self.fresh_label):
            label.setWordWrap(True)
            layout.addWidget(label)
        self.buttons = QWidget(self)
        buttons = QHBoxLayout(self.buttons)
        buttons.setContentsMargins(0, 0, 0, 0)
        buttons.setSpacing(4)
        self.control_button = QPushButton(self.buttons)
        self.control_button.clicked.connect(lambda: self.takeControl.emit(self.name))
        self.history_button = QPushButton(self.buttons)
        self.history_button.clicked.connect(lambda: self.showHistory.emit(self.name))
        buttons.addWidget(self.control_button)
        buttons.addWidget(self.history_button)
        layout.addWidget(self.buttons)
        layout.addStretch(1)
        self.refresh()

    def set_compact(self, compact: bool) -> None:
        """Compact: a smaller font, the address in the tooltip, the actions in a menu, shorter words
        (16 tiles beside the pendant's controls at 1280×800); otherwise the full tile."""
        if compact == self.compact:
            return
        self.compact = compact
        parent = self.parentWidget()
        base = parent.font() if parent is not None else QApplication.font()
        font = QFont(base)
        font.setPointSizeF(base.pointSizeF() * (COMPACT_FONT_SCALE if compact else 1.0))
        for child in (*self.findChildren(QLabel), self.menu_button):  # each: a style sheet stops inheritance
            child.setFont(font)
        bold = QFont(font)
        bold.setBold(True)
        self.name_label.setFont(bold)
        self.menu_button.setFixedHeight(self.name_label.fontMetrics().height())
        # compact: the link state beside the name (one line less), the actions in the menu
        body = self.body
        body.removeWidget(self.link_label)
        self.head.removeWidget(self.link_label)
        if compact:
            self.head.insertWidget(1, self.link_label, 1)
        else:
            body.insertWidget(1, self.link_label)
        self.buttons.setVisible(not compact)
        self.menu_button.setVisible(compact)
        self.name_label.setSizePolicy(
            QSizePolicy.Policy.Maximum if compact else QSizePolicy.Policy.Preferred,
            QSizePolicy.Policy.Preferred,
        )
        margin = 3 if compact else 6
        body.setContentsMargins(margin, 1 if compact else 4, margin, 1 if compact else 4)
        body.setSpacing(0 if compact else 1)
        self.head.setSpacing(6 if compact else 2)
        self.retranslate()

    # --- what the poller told ---------------------------------------------------------
    def on_answer(self, reading: Reading) -> None:
        self.reading = reading
        self.failed_last = False
        self.history.observe(reading.status, reading.wall_ms)

    def on_failure(self, reason: str) -> None:
        self.failed_last = True
        self.reason = reason
        self.error_times.append(time.monotonic())
        self.history.silent(reason, int(time.time() * 1000))

    # --- what it shows ---------------------------------------------------------------
    def age(self) -> float:
        since = self.reading.answered_at if self.reading is not None else self.started_at
        return max(0.0, time.monotonic() - since)

    def errors_last_minute(self) -> int:
        now = time.monotonic()
        while self.error_times and self.error_times[0] < now - ERROR_WINDOW:
            self.error_times.popleft()
        return len(self.error_times)

    def refresh(self, stale_after: float | None = None) -> None:
        """Show what the poller told last (``stale_after``: s without an answer before it greys)."""
        if stale_after is not None:
            self.stale_after = stale_after
        age = self.age()
        silent = self.failed_last or age > self.stale_after or self.reading is None
        name = self.name if not self.controlled else self.tr("{name} (in control)").format(name=self.name)
        self.name_label.setText(name if self.compact else f"{name}  {self.where}")
        if silent:
            self.link_label.setText(self.tr("not answering {seconds} s").format(seconds=f"{age:.0f}"))
        else:
            self.link_label.setText(self.tr("answering"))
        self._show_reading()
        self._show_freshness(age)
        if silent != self.silent:
            self.silent = silent
            self.setProperty("silent", silent)
            self.setStyleSheet(SILENT_STYLE if silent else "")  # greyed at a glance
            for child in self.findChildren(QLabel):
                child.setEnabled(not silent or child is self.link_label)
            self.link_label.setStyleSheet(SILENT_TEXT_STYLE if silent else "")
        self.control_button.setEnabled(not self.controlled)
        self.control_action.setEnabled(not self.controlled)

    def _show_freshness(self, age: float) -> None:
        errors = self.errors_last_minute()
        if self.reading is None:
            text = (
                self.tr("no answer, {errors} err/min")
                if self.compact
                else self.tr("no answer yet, {errors} errors/min")
            )
            self.fresh_label.setText(text.format(errors=errors))
            return
        text = (
            self.tr("{age} s, RTT {rtt} ms, {errors} err/min")
            if self.compact
            else self.tr("{age} s ago, RTT {rtt} ms, {errors} errors/min")
        )
        self.fresh_label.setText(
            text.format(age=f"{age:.1f}", rtt=f"{self.reading.rtt_ms:.0f}", errors=errors)
        )

    def _show_reading(self) -> None:
        reading = self.reading
        if reading is None:
            for label in (self.state_label, self.alarm_label, self.pose_label):
                label.setText("—")
            return
        status = reading.status
        mode = CONTROLLER_MODE_TEXT.get(ControllerMode(status.mode)) if status.mode in MODES else None
        program = (
            PROGRAM_STATE_TEXT.get(ProgramState(status.program_state))
            if status.program_state in PROGRAM_STATES
            else None
        )
        words = self.tr("{mode}, {program}") if self.compact else self.tr("mode {mode}, program {program}")
        self.state_label.setText(
            words.format(
                mode=_protocol(mode) if mode else str(int(status.mode)),
                program=_protocol(program) if program else str(int(status.program_state)),
            )
        )
        self._show_alarms(alarm_order(int(status.alarms), self.history.raised_at))
        pose = reading.pose
        gap = " " if self.compact else "  "
        self.pose_label.setText(
            f"X {pose.x:.1f}{gap}Y {pose.y:.1f}{gap}Z {pose.z:.1f}\n"
            f"A {pose.a:.1f}{gap}B {pose.b:.1f}{gap}C {pose.c:.1f}"
        )

    def _show_alarms(self, alarms: list[Alarm]) -> None:
        """Most severe first, then the oldest; the compact tile names the first and counts the rest."""
        names = [_protocol(ALARM_TEXT[bit]) for bit in alarms]
        if not names:
            text = self.tr("no alarm")
        elif self.compact and len(names) > 1:
            text = self.tr("{alarm} +{more}").format(alarm=names[0], more=len(names) - 1)
        elif self.compact:
            text = names[0]
        else:
            text = self.tr("alarms: {alarms}").format(alarms=join_names(names))
        self.alarm_label.setText(text)
        self.alarm_label.setToolTip(join_names(names) if names else "")
        if bool(names) != self.alarmed:  # a style sheet only when it changes (it re-polishes the label)
            self.alarmed = bool(names)
            self.alarm_label.setStyleSheet(ALARM_STYLE if names else "")

    def retranslate(self) -> None:
        self.control_button.setText(self.tr("Take control…"))
        self.history_button.setText(self.tr("History"))
        self.control_action.setText(self.tr("Take control…"))
        self.history_action.setText(self.tr("History"))
        self.menu_button.setToolTip(
            self.tr("Take control or see the history of {name}").format(name=self.name)
        )
        self.name_label.setToolTip(self.where)
        self.refresh()


class CellPanel(QWidget):
    """The Cell tab of one cell (see the module docstring). :meth:`stop` ends its pollers."""

    takeControl = Signal(str)
    exportHistory = Signal(str)  # controller name: the host asks where and writes
    ownWindow = Signal(bool)  # the whole-window button: True to leave the tab, False to come back
    publishAsked = Signal()  # the plant link button: the host asks where to publish

    def __init__(
        self,
        cell: Cell,
        parent: QWidget | None = None,
        *,
        timing: GatewayTiming | None = None,
        stale_after: float = STALE_AFTER,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("CellPanel")
        self.cell = cell
        self.stale_after = stale_after
        self.feed = CellFeed(self)
        self.feed.answered.connect(self._on_answer, Qt.ConnectionType.QueuedConnection)
        self.feed.failed.connect(self._on_failure, Qt.ConnectionType.QueuedConnection)
        self.tiles: dict[str, CellTile] = {}
        self.pages = QStackedWidget(self)
        outer = QVBoxLayout(self)
        outer.setContentsMargins(0, 0, 0, 0)
        self.title = QLabel(self)
        self.title.setTextFormat(Qt.TextFormat.PlainText)
        self.title.setWordWrap(True)  # a long cell name takes a second line, not the buttons' room
        self.window_button = QPushButton(self)
        self.window_button.setCheckable(True)
        self.window_button.toggled.connect(self.ownWindow)
        self.publish_label = QLabel(self)
        self.publish_label.setObjectName("CellPublishState")
        self.publish_label.setTextFormat(Qt.TextFormat.PlainText)
        self.publish_button = QPushButton(self)
        self.publish_button.setObjectName("CellPublishButton")
        self.publish_button.clicked.connect(self.publishAsked)
        self.publisher: CellPublisher | None = None
        top = QHBoxLayout()
        top.addWidget(self.title, 1)
        top.addWidget(self.publish_label)
        top.addWidget(self.publish_button)
        top.addWidget(self.window_button)
        outer.addLayout(top)
        outer.addWidget(self.pages, 1)
        self.area = QScrollArea(self)
        self.area.setWidgetResizable(True)
        self.area.setFrameShape(QFrame.Shape.NoFrame)
        grid_host = QWidget(self.area)
        self.grid = QGridLayout(grid_host)
        self.grid.setContentsMargins(0, 2, 0, 0)
        self.grid.setSpacing(3)
        self.columns = 0
        self.compact = False
        self.probe = CellTile(cell.controllers[0], self)  # a full tile nobody sees: how tall full tiles are
        self.probe.hide()
        for controller in cell.controllers:
            tile = CellTile(controller, grid_host, stale_after=stale_after)
            tile.takeControl.connect(self.takeControl)
            tile.showHistory.connect(self.show_history)
            self.tiles[controller.name] = tile
        self._reflow(4)
        self.area.setWidget(grid_host)
        self.area.installEventFilter(self)
        self.pages.addWidget(self.area)
        self.detail = self._make_detail()
        self.pages.addWidget(self.detail)
        self.detail_name: str | None = None
        gateway = timing or GatewayTiming(poll_hz=CELL_POLL_HZ)
        self.listener = _Listener(self.feed)
        self.pollers = [ControllerPoller(c, self.listener, gateway) for c in cell.controllers]
        self.timer = QTimer(self)
        self.timer.setInterval(250)
        self.timer.timeout.connect(self.refresh)
        self.retranslate()

    def _make_detail(self) -> QWidget:
        page = QWidget(self)
        layout = QVBoxLayout(page)
        row = QHBoxLayout()
        self.back_button = QPushButton(page)
        self.back_button.clicked.connect(lambda: self.pages.setCurrentIndex(0))
        self.export_button = QPushButton(page)
        self.export_button.clicked.connect(lambda: self.exportHistory.emit(self.detail_name or ""))
        self.detail_title = QLabel(page)
        self.detail_title.setTextFormat(Qt.TextFormat.PlainText)
        row.addWidget(self.back_button)
        row.addWidget(self.detail_title, 1)
        row.addWidget(self.export_button)
        layout.addLayout(row)
        self.table = QTableWidget(0, 3, page)
        self.table.verticalHeader().setVisible(False)
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        layout.addWidget(self.table, 1)
        return page

    def _reflow(self, columns: int) -> None:
        """Lay the tiles out in ``columns`` columns (the tab's width decides: :meth:`resizeEvent`)."""
        columns = max(1, columns)
        if columns == self.columns:
            return
        self.columns = columns
        for tile in self.tiles.values():
            self.grid.removeWidget(tile)
        for i, tile in enumerate(self.tiles.values()):
            self.grid.addWidget(tile, i // columns, i % columns)
        for column in range(len(self.tiles)):
            self.grid.setColumnStretch(column, 1 if column < columns else 0)
        rows = -(-len(self.tiles) // columns)
        for row in range(self.grid.rowCount()):
            self.grid.setRowStretch(row, 0)
        self.grid.setRowStretch(rows, 1)

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.area and event.type() == QEvent.Type.Resize:
            self.arrange()
        return False

    def arrange(self) -> None:
        """Full tiles when all of them fit the tab, else compact ones in as many columns as fit (16 at
        1280×800 beside the pendant's controls); the scroll area scrolls what still does not fit."""
        count = len(self.tiles)
        frame = 2 * self.area.frameWidth()
        margins = self.grid.contentsMargins()
        spacing = self.grid.spacing()
        width = self.area.width() - frame - margins.left() - margins.right()
        height = self.area.height() - frame - margins.top() - margins.bottom()
        columns = max(1, (width + spacing) // (TILE_WIDTH + spacing))
        rows = -(-count // columns)
        full = self.probe.heightForWidth(width // columns - spacing) + self.probe.fontMetrics().lineSpacing()
        compact = rows * (full + spacing) - spacing > height
        if compact:
            columns = max(1, min(count, (width + spacing) // (COMPACT_WIDTH + spacing)))
            needed = -(-count // columns) * (self._compact_height() + spacing) - spacing
            if needed > height:  # a vertical scroll bar takes its width
                width -= self.area.verticalScrollBar().sizeHint().width()
                columns = max(1, min(count, (width + spacing) // (COMPACT_WIDTH + spacing)))
        if compact != self.compact:
            self.compact = compact
            for tile in self.tiles.values():
                tile.set_compact(compact)
        self._reflow(columns)

    def _compact_height(self) -> int:
        tile = next(iter(self.tiles.values()))
        return tile.heightForWidth(COMPACT_WIDTH) if tile.compact else 0

    # --- life --------------------------------------------------------------------------
    def start(self) -> None:
        for poller in self.pollers:
            poller.start()
        self.timer.start()

    def stop(self) -> None:
        """End every poller (each ends within its poll timeout) and the refresh."""
        self.timer.stop()
        for poller in self.pollers:
            poller.request_stop()  # all at once: the joins below then wait one poll timeout, not 16
        for poller in self.pollers:
            poller.stop()

    # --- the pollers' news (GUI thread) -------------------------------------------------
    @Slot(str, object)
    def _on_answer(self, name: str, reading: Reading) -> None:
        tile = self.tiles.get(name)
        if tile is not None:
            tile.on_answer(reading)

    @Slot(str, str)
    def _on_failure(self, name: str, reason: str) -> None:
        tile = self.tiles.get(name)
        if tile is not None:
            tile.on_failure(reason)
            tile.refresh(self.stale_after)  # greyed at once, not at the next tick

    @Slot()
    def refresh(self) -> None:
        for tile in self.tiles.values():
            tile.refresh(self.stale_after)
        if self.pages.currentIndex() == 1:
            self._fill_history()
        self._show_publishing()

    # --- the plant link ---------------------------------------------------------------
    def set_publisher(self, publisher: CellPublisher | None) -> None:
        """Feed ``publisher`` every poll from now on (None: nobody) and say how it is doing."""
        self.listener.publisher = publisher
        self.publisher = publisher
        self._show_publishing()

    def _show_publishing(self) -> None:
        publisher = self.publisher
        if publisher is None:
            self.publish_label.setText("")
            self.publish_label.setToolTip("")
            return
        broker, edge = publisher.broker, publisher.edge
        where = f"{broker.host}:{broker.port}, spBv1.0/{edge.group}/…/{edge.node}"
        if publisher.online:  # short: the title row is narrow at 1280×800; the tooltip says where
            self.publish_label.setText(self.tr("MQTT: published"))
            self.publish_label.setToolTip(self.tr("Published to {where}").format(where=where))
        else:
            self.publish_label.setText(self.tr("MQTT: connecting…"))
            self.publish_label.setToolTip(self.tr("Connecting to {where}…").format(where=where))

    def set_controlled(self, name: str | None) -> None:
        for tile_name, tile in self.tiles.items():
            tile.controlled = tile_name == name
            tile.refresh(self.stale_after)

    # --- history ---------------------------------------------------------------------
    @Slot(str)
    def show_history(self, name: str) -> None:
        self.detail_name = name
        self.pages.setCurrentIndex(1)
        self._fill_history()

    def _fill_history(self) -> None:
        tile = self.tiles.get(self.detail_name or "")
        if tile is None:
            return
        self.detail_title.setText(self.tr("History of {name}").format(name=tile.name))
        events = list(tile.history.events)
        self.table.setRowCount(len(events))
        for row, event in enumerate(reversed(events)):  # the newest first
            for column, text in enumerate((event.time_text, event.kind, event.detail)):
                self.table.setItem(row, column, QTableWidgetItem(text))

    def retranslate(self) -> None:
        self.title.setText(
            self.tr("Cell {name}: {count} controllers, monitor only").format(
                name=self.cell.name, count=len(self.tiles)
            )
        )
        self.back_button.setText(self.tr("Back to the cell"))
        self.window_button.setText(self.tr("Whole window"))
        self.publish_button.setText(self.tr("Plant link…"))
        self.publish_button.setToolTip(
            self.tr("Publish this cell to an MQTT broker (Sparkplug B), as teachpad-gateway")
        )
        self._show_publishing()
        self.window_button.setToolTip(self.tr("Show the cell in a window of its own (16 tiles at a glance)"))
        self.export_button.setText(self.tr("Export CSV…"))
        self.table.setHorizontalHeaderLabels([self.tr("Time"), self.tr("Event"), self.tr("Detail")])
        for tile in self.tiles.values():
            tile.retranslate()

    def closeEvent(self, event: QCloseEvent) -> None:
        """In a window of its own, closing it puts the cell back in its tab (the host's)."""
        if self.isWindow() and self.window_button.isChecked():
            event.ignore()
            self.window_button.setChecked(False)
            return
        super().closeEvent(event)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

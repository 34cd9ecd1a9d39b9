"""*File → Open cell…* and the Cell tab of the main window (issue 23): monitor many, command one.

:class:`CellHost` owns the open cell's :class:`~ui.panels.cell_panel.CellPanel` (one at a time: a
new cell closes the last one and its pollers). Its file choosers and error messages go through the
window's project dialogs (``window.project.dialogs``: tests answer them); the *Take control*
confirmation through the window's ``confirm`` (the seam of every question the window asks).

*Take control* on a tile: the connection role check (the administrator's, audited like the
connection dialog's), a confirmation naming the robot, one ``link`` audit record, then the
window's own connect path (:meth:`MainWindow.connect_with`: the link's supervisor decides the
controller identity, so nothing of one robot's sync state carries to another). Only the window's
link ever writes; the tiles' clients are monitor-only, so one robot at a time is commandable.

*Plant link…* (the Cell tab's button, :class:`~ui.dialogs.cell_publish_dialog.CellPublishDialog`):
publish the open cell to an MQTT broker through the gateway's edge node, off by default, remembered
in the window's settings (:data:`PUBLISH_KEYS`) and applied to every cell opened after. The edge
node connects in paho's thread and says its NDEATH and disconnects in a thread of its own (the
window's close waits for it, a bounded time), so the GUI thread never waits on the broker.
"""

from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, Qt, Slot
from PySide6.QtGui import QAction

from app.errors import TeachPadError
from app.link.types import ConnectionState, LinkState
from app.safety.roles import Action

if TYPE_CHECKING:  # the cell's modules (Modbus clients, pollers) load with the first cell, not at start-up
    from PySide6.QtWidgets import QDialog

    from app.cell.cell_file import Cell
    from app.cell.publish import PublishSettings
    from app.gateway.poller import GatewayTiming
    from ui.panels.cell_panel import CellPanel

__all__ = ["PUBLISH_KEYS", "CellHost", "install_cell"]

#: the window's settings of the plant link: on (off by default), broker URL, group, node
PUBLISH_KEYS = ("cell/publish", "cell/publish_broker", "cell/publish_group", "cell/publish_node")
STOP_SLACK = 1.0  # s beyond the edge node's own wait for its NDEATH, at the window's close


class CellHost(QObject):
    """The window's cell: the *Open cell…* action and the Cell tab (see the module docstring)."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.panel: CellPanel | None = None
        self.controlled: str | None = None
        self.publish_timing: GatewayTiming | None = None  # the edge node's clocks (None: the gateway's)
        self._stopping: list[threading.Thread] = []  # edge nodes saying NDEATH and disconnecting
        self.open_action = QAction(window)
        self.open_action.setObjectName("OpenCellAction")
        self.open_action.triggered.connect(self.choose_cell)
        menus = window.menus
        menus.file_menu.insertAction(menus.connect_action, self.open_action)
        menus.file_menu.insertSeparator(menus.connect_action)
        window.installEventFilter(self)
        window.link.state.connectionChanged.connect(self._on_connection)
        self.retranslate()

    # --- opening -----------------------------------------------------------------------
    @Slot()
    def choose_cell(self) -> None:
        dialogs = self.window.project.dialogs
        path = dialogs.open_path(self.tr("Open cell"), self.tr("Cell files (*.json);;All files (*)"))
        if path:
            self.open_cell(path)

    def open_cell(self, path: str) -> bool:
        """Load the cell file at ``path`` and show its tab; a bad file is said in a dialog."""
        from app.cell.cell_file import CellFileError, load_cell

        try:
            cell = load_cell(path)
        except CellFileError as exc:
            self.window.project.dialogs.error(self.tr("Cell file"), str(exc))
            return False
        self.show_cell(cell)
        return True

    def show_cell(self, cell: Cell, **panel_options: Any) -> CellPanel:
        from ui.panels.cell_panel import CellPanel

        self.close_cell()
        panel = CellPanel(cell, self.window.work_tabs, **panel_options)
        panel.takeControl.connect(self.take_control)
        panel.exportHistory.connect(self.export_history)
        panel.ownWindow.connect(self.set_own_window)
        panel.publishAsked.connect(self.choose_publishing)
        self.panel = panel
        tabs = self.window.work_tabs
        tabs.setCurrentIndex(tabs.addTab(panel, self.tr("Cell")))
        panel.start()
        self._on_connection(self.window.link.state.connection)
        self._start_publishing()
        return panel

    def close_cell(self) -> None:
        panel, self.panel = self.panel, None
        if panel is None:
            return
        self._stop_publishing(panel)
        panel.stop()
        panel.window_button.setChecked(False)  # back in its tab, to leave it
        tabs = self.window.work_tabs
        index = tabs.indexOf(panel)
        if index >= 0:
            tabs.removeTab(index)
        panel.deleteLater()

    @Slot(bool)
    def set_own_window(self, own: bool) -> None:
        """The Cell tab in a window of its own (the window's size: 16 tiles at 1280×800), or back."""
        panel, tabs = self.panel, self.window.work_tabs
        if panel is None or own == panel.isWindow():
            return
        if own:
            tabs.removeTab(tabs.indexOf(panel))
            panel.setParent(self.window, Qt.WindowType.Window)
            panel.setWindowTitle(self.tr("Cell {name}").format(name=panel.cell.name))
            panel.resize(self.window.size())
            panel.show()
        else:
            panel.setParent(None)
            tabs.setCurrentIndex(tabs.addTab(panel, self.tr("Cell")))

    # --- monitor many, command one -------------------------------------------------------
    @Slot(object)
    def _on_connection(self, connection: ConnectionState) -> None:
        """The tile "in control" is the one the window's link reaches (by Take control or Connect…)."""
        panel = self.panel
        if panel is None:
            return
        up = connection.state is not LinkState.DISCONNECTED
        name = next((n for n, t in panel.tiles.items() if up and t.where == connection.endpoint), None)
        self.controlled = name
        panel.set_controlled(name)

    @Slot(str)
    def take_control(self, name: str) -> bool:
        """Make ``name`` the pendant's robot (see the module docstring); True when connecting."""
        panel = self.panel
        controller = next((c for c in panel.cell.controllers if c.name == name), None) if panel else None
        if panel is None or controller is None:
            return False
        window = self.window
        safety = window.safety_menu.safety
        if not safety.allowed(Action.CONNECTION):
            return False
        where = panel.tiles[name].where
        text = self.tr(
            "Take control of {name} ({where})?\n\nThe pendant connects to it and commands it; "
            "every other robot of the cell stays monitor-only."
        ).format(name=name, where=where)
        if not window.confirm(self.tr("Take control"), text):
            return False
        safety.session.audit.record(
            "link", "take control", args={"controller": name, "where": where, "cell": panel.cell.name}
        )
        window.connect_with(controller.settings(monitor_only=False))  # the tile follows the link's state
        return True

    @Slot(str)
    def export_history(self, name: str) -> None:
        panel = self.panel
        tile = panel.tiles.get(name) if panel is not None else None
        if tile is None:
            return
        dialogs = self.window.project.dialogs
        path = dialogs.save_path(
            self.tr("Export history"), self.tr("CSV files (*.csv)"), f"{name}-history.csv"
        )
        if not path:
            return
        try:
            tile.history.export_csv(path)
        except (OSError, TeachPadError) as exc:
            dialogs.error(
                self.tr("Export history"),
                self.tr("Cannot write {path}: {error}").format(
                    path=path, error=getattr(exc, "strerror", None) or str(exc)
                ),
            )

    # --- the plant link (publishing the cell, off by default) ----------------------------
    def publish_settings(self) -> tuple[bool, PublishSettings]:
        """Whether the GUI publishes its cell, and where (remembered in the window's settings)."""
        from app.cell.publish import PublishSettings

        store = self.window.settings.store
        enabled = str(store.value(PUBLISH_KEYS[0], "false")).strip().lower() in ("1", "true", "yes", "on")
        defaults = PublishSettings()
        settings = PublishSettings(
            broker=str(store.value(PUBLISH_KEYS[1], defaults.broker)),
            group=str(store.value(PUBLISH_KEYS[2], defaults.group)),
            node=str(store.value(PUBLISH_KEYS[3], defaults.node)),
        )
        return enabled, settings

    def set_publishing(self, enabled: bool, settings: PublishSettings) -> None:
        """Remember the setting and apply it to the open cell: a new edge node (its NBIRTH and DBIRTHs),
        or the last one's NDEATH and a clean disconnect; none of it on the GUI thread."""
        store = self.window.settings.store
        for key, value in zip(
            PUBLISH_KEYS, (enabled, settings.broker, settings.group, settings.node), strict=True
        ):
            store.setValue(key, value)
        store.sync()
        if self.panel is not None:
            self._stop_publishing(self.panel)
            self._start_publishing()

    @Slot()
    def choose_publishing(self) -> None:
        from ui.dialogs.cell_publish_dialog import CellPublishDialog

        enabled, settings = self.publish_settings()
        dialog = CellPublishDialog(enabled, settings, self.panel or self.window)
        if self.run_dialog(dialog):
            self.set_publishing(*dialog.values())
        dialog.deleteLater()

    def run_dialog(self, dialog: QDialog) -> bool:
        """The seam tests answer: show ``dialog`` modally, True when accepted."""
        from PySide6.QtWidgets import QDialog

        return dialog.exec() == QDialog.DialogCode.Accepted

    def _stop_wait(self) -> float:
        from app import timing

        return self.publish_timing.stop_wait if self.publish_timing is not None else timing.GATEWAY_STOP_WAIT

    def _start_publishing(self) -> None:
        from app.cell.publish import CellPublisher

        panel = self.panel
        enabled, settings = self.publish_settings()
        if panel is None or not enabled or not settings.valid():
            return
        publisher = CellPublisher(panel.cell, settings, self.publish_timing)
        panel.set_publisher(publisher)  # the pollers feed it from their threads
        publisher.start()  # paho's network thread connects

    def _stop_publishing(self, panel: CellPanel) -> None:
        publisher = panel.publisher
        if publisher is None:
            return
        panel.set_publisher(None)
        self._stopping.append(publisher.stop())  # NDEATH and the disconnect in a thread of their own

    def wait_unpublished(self, timeout: float) -> bool:
        """Wait (at most ``timeout`` s in all) for the stopped edge nodes' NDEATH and disconnect."""
        deadline = time.monotonic() + timeout
        for thread in self._stopping:
            thread.join(max(0.0, deadline - time.monotonic()))
        self._stopping = [t for t in self._stopping if t.is_alive()]
        return not self._stopping

    # --- the window --------------------------------------------------------------------
    def retranslate(self) -> None:
        self.open_action.setText(self.tr("Open &cell…"))
        self.open_action.setToolTip(self.tr("Watch every controller of a cell file, monitor only"))
        if self.panel is not None:
            index = self.window.work_tabs.indexOf(self.panel)
            if index >= 0:
                self.window.work_tabs.setTabText(index, self.tr("Cell"))
            self.panel.setWindowTitle(self.tr("Cell {name}").format(name=self.panel.cell.name))

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window:
            if event.type() == QEvent.Type.LanguageChange:
                self.retranslate()
            elif event.type() == QEvent.Type.Close:
                self.close_cell()  # the pollers end with the window
                self.wait_unpublished(self._stop_wait() + STOP_SLACK)  # NDEATH before exit
        return False


def install_cell(window: Any) -> CellHost:
    return CellHost(window)

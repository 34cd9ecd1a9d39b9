"""*View → Watch list*: the dock, the list saved with the project, its reads and writes (issue 24).

:class:`WatchListHost` owns the watch list's dock (in the bottom dock area, tabbed with the event
log, closed at first; the View menu's *Watch list* opens it), its
:class:`~app.watchlist.history.WatchHistory` and the link's side of it:

* the list is the project's (``Project.watch_list``, saved with it: docs/PROJECT_FORMAT.md); an
  edit changes the project (dirty, saved, autosaved), a project opened brings its own list;
* while the dock is open (shown, or tabbed behind another) the list is sent to the link
  (:class:`~app.link.ops.SetWatchList`): the worker reads it after the pose of each poll; closed,
  an empty list is sent and the polls read nothing more than before;
* an engineer's write (:meth:`WatchListHost.write_value`): the role (refused and audited below
  engineer, :class:`~app.safety.roles.Action` ``WRITE_WATCHED``), a writable link, the value
  asked and checked, a confirmation naming the value, the controller and the old value, an
  ``action`` audit record, then :class:`~app.link.ops.WriteWatched` -- whose register write goes
  through the client's one write guard (monitor-only refuses it; the audit records the write).

The panel itself is built when the dock is first shown (pyqtgraph with it).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, Qt, Slot
from PySide6.QtWidgets import QDockWidget, QWidget

from app.errors import InvalidInput, TeachPadError
from app.link.ops import SetWatchList, WriteWatched
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import CommandResult
from app.safety.roles import Action
from app.watchlist.entry import WatchEntry, format_value
from app.watchlist.history import WatchHistory
from ui.messages import error_text, result_text

if TYPE_CHECKING:
    from app.points.project_model import Project
    from app.watchlist.plan import WatchReadings
    from ui.panels.watch_list_panel import WatchListPanel

__all__ = ["WatchListHost", "install_watch_list"]


def _ask_value(parent: QWidget, title: str, label: str, current: str) -> str | None:
    from PySide6.QtWidgets import QInputDialog

    text, ok = QInputDialog.getText(parent, title, label, text=current)
    return text if ok else None


class WatchListHost(QObject):
    """See the module docstring. ``ask_value(title, label, current) -> text | None`` is the seam
    of the value prompt (tests answer it, as ``window.confirm``)."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.link = window.link
        self.history = WatchHistory()
        self.generation = 0
        self.entries: tuple[WatchEntry, ...] = tuple(window.project.project.watch_list)
        self.panel: WatchListPanel | None = None
        self._sent: tuple[WatchEntry, ...] | None = None  # the list the link reads now
        self.ask_value: Callable[[str, str, str], str | None] = lambda title, label, current: _ask_value(
            window, title, label, current
        )
        dock = self.dock = QDockWidget(window)
        dock.setObjectName("WatchListDock")
        placeholder = QWidget(dock)
        placeholder.setObjectName("WatchListPlaceholder")
        dock.setWidget(placeholder)
        window.addDockWidget(Qt.DockWidgetArea.BottomDockWidgetArea, dock)
        window.tabifyDockWidget(window.event_dock, dock)
        dock.hide()  # closed at first; a remembered layout may open it
        self._add_to_view_menu(window.menus.view_menu, window.alarm_dock)
        dock.visibilityChanged.connect(self._on_visibility)
        self.link.watchRead.connect(self._on_read)
        self.link.state.connectionChanged.connect(self._on_connection)
        window.project.projectReplaced.connect(self._on_project)
        window.installEventFilter(self)
        self.retranslate()

    def _add_to_view_menu(self, menu: Any, after: QDockWidget) -> None:
        actions = menu.actions()
        anchor = after.toggleViewAction()
        index = actions.index(anchor) + 1 if anchor in actions else len(actions)
        action = self.dock.toggleViewAction()
        action.setObjectName("WatchListAction")
        action.triggered.connect(self._raise_if_open)  # tabbed with the event log: in front when opened
        if index < len(actions):
            menu.insertAction(actions[index], action)
        else:
            menu.addAction(action)

    # --- the panel ---------------------------------------------------------------------
    def build_panel(self) -> WatchListPanel:
        panel = self.panel
        if panel is not None:
            return panel
        from ui.panels.watch_list_panel import WatchListPanel

        panel = self.panel = WatchListPanel(self.history, lambda: self.link.state.fresh, self.dock)
        panel.set_entries(self.entries)
        panel.entriesEdited.connect(self.set_entries)
        panel.writeRequested.connect(self.write_value)
        panel.exportRequested.connect(self.export_csv)
        self.window.safety_menu.safety.gate_panel(panel, Action.WRITE_WATCHED)
        panel.set_writable(self.link.state.writable)
        placeholder = self.dock.widget()
        self.dock.setWidget(panel)
        if placeholder is not None:
            placeholder.deleteLater()
        return panel

    @property
    def open(self) -> bool:
        """The dock is open (shown, or tabbed behind another dock)."""
        return not self.dock.isHidden()

    @Slot(bool)
    def _raise_if_open(self, checked: bool) -> None:
        if checked:
            self.dock.raise_()

    @Slot(bool)
    def _on_visibility(self, shown: bool) -> None:
        if shown:
            self.build_panel()
        self._send()

    # --- the list ----------------------------------------------------------------------
    @Slot(tuple)
    def set_entries(self, entries: tuple[WatchEntry, ...]) -> None:
        """The operator's new list: the project's, the panel's, the link's."""
        self.entries = tuple(entries)
        self.window.project.project.set_watch_list(self.entries)
        self.window.project.note_changed()
        self._show_entries()

    @Slot(object)
    def _on_project(self, project: Project) -> None:
        self.entries = tuple(project.watch_list)
        self._show_entries()

    def _show_entries(self) -> None:
        self.history.keep_only(self.entries)
        if self.panel is not None:
            self.panel.set_entries(self.entries)
        self._send()

    def _send(self) -> None:
        wanted = self.entries if self.open else ()
        if wanted == self._sent:
            return
        if self._sent is None and (not wanted or self.link.connection.state is LinkState.DISCONNECTED):
            return  # nothing sent yet: no list to clear, or no link (sent when it connects: the
            # window's start makes no worker for it)
        self.generation += 1
        self._sent = wanted
        self.link.submit(SetWatchList(wanted, generation=self.generation))

    @Slot(object)
    def _on_read(self, readings: WatchReadings) -> None:
        if readings.generation == self.generation:
            self.history.add(readings.values)

    @Slot(object)
    def _on_connection(self, _state: ConnectionState) -> None:
        self._send()
        if self.panel is not None:
            self.panel.set_writable(self.link.state.writable)

    # --- an engineer's write ---------------------------------------------------------------
    @Slot(object)
    def write_value(self, entry: WatchEntry) -> bool:
        """See the module docstring; True when the write was sent to the link."""
        safety = self.window.safety_menu.safety
        if not safety.allowed(Action.WRITE_WATCHED):  # refused, audited, said
            return False
        panel = self.build_panel()
        if not self.link.state.writable:
            panel.show_problem(self.tr("Not connected, or monitor-only: nothing can be written"))
            return False
        last = self.history.last.get(entry)
        current = format_value(entry, last.value).replace(" ", "") if last is not None else ""
        text = self.ask_value(
            self.tr("Write value"),
            self.tr("New value of {what} ({type}):").format(what=entry.title, type=entry.type.value),
            current,
        )
        if text is None:
            return False
        try:
            value = entry.parse_value(text)
        except InvalidInput as exc:
            panel.show_problem(error_text(exc))
            return False
        settings = self.link.settings
        where = settings.endpoint if settings is not None else "?"
        shown = format_value(entry, value)
        question = self.tr(
            "Write {value} to {what} ({where_reg}) on the controller at {endpoint}?\n\nIt holds {old} now."
        ).format(
            value=shown,
            what=entry.title,
            where_reg=entry.label,
            endpoint=where,
            old=current or self.tr("(not read)"),
        )
        if not self.window.confirm(self.tr("Write value"), question):
            return False
        safety.session.audit.record(
            "action",
            "write watched value",
            args={
                "what": entry.label,
                "name": entry.name,
                "type": entry.type.value,
                "value": shown,
                "was": current,
            },
        )
        panel.show_problem("")
        pending = self.link.track(self.link.submit(WriteWatched(entry, value)))
        pending.finished.connect(self._on_written)
        pending.failed.connect(self._on_write_failed)
        return True

    @Slot(object)
    def _on_written(self, result: CommandResult) -> None:
        if not result.ok and self.panel is not None:
            self.panel.show_problem(result_text(result))

    @Slot(object)
    def _on_write_failed(self, error: WorkerError) -> None:
        if self.panel is not None:
            self.panel.show_problem(self.tr("The value was not written: {why}").format(why=error_text(error)))

    # --- CSV ---------------------------------------------------------------------------
    @Slot()
    def export_csv(self, path: str | None = None) -> bool:
        dialogs = self.window.project.dialogs
        title = self.tr("Export the watch list")
        if path is None:
            path = dialogs.save_path(title, self.tr("CSV files (*.csv)"), "watch-list.csv")
        if not path:
            return False
        try:
            self.history.export_csv(path, self.entries)
        except (OSError, TeachPadError) as exc:
            dialogs.error(
                title,
                self.tr("Cannot write {path}: {error}").format(
                    path=path, error=getattr(exc, "strerror", None) or str(exc)
                ),
            )
            return False
        return True

    # --- the window --------------------------------------------------------------------
    def retranslate(self) -> None:
        self.dock.setWindowTitle(self.tr("Watch list"))
        self.dock.toggleViewAction().setText(self.tr("&Watch list"))

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window and event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        return False


def install_watch_list(window: Any) -> WatchListHost:
    return WatchListHost(window)

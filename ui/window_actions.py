"""The main window's actions, menus and toolbar, with their texts and shortcuts.

:class:`WindowActions` builds them on a :class:`QMainWindow` from the callables it is given
(the window composes; this only lays out commands). Stop, Pause and Resume work application
wide (also from floating docks); every other shortcut works in the window.

Once bound to the link's :class:`~app.link.state.RobotState` (:meth:`WindowActions.bind`),
Disconnect is enabled unless the link is disconnected, Reconnect only while it is (and a last
connection is known), Pause and Resume only while it is writable (connected, not monitor-only);
Stop always. They read the state when it changes and
keep no copy of it.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence

from PySide6.QtCore import QObject, QSize, Qt, Slot
from PySide6.QtGui import QAction, QActionGroup, QKeySequence
from PySide6.QtWidgets import QDockWidget, QMainWindow, QToolBar

from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState
from ui.i18n import LANGUAGE_NAMES

__all__ = ["WindowActions"]

Command = Callable[[], object]


class WindowActions(QObject):
    """Actions (``connect_action``, ``stop_action``, ``tab_actions``, ``language_actions``, ...),
    the menus (``file_menu`` ... ``help_menu``) and the toolbar of ``window``."""

    def __init__(
        self,
        window: QMainWindow,
        *,
        connect: Command,
        disconnect: Command,
        reconnect: Command,
        can_reconnect: Callable[[], bool],
        stop: Command,
        pause: Command,
        resume: Command,
        about: Command,
        show_tab: Callable[[int], object],
        tab_count: int,
        set_language: Callable[[str], object],
        language: str,
        file_actions: Sequence[QAction | None],
        edit_actions: Sequence[QAction],
        docks: Sequence[QDockWidget],
        set_touch_mode: Callable[[bool], object] | None = None,
        touch_mode: bool = False,
    ) -> None:
        super().__init__(window)
        self._window = window
        self._state: RobotState | None = None
        app_wide = Qt.ShortcutContext.ApplicationShortcut
        self.connect_action = self._action(connect, "Ctrl+K")
        self.disconnect_action = self._action(disconnect, "Ctrl+Shift+K")
        self.reconnect_action = self._action(reconnect)
        self.reconnect_action.setObjectName("ReconnectAction")
        self._can_reconnect = can_reconnect
        self.quit_action = self._action(window.close, QKeySequence.StandardKey.Quit)
        self.stop_action = self._action(stop, Qt.Key.Key_Escape, context=app_wide)
        self.stop_action.setObjectName("StopAction")
        self.pause_action = self._action(pause, Qt.Key.Key_F6, context=app_wide)
        self.resume_action = self._action(resume, Qt.Key.Key_F7, context=app_wide)
        self.about_action = self._action(about)
        self.tab_actions = [
            self._action(functools.partial(show_tab, i), f"Ctrl+{i + 1}") for i in range(tab_count)
        ]
        self.language_group = QActionGroup(self)
        self.language_group.setExclusive(True)
        self.language_actions: dict[str, QAction] = {}
        for code, name in LANGUAGE_NAMES.items():
            action = QAction(name, self)  # each language in its own script, never translated
            action.setCheckable(True)
            action.setData(code)
            action.triggered.connect(lambda _checked=False, c=code: set_language(c))
            self.language_group.addAction(action)
            self.language_actions[code] = action
        self.language_actions.get(language, self.language_actions["en"]).setChecked(True)
        self.touch_action = QAction(self)
        self.touch_action.setObjectName("TouchModeAction")
        self.touch_action.setCheckable(True)
        self.touch_action.setChecked(touch_mode)
        if set_touch_mode is not None:
            self.touch_action.toggled.connect(set_touch_mode)
        self._make_menus(file_actions, edit_actions, docks)

    def _action(
        self,
        slot: Callable[[], object],
        shortcut: QKeySequence | QKeySequence.StandardKey | Qt.Key | str | None = None,
        *,
        context: Qt.ShortcutContext = Qt.ShortcutContext.WindowShortcut,
    ) -> QAction:
        action = QAction(self)
        if shortcut is not None:
            action.setShortcut(QKeySequence(shortcut))
        action.setShortcutContext(context)
        action.triggered.connect(slot)
        self._window.addAction(action)
        return action

    def bind(self, state: RobotState) -> None:
        """Enable Disconnect, Pause and Resume from ``state`` (see the module docstring)."""
        self._state = state
        state.connectionChanged.connect(self._on_connection)
        self._on_connection(state.connection)

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        writable = self._state is not None and self._state.writable
        disconnected = connection.state is LinkState.DISCONNECTED
        self.disconnect_action.setEnabled(not disconnected)
        self.reconnect_action.setEnabled(disconnected and self._can_reconnect())
        self.pause_action.setEnabled(writable)
        self.resume_action.setEnabled(writable)

    def _make_menus(
        self,
        file_actions: Sequence[QAction | None],
        edit_actions: Sequence[QAction],
        docks: Sequence[QDockWidget],
    ) -> None:
        window = self._window
        bar = window.menuBar()
        self.file_menu = bar.addMenu("")
        for file_action in file_actions:
            if file_action is None:
                self.file_menu.addSeparator()
            else:
                self.file_menu.addAction(file_action)
                window.addAction(file_action)  # shortcuts work from every panel
        self.file_menu.addSeparator()
        self.file_menu.addAction(self.connect_action)
        self.file_menu.addAction(self.reconnect_action)
        self.file_menu.addAction(self.disconnect_action)
        self.file_menu.addSeparator()
        self.file_menu.addAction(self.quit_action)
        self.edit_menu = bar.addMenu("")
        for action in edit_actions:
            self.edit_menu.addAction(action)
            window.addAction(action)
        self.motion_menu = bar.addMenu("")
        for action in (self.stop_action, self.pause_action, self.resume_action):
            self.motion_menu.addAction(action)
        self.view_menu = bar.addMenu("")
        for action in self.tab_actions:
            self.view_menu.addAction(action)
        self.view_menu.addSeparator()
        for dock in docks:
            self.view_menu.addAction(dock.toggleViewAction())
        self.view_menu.addSeparator()
        self.view_menu.addAction(self.touch_action)
        self.language_menu = bar.addMenu("")
        for action in self.language_actions.values():
            self.language_menu.addAction(action)
        self.help_menu = bar.addMenu("")
        self.help_menu.addAction(self.about_action)

        self.toolbar = QToolBar(window)
        self.toolbar.setObjectName("MainToolBar")
        self.toolbar.setMovable(False)
        for action in (self.connect_action, self.reconnect_action, self.disconnect_action):
            self.toolbar.addAction(action)
        self.toolbar.addSeparator()
        for action in (self.stop_action, self.pause_action, self.resume_action):
            self.toolbar.addAction(action)
        # in the menu bar's free right end, not a row of its own: the screen's height goes to
        # the motion buttons (STOP, Pause and Resume are in the control bar as well)
        self.toolbar.setIconSize(QSize(16, 16))
        bar.setCornerWidget(self.toolbar, Qt.Corner.TopRightCorner)
        self.view_menu.addSeparator()
        self.view_menu.addAction(self.toolbar.toggleViewAction())

    def retranslate(self) -> None:
        for action, text in zip(
            self.tab_actions,
            (self.tr("Show &monitor"), self.tr("Show &points"), self.tr("Show p&lanner")),
            strict=True,
        ):
            action.setText(text)
        self.file_menu.setTitle(self.tr("&File"))
        self.edit_menu.setTitle(self.tr("&Edit"))
        self.motion_menu.setTitle(self.tr("&Motion"))
        self.view_menu.setTitle(self.tr("&View"))
        self.language_menu.setTitle(self.tr("&Language"))
        self.help_menu.setTitle(self.tr("&Help"))
        self.toolbar.setWindowTitle(self.tr("Toolbar"))
        self.toolbar.toggleViewAction().setText(self.tr("Toolbar"))
        self.connect_action.setText(self.tr("&Connect…"))
        self.connect_action.setToolTip(self.tr("Connect to a controller (Ctrl+K)"))
        self.disconnect_action.setText(self.tr("&Disconnect"))
        self.reconnect_action.setText(self.tr("&Reconnect"))
        self.reconnect_action.setToolTip(
            self.tr("Connect again to the last controller, with the same settings")
        )
        self.quit_action.setText(self.tr("&Quit"))
        self.stop_action.setText(self.tr("&Stop"))
        self.stop_action.setToolTip(self.tr("Stop all motion (Esc)"))
        self.pause_action.setText(self.tr("&Pause"))
        self.pause_action.setToolTip(self.tr("Pause the current move or program (F6)"))
        self.resume_action.setText(self.tr("&Resume"))
        self.resume_action.setToolTip(self.tr("Resume the paused move or program (F7)"))
        self.about_action.setText(self.tr("&About TeachPad"))
        self.touch_action.setText(self.tr("&Touch mode"))
        self.touch_action.setToolTip(self.tr("Bigger motion buttons and an on-screen keypad for numbers"))

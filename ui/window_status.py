"""The main window's status bar: its permanent labels, each following what it shows.

Right to left: the link (``connected``, ``not answering``..., its message as tooltip), the mean
poll round trip, the open project, and a red MONITOR ONLY while the link is monitor-only. The
link labels read the link's :class:`~app.link.state.RobotState` when it changes (no copy kept);
transient messages (errors, refusals, the panels' notes) show for :data:`MESSAGE_MS`.
"""

from __future__ import annotations

from PySide6.QtCore import QCoreApplication, QObject, Slot
from PySide6.QtWidgets import QLabel, QStatusBar

from app.link.state import RobotState
from app.link.types import ConnectionState, LinkState
from ui.messages import connection_text
from ui.widgets.live_label import LiveLabel
from ui.widgets_common import connection_display

__all__ = ["MESSAGE_MS", "WindowStatusBar"]

# These labels were the window's: their texts keep the "MainWindow" translation context.
MESSAGE_MS = 8000  # how long a transient status-bar message stays


class WindowStatusBar(QObject):
    """The labels ``monitor_only_label``, ``project_label``, ``rtt_label`` and ``link_label`` on ``bar``."""

    def __init__(self, bar: QStatusBar) -> None:
        super().__init__(bar)
        self.bar = bar
        self._state: RobotState | None = None
        self._project_title = ""
        self._silence_note: str | None = None  # the message shown about the controller's silence
        self.project_label = QLabel(bar)
        self.link_label = QLabel(bar)
        self.rtt_label = LiveLabel(parent=bar, opaque=True)  # twice a second: repaints itself only
        self.monitor_only_label = QLabel(bar)
        self.monitor_only_label.setStyleSheet("color: #c62828; font-weight: bold;")
        for label in (self.monitor_only_label, self.project_label, self.rtt_label, self.link_label):
            bar.addPermanentWidget(label)
        self.retranslate()

    def bind(self, state: RobotState) -> None:
        self._state = state
        state.connectionChanged.connect(self._on_connection)
        state.rttChanged.connect(self._on_rtt)  # a slot of this object: gone with the window
        self._show_connection()
        self._show_rtt()

    @Slot(float)
    def _on_rtt(self, _ms: float) -> None:
        self._show_rtt()

    def retranslate(self) -> None:
        # room for the widest RTT from the start: the status bar does not shift when one arrives
        widest_rtt = QCoreApplication.translate("MainWindow", "RTT {ms} ms").format(ms="9999.9")
        self.rtt_label.fit_texts([widest_rtt + "  "])
        self._show_rtt()
        self.show_project(self._project_title, self.project_label.toolTip())
        self._show_connection()

    def show_message(self, text: str, *, until_answering: bool = False) -> None:
        """A transient message; ``until_answering``: it says the controller did not answer or
        the link failed, and goes as soon as the controller answers again (not after 8 s)."""
        self.bar.showMessage(text, MESSAGE_MS)
        self._silence_note = text if until_answering else None

    def show_project(self, title: str, path: str) -> None:
        self._project_title = title
        self.project_label.setText(
            QCoreApplication.translate("MainWindow", "Project: {name}").format(name=title)
        )
        self.project_label.setToolTip(path)

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        note = self._silence_note
        if connection.state is LinkState.CONNECTED and note is not None:
            self._silence_note = None
            if self.bar.currentMessage() == note:
                self.bar.clearMessage()  # the controller answers again: the silence is over
        self._show_connection()
        self._show_rtt()

    def _show_connection(self) -> None:
        if self._state is None:
            return
        connection = self._state.connection
        text, _level = connection_display(connection)
        self.link_label.setText(text)
        self.link_label.setToolTip(connection_text(connection))
        monitor_only = QCoreApplication.translate("MainWindow", "MONITOR ONLY")
        self.monitor_only_label.setText(monitor_only if connection.monitor_only else "")

    @Slot()
    def _show_rtt(self) -> None:
        """The mean round trip of the polls, "—" while the controller is not answering or the
        link is down (the last figure is not today's)."""
        state = self._state
        if state is None:
            return
        ms = state.rtt
        if ms is None or state.connection.state is not LinkState.CONNECTED:
            text = QCoreApplication.translate("MainWindow", "RTT —")
        else:
            text = QCoreApplication.translate("MainWindow", "RTT {ms} ms").format(ms=f"{ms:.1f}")
        self.rtt_label.setText(text)

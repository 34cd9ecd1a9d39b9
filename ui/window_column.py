"""The main window's control column: the control bar (the big STOP), the motion banner and the
Jog / Step / Program tabs, on the window's left whatever work tab is shown.

The banner says why the motion controls are off ("Not connected", "Monitor only"); it reads the
link's :class:`~app.link.state.RobotState` when it changes and keeps no copy of it. Which
controls are enabled is :class:`~ui.controllers.motion.MotionController`'s business.

The Step and Program tabs are built the first time they are shown or asked for
(:class:`~ui.window_tabs.LazyTab`, ``step_tab`` / ``program_tab``): the window's first paint does
not wait for them; the window attaches their gating through ``on_built``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from PySide6.QtCore import QCoreApplication, Qt, QTimer, Slot
from PySide6.QtWidgets import QLabel, QSizePolicy, QTabWidget, QVBoxLayout, QWidget

from app.link.state import RobotState
from app.link.types import ConnectionState
from app.protocol.word_order_check import WordOrderVerdict
from ui.foreign_words import foreign_master_details, foreign_master_text
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel
from ui.panels.jog_refusal import MotionRefusalLine
from ui.window_tabs import LazyTab

if TYPE_CHECKING:  # built when their tab is first shown (LazyTab)
    from ui.panels.program_panel import ProgramPanel
    from ui.panels.step_panel import StepPanel

__all__ = ["FOREIGN_BANNER_MS", "ControlColumn"]

#: How long the "another master" banner stays after the last sign of one (ms)
FOREIGN_BANNER_MS = 15_000

# The column was part of the window: its texts keep the "MainWindow" translation context.
BANNER_STYLE = (
    "QLabel { background: #fff1d6; color: #7a4a00; border: 1px solid #ef8f00;"
    " border-radius: 4px; padding: 2px 4px; font-weight: bold; }"
)


class ControlColumn(QWidget):
    """``control_bar``, ``motion_banner``, ``tabs`` (``jog_panel``, ``step_panel``,
    ``program_panel``; the last two built on first use), ``refusal_line`` under them (the latest
    refusal of a motion, :mod:`ui.panels.jog_refusal`). Changing the motion tab releases any held
    jog."""

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("ControlColumn")
        self._state: RobotState | None = None
        self.control_bar = ControlBar(self)
        self.jog_panel = JogPanel(self)
        self.tabs = QTabWidget(self)
        self.tabs.setObjectName("MotionTabs")
        self.tabs.addTab(self.jog_panel, "")
        # the dead-man first: connected before the lazy tabs, a held jog is let go before a tab
        # being shown for the first time is built
        self.tabs.currentChanged.connect(lambda _i: self.jog_panel.release_all())
        self.step_tab: LazyTab[StepPanel] = LazyTab(self.tabs, _build_step_panel, "Step")
        self.program_tab: LazyTab[ProgramPanel] = LazyTab(self.tabs, _build_program_panel, "Program")
        self.motion_banner = QLabel(self)
        self.motion_banner.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.motion_banner.setWordWrap(True)
        self.motion_banner.setStyleSheet(BANNER_STYLE)
        # another Modbus master on the controller (issue 19): shown while its signs keep coming
        self.foreign_banner = QLabel(self)
        self.foreign_banner.setObjectName("ForeignMasterBanner")
        self.foreign_banner.setWordWrap(True)
        self.foreign_banner.setStyleSheet(BANNER_STYLE)
        self.foreign_banner.setVisible(False)
        self._foreign_sign: tuple[str, float] | None = None  # the sign the banner says (what, value)
        self._foreign_timer = QTimer(self)
        self._foreign_timer.setSingleShot(True)
        self._foreign_timer.timeout.connect(self.hide_foreign_master)
        # the register profile's float word order is probably wrong (ui/controllers/word_order_watch.py)
        self.word_order_banner = QLabel(self)
        self.word_order_banner.setObjectName("WordOrderBanner")
        self.word_order_banner.setWordWrap(True)
        self.word_order_banner.setStyleSheet(BANNER_STYLE)
        self.word_order_banner.setVisible(False)
        self._word_order: WordOrderVerdict | None = None
        column = QVBoxLayout(self)
        column.setContentsMargins(0, 0, 0, 0)
        column.addWidget(self.control_bar)
        column.addWidget(self.motion_banner)
        column.addWidget(self.foreign_banner)
        column.addWidget(self.word_order_banner)
        column.addWidget(self.tabs, 1)
        # the latest refusal of a motion, under the motion buttons (shown only while it holds)
        self.refusal_line = MotionRefusalLine(self)
        self.refusal_line.shownChanged.connect(self._make_room)  # the six rows keep fitting
        column.addWidget(self.refusal_line)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Expanding)
        self.retranslate()

    @property
    def step_panel(self) -> StepPanel:  # built now if it was not yet
        return self.step_tab.panel

    @property
    def program_panel(self) -> ProgramPanel:
        return self.program_tab.panel

    def bind(self, state: RobotState) -> None:
        """Follow ``state``: the banner shows while the link is not writable, and says why."""
        self._state = state
        state.connectionChanged.connect(self._on_connection)
        state.lastResultChanged.connect(self.refusal_line.on_result)
        self._show_banner()

    def retranslate(self) -> None:
        self.tabs.setTabText(0, QCoreApplication.translate("MainWindow", "Jog"))
        self.tabs.setTabText(1, QCoreApplication.translate("MainWindow", "Step"))
        self.tabs.setTabText(2, QCoreApplication.translate("MainWindow", "Program"))
        self._show_banner()
        self._show_foreign_master()
        self._show_word_order()

    @Slot(object)
    def show_word_order(self, verdict: WordOrderVerdict | None) -> None:
        """The register profile's word order is probably wrong (``verdict``; None: no longer
        said): what is wrong and what to set, the pose read both ways in its tooltip."""
        self._word_order = verdict
        self._show_word_order()
        self._make_room()

    def _show_word_order(self) -> None:
        verdict = self._word_order
        self.word_order_banner.setVisible(verdict is not None)
        if verdict is None:
            return
        from ui.messages_word_order import word_order_details, word_order_text

        self.word_order_banner.setText(word_order_text(verdict))
        self.word_order_banner.setToolTip(word_order_details(verdict))

    @Slot()
    def _make_room(self) -> None:
        """A line shown in the column under or over the tabs (the refusal, the motion banner,
        another master, the word order): the jog panel gives it its hints' height (the six rows
        keep fitting a 1280×800 screen)."""
        banners = (self.motion_banner, self.foreign_banner, self.word_order_banner)
        self.jog_panel.make_room(self.refusal_line.shown or any(not b.isHidden() for b in banners))

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        if not connection.connected:
            self.hide_foreign_master()  # another controller may come next
            self.refusal_line.clear_refusal()  # the motion banner says why nothing moves now
        self._show_banner()

    def show_foreign_master(self, what: str, value: float) -> bool:
        """Say that another master is on the controller (for :data:`FOREIGN_BANNER_MS` after the
        last sign): ``what`` and ``value`` as the link reports the sign (app/link/foreign.py); the
        banner says it again in the new language when it changes. True when the banner was not
        showing (a new episode)."""
        new = self.foreign_banner.isHidden()
        self._foreign_sign = (what, value)
        self._show_foreign_master()
        self.foreign_banner.setVisible(True)
        self._foreign_timer.start(FOREIGN_BANNER_MS)
        self._make_room()
        return new

    def _show_foreign_master(self) -> None:
        """The banner says the sign it keeps in the language in force; its tooltip explains."""
        if self._foreign_sign is None:
            return
        self.foreign_banner.setText(foreign_master_text(*self._foreign_sign))
        self.foreign_banner.setToolTip(foreign_master_details(*self._foreign_sign))

    @Slot()
    def hide_foreign_master(self) -> None:
        self._foreign_timer.stop()
        self._foreign_sign = None
        self.foreign_banner.setVisible(False)
        self._make_room()

    def _show_banner(self) -> None:
        state = self._state
        connection = state.connection if state is not None else None
        writable = state is not None and state.writable
        if connection is not None and connection.connected and connection.monitor_only:
            self.motion_banner.setText(
                QCoreApplication.translate("MainWindow", "Monitor only: motion controls are disabled")
            )
        elif connection is None or not connection.connected:
            self.motion_banner.setText(
                QCoreApplication.translate("MainWindow", "Not connected: motion controls are disabled")
            )
        self.motion_banner.setVisible(not writable)
        self._make_room()


def _build_step_panel() -> StepPanel:
    from ui.panels.step_panel import StepPanel

    return StepPanel()


def _build_program_panel() -> ProgramPanel:
    from ui.panels.program_panel import ProgramPanel

    return ProgramPanel()

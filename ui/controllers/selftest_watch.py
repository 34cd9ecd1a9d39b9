"""The register-map self-test in the GUI: run by itself after every connect, quietly unless
something is off, and on demand (*Help → Check the controller's register map…*).

:class:`RegisterMapCheck` submits one :class:`~app.link.ops.ReadRegisters` of the self-test's
blocks (:data:`app.selftest.checks.SELFTEST_BLOCKS`) to the link -- the reads run in the worker,
never on the GUI thread, and nothing is written -- then checks what came back against the link's
register profile (word order, date/time layout) and the window's robot model
(:func:`app.selftest.checks.check_register_map`) and emits ``reported(SelfTestReport)``; a read
that failed is ``failed(str)`` (in the operator's language). It builds on the link's word-order
watch (:mod:`ui.controllers.word_order_watch`), which judges every pose: this one says it once
per connection with the rest of the map, and names the other settings too.

:func:`install_register_map_check` adds the Help menu's action and says a report with a
mismatch in the event log (one warning line, the fixes in the same entry) and the status bar;
the dialog (:mod:`ui.dialogs.selftest_dialog`) shows the lines on demand.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, Signal, Slot
from PySide6.QtGui import QAction

from app.link.ops import ReadRegisters
from app.link.register_reads import RegisterBlocks
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import CommandResult

if TYPE_CHECKING:
    from app.link.robot_link import RobotLink
    from app.selftest.checks import SelfTestReport
    from app.view3d.kinematics import ArmModel
    from ui.dialogs.selftest_dialog import SelfTestDialog

__all__ = ["RegisterMapCheck", "install_register_map_check"]

_CONNECTED_BEFORE = (LinkState.CONNECTED, LinkState.NOT_ANSWERING)  # still the same connection


class RegisterMapCheck(QObject):
    """See the module docstring. ``report``: the last report (None: none yet, or the link went
    down since); ``running``: a read is under way; ``after_connect``: the last run was the one
    after a connect (not asked for)."""

    reported = Signal(object)  # SelfTestReport
    failed = Signal(str)  # why the registers could not be read, in the operator's language
    started = Signal()

    def __init__(
        self, link: RobotLink, model: Callable[[], ArmModel | None], parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self._link = link
        self._model = model
        self._ticket: int | None = None
        self._was = link.state.connection.state
        self.report: SelfTestReport | None = None
        self.error = ""
        self.after_connect = False
        link.state.connectionChanged.connect(self._on_connection)
        link.registersRead.connect(self._on_read)
        link.errorOccurred.connect(self._on_error)
        link.commandFinished.connect(self._on_result)

    @property
    def running(self) -> bool:
        return self._ticket is not None

    def run(self, *, after_connect: bool = False) -> bool:
        """Read the registers now (False: not connected, or a read is under way)."""
        if self._ticket is not None or not self._link.state.connection.connected:
            return False
        self.after_connect = after_connect
        from app.selftest.checks import SELFTEST_BLOCKS  # the checks (and numpy): by the first use

        self.error = ""
        self._ticket = self._link.submit(ReadRegisters(SELFTEST_BLOCKS))
        self.started.emit()
        return True

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        was, self._was = self._was, connection.state
        if connection.state is LinkState.CONNECTED and was not in _CONNECTED_BEFORE:
            self._ticket = None  # a read of the last connection answers no more
            self.run(after_connect=True)
        elif not connection.connected and connection.state is not LinkState.NOT_ANSWERING:
            self.report = None

    @Slot(object)
    def _on_read(self, read: RegisterBlocks) -> None:
        if self._ticket is None or read.request_id != self._ticket:
            return
        self._ticket = None
        settings = self._link.settings
        if settings is None:
            return
        from app.selftest.checks import check_register_map

        self.report = check_register_map(read, settings.word_order, settings.datetime_layout, self._model())
        self.reported.emit(self.report)

    @Slot(WorkerError)
    def _on_error(self, error: WorkerError) -> None:
        if self._ticket is not None and error.request_id == self._ticket:
            from ui.messages import error_text

            self._fail(error_text(error))

    @Slot(CommandResult)
    def _on_result(self, result: CommandResult) -> None:  # a read refused as a whole
        if self._ticket is not None and result.request_id == self._ticket and not result.ok:
            from ui.messages import result_text

            self._fail(result_text(result))

    def _fail(self, text: str) -> None:
        self._ticket = None
        self.error = text
        self.failed.emit(text)


class RegisterMapMenu(QObject):
    """The Help menu's action, the dialog, and what a report with a mismatch says."""

    def __init__(self, window: Any, check: RegisterMapCheck) -> None:
        super().__init__(window)
        self.window = window
        self.check = check
        self.dialog: SelfTestDialog | None = None
        self.action = QAction(window)
        self.action.setObjectName("RegisterMapCheckAction")
        self.action.triggered.connect(self.show_dialog)
        menus = window.menus
        menus.help_menu.insertAction(menus.about_action, self.action)
        check.reported.connect(self._on_report)
        window.installEventFilter(self)
        self.retranslate()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window and event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        return False

    def retranslate(self) -> None:
        self.action.setText(self.tr("Check the controller's &register map…"))
        self.action.setToolTip(
            self.tr(
                "Read the documented registers (nothing is written) and check them against the "
                "register profile"
            )
        )

    @Slot()
    def show_dialog(self) -> SelfTestDialog:
        from ui.dialogs.selftest_dialog import SelfTestDialog

        if self.dialog is None:
            self.dialog = SelfTestDialog(self.check, self.window)
        self.dialog.show()
        self.dialog.raise_()
        if self.check.report is None and not self.check.running:
            self.check.run()
        return self.dialog

    @Slot(object)
    def _on_report(self, report: SelfTestReport) -> None:
        if report.passed or not self.check.after_connect:
            return  # quiet: nothing is off (or the operator asked, and sees the dialog)
        from ui.selftest_words import check_name, fix_text, found_text, summary_text

        def details() -> str:
            lines = [summary_text(report)]
            for line in report.mismatches:
                fix = fix_text(line)
                lines.append(f"{check_name(line)}: {found_text(line)}" + (f" {fix}" if fix else ""))
            return " ".join(lines)

        self.window.event_log.add_event("warning", lambda: self.tr("register map"), details)
        self.window.status_bar.show_message(
            self.tr(
                "The controller's register map does not match the register profile: Help → Check the "
                "controller's register map…"
            )
        )


def install_register_map_check(window: Any) -> RegisterMapCheck:
    """The self-test on ``window`` (its link, its 3D view's robot model, its Help menu)."""
    view3d = getattr(window, "view3d", None)

    def model() -> ArmModel | None:
        return None if view3d is None else view3d.robot.model

    check = RegisterMapCheck(window.link, model, window)
    check.setObjectName("RegisterMapCheck")
    window.register_map_ui = RegisterMapMenu(window, check)
    return check

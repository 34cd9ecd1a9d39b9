"""The register-map self-test's run in the GUI (:class:`RegisterMapCheck`): one
:class:`~app.link.ops.ReadRegisters` of the self-test's blocks submitted to the link after every
connect and on demand -- the reads run in the worker, never on the GUI thread, and nothing is
written -- then the checks (:func:`app.selftest.checks.check_register_map`) against the link's
register profile and the window's robot model. See :mod:`ui.controllers.selftest_watch` for
what the window does with a report.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal, Slot

from app.link.ops import ReadRegisters
from app.link.progress import Progress, RegisterBlocks
from app.link.types import ConnectionState, LinkState, WorkerError
from app.models import CommandResult

if TYPE_CHECKING:
    from app.link.robot_link import RobotLink
    from app.selftest.checks import SelfTestReport
    from app.view3d.kinematics import ArmModel

__all__ = ["RegisterMapCheck"]

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
        link.progressed.connect(self._on_progress)
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

    @Slot(int, object)
    def _on_progress(self, ticket: int, read: Progress) -> None:
        if self._ticket is None or ticket != self._ticket or not isinstance(read, RegisterBlocks):
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

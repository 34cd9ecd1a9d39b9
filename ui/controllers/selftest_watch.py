"""The register-map self-test in the GUI: run by itself after every connect, quietly unless
something is off, and on demand (*Help → Check the controller's register map…*).

:class:`~ui.controllers.register_map_check.RegisterMapCheck` submits one
:class:`~app.link.ops.ReadRegisters` of the self-test's blocks
(:data:`app.selftest.checks.SELFTEST_BLOCKS`) to the link -- the reads run in the worker, never
on the GUI thread, and nothing is written -- then checks what came back against the link's
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

from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, Slot
from PySide6.QtGui import QAction

from ui.controllers.register_map_check import RegisterMapCheck

if TYPE_CHECKING:
    from app.selftest.checks import SelfTestReport
    from app.view3d.kinematics import ArmModel
    from ui.dialogs.selftest_dialog import SelfTestDialog

__all__ = ["RegisterMapMenu", "install_register_map_check"]


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

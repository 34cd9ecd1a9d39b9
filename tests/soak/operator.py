"""The soak's random operator: what a person does with the window, picked by a seeded random
generator, one action every few hundred milliseconds, each one logged.

Every action goes through what the operator would use -- a button's click (or press and release
for a jog button), a menu's QAction, a dock's tab, the language menu -- never through the link
behind the window's back, except :meth:`Operator.connect` (what *File -> Connect...* does once
its dialog is accepted: the soak cannot type the simulator's port into it). A control that is
greyed does nothing, as for the operator. Modal dialogs are answered by
:class:`~tests.soak.answers.Answerer`.
"""

from __future__ import annotations

import random
from collections.abc import Callable
from dataclasses import dataclass

from PySide6.QtCore import QObject, QPoint, Qt, QTimer, Slot
from PySide6.QtGui import QAction
from PySide6.QtTest import QTest
from PySide6.QtWidgets import QAbstractButton, QApplication, QMenu

from app.connection import ConnectionSettings
from app.safety.roles import Role
from ui.main_window import MainWindow

__all__ = ["PASSWORD", "Operator"]

PASSWORD = "soak-pw"  # every role's password in the soak's own role store
PAUSE_S = (0.03, 0.6)  # s between two actions (uniform)
JOG_HELD_S = (0.05, 0.8)  # s a jog button is held
LANGUAGES = ("en", "zh_CN")


@dataclass(frozen=True)
class Move:
    """One kind of action: its weight in the random choice and what it does (returns the log
    line's detail, or None when it could not be done now)."""

    name: str
    weight: int
    run: Callable[[], str | None]


class Operator(QObject):
    """Acts on ``window`` until :meth:`stop`; ``say`` gets one line per action."""

    def __init__(
        self, window: MainWindow, rng: random.Random, say: Callable[[str], None], sim: ConnectionSettings
    ) -> None:
        super().__init__(window)
        self.window = window
        self.rng = rng
        self.say = say
        self.sim = sim
        self.count = 0
        self.by_kind: dict[str, int] = {}
        self._busy = False
        self._held: QAbstractButton | None = None
        self._menu_actions = self._collect_menu_actions()
        self._moves = self._table()
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.act)
        self._release_timer = QTimer(self)
        self._release_timer.setSingleShot(True)
        self._release_timer.timeout.connect(self.release_jog)

    # --- the loop -----------------------------------------------------------------------------
    def start(self) -> None:
        self._schedule()

    def stop(self) -> None:
        self._timer.stop()
        self.release_jog()

    def _schedule(self) -> None:
        self._timer.start(round(1000 * self.rng.uniform(*PAUSE_S)))

    @Slot()
    def act(self) -> None:
        """One random action (none while a dialog is up: the operator is answering it)."""
        if self._busy or QApplication.activeModalWidget() is not None:
            self._schedule()
            return
        move = self.rng.choices(self._moves, weights=[m.weight for m in self._moves])[0]
        self._busy = True  # an action that opens a modal dialog returns when it is answered
        try:
            detail = move.run()
        finally:
            self._busy = False
        if detail is not None:
            self.count += 1
            self.by_kind[move.name] = self.by_kind.get(move.name, 0) + 1
            self.say(f"#{self.count:05d} {move.name}: {detail}")
        self._schedule()

    def _table(self) -> list[Move]:
        return [
            Move("menu", 14, self.menu_action),
            Move("connect", 2, self.connect_link),
            Move("disconnect", 1, self.disconnect_link),
            Move("jog", 12, self.jog),
            Move("step", 5, self.step),
            Move("program", 3, self.program),
            Move("mode", 2, self.mode),
            Move("stop", 5, self.stop_button),
            Move("pause/resume", 3, self.pause_resume),
            Move("teach", 4, self.teach),
            Move("upload", 3, self.upload),
            Move("move to point", 2, self.move_to_point),
            Move("plan", 6, self.plan),
            Move("tab", 6, self.tab),
            Move("dock", 6, self.dock),
            Move("traffic", 6, self.traffic),
            Move("bundle", 2, self.bundle),
            Move("language", 2, self.language),
            Move("role", 3, self.role),
            Move("3d", 3, self.view3d),
        ]

    # --- the link -------------------------------------------------------------------------------
    def connect_link(self) -> str:
        self.window.jog_panel.release_all()
        self.window.connect_with(self.sim)
        return f"connect to {self.sim.host}:{self.sim.port} (as File -> Connect... accepted)"

    def disconnect_link(self) -> str:
        action = self.window.menus.disconnect_action
        action.trigger()
        return f"Disconnect ({'enabled' if action.isEnabled() else 'greyed'})"

    # --- motion ---------------------------------------------------------------------------------
    def jog(self) -> str:
        panel = self.window.jog_panel
        self.release_jog()
        if self.rng.random() < 0.3:
            panel.set_ratio(self.rng.choice((1, 5, 10, 25, 50, 100)))
        axis = self.rng.randrange(panel.axis_count())
        direction = self.rng.choice((-1, 1))
        button = panel.button(axis, direction)
        held = self.rng.uniform(*JOG_HELD_S)
        QTest.mousePress(button, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, QPoint(5, 5))
        self._held = button
        self._release_timer.start(round(held * 1000))
        return f"press axis {axis + 1}{'+' if direction > 0 else '-'} at {panel.ratio} %, for {held:.2f} s"

    @Slot()
    def release_jog(self) -> None:
        button, self._held = self._held, None
        self._release_timer.stop()
        if button is not None:
            QTest.mouseRelease(
                button, Qt.MouseButton.LeftButton, Qt.KeyboardModifier.NoModifier, QPoint(5, 5)
            )

    def step(self) -> str:
        panel = self.window.step_panel
        values = [0.0] * 6
        values[self.rng.randrange(6)] = self.rng.choice((-5.0, -1.0, 1.0, 2.0, 5.0))
        panel.set_values(values)
        panel.move_button.click()
        return f"step {values}"

    def program(self) -> str:
        panel = self.window.program_panel
        button = panel.zero_button if self.rng.random() < 0.3 else panel.run_button
        button.click()
        return button.text()

    def mode(self) -> str:
        bar = self.window.control_bar
        button = self.rng.choice((bar.manual_button, bar.auto_button))
        button.click()
        return button.text()

    def stop_button(self) -> str:
        self.window.control_bar.stop_button.click()
        return "STOP"

    def pause_resume(self) -> str:
        bar = self.window.control_bar
        button = self.rng.choice((bar.pause_button, bar.resume_button))
        button.click()
        return button.text()

    # --- points and plans -------------------------------------------------------------------------
    def teach(self) -> str:
        panel = self.window.points_panel
        action = self.rng.choice((panel.action_teach, panel.action_teach, panel.action_add))
        return self._trigger(action)

    def upload(self) -> str:
        panel = self.window.points_panel
        actions = (
            panel.action_upload_all,
            panel.action_upload_needed,
            panel.action_restore_all,
            panel.action_cancel_upload,
        )
        return self._trigger(self.rng.choice(actions))

    def move_to_point(self) -> str | None:
        panel = self.window.points_panel
        rows = panel.model.rowCount()
        if not rows:
            return None
        panel.select_rows([self.rng.randrange(rows)])
        return self._trigger(panel.action_move_to)

    def plan(self) -> str | None:
        panel = self.window.planner_panel
        plans = panel.plan_view.model().rowCount()
        if plans:
            panel.select_plan(self.rng.randrange(plans))
        actions = (
            panel.action_run,
            panel.action_run,
            panel.action_step,
            panel.action_pause,
            panel.action_resume,
            panel.action_stop,
            panel.action_check,
            panel.action_resume_from,
        )
        return self._trigger(self.rng.choice(actions))

    # --- the window -------------------------------------------------------------------------------
    def menu_action(self) -> str:
        return self._trigger(self.rng.choice(self._menu_actions))

    def tab(self) -> str:
        window = self.window
        tabs = window.work_tabs if self.rng.random() < 0.5 else window.tabs
        index = self.rng.randrange(tabs.count())
        tabs.setCurrentIndex(index)
        return f"{tabs.objectName() or 'motion tabs'} -> {tabs.tabText(index)!r}"

    def dock(self) -> str:
        window = self.window
        dock = self.rng.choice(window.docks.docks)
        what = self.rng.random()
        if what < 0.5:
            dock.raise_()  # its tab clicked
            return f"{dock.objectName()}: shown in front"
        if what < 0.85:
            dock.toggleViewAction().trigger()
            return f"{dock.objectName()}: {'shown' if dock.isVisible() else 'closed'}"
        dock.setFloating(not dock.isFloating())
        return f"{dock.objectName()}: {'floating' if dock.isFloating() else 'docked'}"

    def traffic(self) -> str:
        window = self.window
        if self.rng.random() < 0.4:
            window.traffic_dock.show()
            window.traffic_dock.raise_()
            return "Modbus traffic tab clicked"
        panel = window.traffic_panel
        choice = self.rng.randrange(5)
        if choice == 0:
            panel.pause_button.click()
            return f"capture {'paused' if panel.pause_button.isChecked() else 'on'}"
        if choice == 1:
            panel.hide_polls_check.click()
            return f"hide polls {panel.hide_polls_check.isChecked()}"
        if choice == 2:
            text = self.rng.choice(("", "write", "0x10", "440", "exception"))
            panel.set_filter_text(text)
            return f"filter {text!r}"
        if choice == 3:
            panel.clear_button.click()
            return "clear"
        panel.export_button.click()
        return "export"

    def bundle(self) -> str:
        self.window.safety_menu.bundle_action.trigger()
        return "Write a support bundle..."

    def language(self) -> str:
        code = self.rng.choice(LANGUAGES)
        self.window.menus.language_actions[code].trigger()
        return code

    def role(self) -> str:
        safety = self.window.safety_menu.safety
        role = self.rng.choice(list(Role))
        if role is Role.OPERATOR:
            safety.logout()
        else:
            safety.login(role, PASSWORD)
        return role.name.lower()

    def view3d(self) -> str:
        window = self.window
        panel = window.view3d.panel
        buttons: list[QAbstractButton] = [
            panel.fit_button,
            panel.ortho_button,
            panel.beside_button,
            panel.profile_button,
            panel.dry_bar.play_button,
            panel.dry_bar.stop_button,
            *panel.preset_buttons.values(),
        ]
        button = self.rng.choice(buttons)
        button.click()
        return f"3D {button.text() or button.toolTip()!r}"

    # --- helpers ---------------------------------------------------------------------------------
    def _trigger(self, action: QAction) -> str:
        enabled = action.isEnabled()
        action.trigger()
        return f"{action.text().replace('&', '')!r}{'' if enabled else ' (greyed)'}"

    def _collect_menu_actions(self) -> list[QAction]:
        """Every action of the menu bar's menus (submenus too), but Quit (the soak ends the session)."""
        found: list[QAction] = []
        menus = [m for a in self.window.menuBar().actions() if isinstance(m := a.menu(), QMenu)]
        while menus:
            for action in menus.pop().actions():
                submenu = action.menu()
                if isinstance(submenu, QMenu):
                    menus.append(submenu)
                elif not action.isSeparator() and action is not self.window.menus.quit_action:
                    found.append(action)
        return found

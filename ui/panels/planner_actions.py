"""The planner's actions: created with their shortcuts, worded, and enabled from the presenter's
:class:`~app.plan.presenter.ActionStates`. The panel connects them to its slots."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from PySide6.QtCore import QObject, Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import QWidget

from app.plan.presenter import ActionStates, RunBlocker

# name -> shortcut ("" for none), in the order the panel lists them
SHORTCUTS: dict[str, str] = {
    "add_plan": "",
    "rename_plan": "F2",
    "duplicate_plan": "",
    "delete_plan": "",
    "add_line": "Ctrl+L",
    "add_arc": "Ctrl+Shift+A",
    "delete_segment": "",
    "segment_up": "Alt+Up",
    "segment_down": "Alt+Down",
    "check": "",
    "upload_now": "",
    "run": "F5",
    "run_from": "Shift+F5",
    "step": "F10",
    "pause": "",
    "resume": "",
    "stop": "",
    "resume_from": "",
}

#: The plan edits (engineer and up); the rest (run, step, pause, ...) is the operator's.
EDIT_ACTIONS = frozenset(
    {
        "add_plan",
        "rename_plan",
        "duplicate_plan",
        "delete_plan",
        "add_line",
        "add_arc",
        "delete_segment",
        "segment_up",
        "segment_down",
    }
)


class PlannerActions(QObject):
    """One ``QAction`` per planner command, owned by ``owner`` (shortcuts work inside it)."""

    def __init__(self, owner: QWidget, slots: Mapping[str, Callable[[], Any]]) -> None:
        super().__init__(owner)
        self.all: dict[str, QAction] = {}
        for name, shortcut in SHORTCUTS.items():
            action = QAction(owner)
            if shortcut:
                action.setShortcut(QKeySequence(shortcut))
                action.setShortcutContext(Qt.ShortcutContext.WidgetWithChildrenShortcut)
            action.triggered.connect(slots[name])
            owner.addAction(action)
            self.all[name] = action
        self._tips: dict[str, str] = {}
        self._states: ActionStates | None = None
        self.edit_reason: str | None = None  # role gating: why plan edits are not allowed (None: they are)

    def __getitem__(self, name: str) -> QAction:
        return self.all[name]

    def retranslate(self) -> None:
        texts: dict[str, tuple[str, str]] = {
            "add_plan": (self.tr("Add"), self.tr("Add an empty plan")),
            "rename_plan": (self.tr("Rename"), self.tr("Rename the selected plan (F2)")),
            "duplicate_plan": (self.tr("Duplicate"), self.tr("Copy the selected plan")),
            "delete_plan": (self.tr("Delete"), self.tr("Delete the selected plan (Ctrl+Z to undo)")),
            "add_line": (self.tr("+ Line"), self.tr("Add a line segment after the selection (Ctrl+L)")),
            "add_arc": (self.tr("+ Arc"), self.tr("Add an arc segment after the selection")),
            "delete_segment": (self.tr("Delete"), self.tr("Delete the selected segments")),
            "segment_up": ("▲", self.tr("Move the selected segments up (Alt+Up)")),
            "segment_down": ("▼", self.tr("Move the selected segments down (Alt+Down)")),
            "check": (self.tr("Check"), self.tr("Check the plan from the robot's current pose")),
            "upload_now": (self.tr("Upload now"), self.tr("Upload the points the plan needs")),
            "run": (self.tr("Run"), self.tr("Run the plan from the first segment (F5)")),
            "run_from": (self.tr("Run from here"), self.tr("Run from the selected segment (Shift+F5)")),
            "step": (self.tr("Step"), self.tr("Run one segment, then stop (F10)")),
            "pause": (self.tr("Pause"), self.tr("Pause the motion")),
            "resume": (self.tr("Resume"), self.tr("Resume the paused motion")),
            "stop": (self.tr("Stop"), self.tr("Stop the robot and the run")),
            "resume_from": (self.tr("Resume from segment"), self.tr("Continue the stopped run")),
        }
        for name, (text, tip) in texts.items():
            self.all[name].setText(text)
            self.all[name].setToolTip(tip)
            self._tips[name] = tip
        if self._states is not None:
            self._show_run_blocker(self._states)

    def set_resume_from(self, k: int | None, loop: int | None = None) -> None:
        """``Resume from segment k`` (1-based), ``…, loop i`` when the run has more than one
        loop (``loop``; None: it has one), or the bare text when there is nothing to resume."""
        if k is None:
            text = self.tr("Resume from segment")
        elif loop is None:
            text = self.tr("Resume from segment {k}").format(k=k)
        else:
            text = self.tr("Resume from segment {k}, loop {loop}").format(k=k, loop=loop)
        self.all["resume_from"].setText(text)

    def apply(self, states: ActionStates) -> None:
        enabled = {
            "add_plan": states.add_plan,
            "rename_plan": states.edit_plan,
            "duplicate_plan": states.edit_plan,
            "delete_plan": states.edit_plan,
            "add_line": states.add_segment,
            "add_arc": states.add_segment,
            "delete_segment": states.delete_segment,
            "segment_up": states.segment_up,
            "segment_down": states.segment_down,
            "run": states.run,
            "run_from": states.run_from,
            "step": states.run,
            "pause": states.pause,
            "resume": states.resume,
            "stop": states.stop,
            "resume_from": states.resume_from,
            "upload_now": states.upload_now,
        }
        for name, on in enabled.items():
            gated = self.edit_reason is not None and name in EDIT_ACTIONS
            self.all[name].setEnabled(on and not gated)
            if name in EDIT_ACTIONS:
                self.all[name].setToolTip(self.edit_reason or self._tips.get(name, ""))
        self._states = states
        self._show_run_blocker(states)

    def blocker_text(self, blocker: RunBlocker, first_error: str = "") -> str:
        """Why Run is disabled, in the operator's words ("" when it is not)."""
        if blocker is RunBlocker.CHECKS:
            text = self.tr("Run is disabled: the plan's checks found errors; fix them first")
            return f"{text}\n{first_error[:160]}" if first_error else text
        return {
            RunBlocker.NONE: "",
            RunBlocker.NO_LINK: self.tr("Run is disabled: not connected to the controller"),
            RunBlocker.RUNNING: self.tr("Run is disabled: a run is going"),
            RunBlocker.NO_SEGMENTS: self.tr("Run is disabled: the plan has no segments"),
            RunBlocker.SYNC_BUSY: self.tr("Run is disabled: wait for the points' upload to finish"),
        }[blocker]

    def _show_run_blocker(self, states: ActionStates) -> None:
        """Run, Run from here and Step say in their tooltip why they are disabled."""
        why = self.blocker_text(states.run_blocker, states.first_error)
        for name in ("run", "run_from", "step"):
            tip = self._tips.get(name, "")
            self.all[name].setToolTip(f"{why}\n\n{tip}" if why and tip else why or tip)

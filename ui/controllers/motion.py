"""MotionController: the motion panels' intents become link requests; it gates them too.

The control bar (stop / pause / resume / mode), the jog, step and program panels only emit
intents; this controller sends them through the :class:`~app.link.robot_link.LinkPort`. It
decides when motion controls are enabled (the link connected and writable, from
``link.state``, and no plan running: Stop, Pause and Resume stay while a plan runs) and it is
the dead-man's second hand: any jog ends when the link leaves CONNECTED, when a plan starts
and before a mode change.

Alarm hold: while the controller reports an emergency stop or a servo alarm
(:data:`app.alarm_history.BLOCKING_ALARMS`) the jog, step and program panels and Resume are
disabled, any jog is released, and a jog / step / program intent that still arrives is dropped
(never written). Stop stays enabled whatever happens. ``alarmHoldChanged(bool)`` tells the other
panels that start motion (points' move-to, the planner's run).

Work mode and reduced speed: the program panel is told the controller's mode (its confirmations
name a switch from manual to auto, and only a yes to that lets the request switch it); with the
guard rails installed (:attr:`MotionController.safety`) the jog, step and program panels are told
the caps in force, shown where each speed is set (the link's client applies them to the writes).

The step and program panels are built when their tab is first shown (``ui/window_tabs.py``):
:meth:`MotionController.add_step_panel` / :meth:`~MotionController.add_program_panel` attach one
when it exists, and it gets the gating in force before it can be shown.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, Signal, Slot

from app.alarm_history import blocks_motion
from app.link.link_port import LinkPort
from app.link.ops import (
    GoZero,
    JogPress,
    JogRelease,
    Pause,
    Resume,
    RunProgram,
    SetJogRatio,
    SetMode,
    Step,
    Stop,
)
from app.link.types import ConnectionState, JogRequest, StepFrame
from app.models import ControllerStatus
from app.protocol.enums import ProgramMotionMode, WorkMode
from app.safety.caps import MotionCaps
from ui.controllers.plan_run_controller import PlanRunController
from ui.controllers.safety import SafetyController
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel

if TYPE_CHECKING:  # built when their tab is first shown: not imported before the first paint
    from ui.panels.program_panel import ProgramPanel, ProgramRequest, ZeroRequest
    from ui.panels.step_panel import StepPanel, StepRequest

__all__ = ["MotionController"]


class MotionController(QObject):
    """See the module docstring. ``motionEnabledChanged(bool)``: the link is writable (Pause /
    Resume may go out); the jog / step / program panels are also held while a plan runs."""

    motionEnabledChanged = Signal(bool)
    alarmHoldChanged = Signal(bool)

    def __init__(
        self,
        link: LinkPort,
        control_bar: ControlBar,
        jog: JogPanel,
        step: StepPanel | None,
        program: ProgramPanel | None,
        run_controller: PlanRunController,
        parent: QObject | None = None,
    ) -> None:
        super().__init__(parent)
        self._link = link
        self._bar = control_bar
        self._jog = jog
        self._step: StepPanel | None = None  # attached now or when built (add_step_panel)
        self._program: ProgramPanel | None = None
        self._run_active = False
        self._enabled = link.state.writable
        self._alarm_hold = blocks_motion(link.state.alarms)
        self._safety: SafetyController | None = None  # the guard rails (set by install_safety)

        control_bar.stopRequested.connect(self._on_stop_requested)
        self._runs = run_controller
        control_bar.pauseRequested.connect(self._on_pause_requested)
        control_bar.resumeRequested.connect(self._on_resume_requested)
        control_bar.modeRequested.connect(self._on_mode_requested)
        jog.jogPressed.connect(self._on_jog_pressed)
        jog.jogReleased.connect(self._on_jog_released)
        jog.ratioChanged.connect(self._on_ratio_changed)
        link.state.haltChanged.connect(jog.show_halt)  # "releasing -- the controller has not confirmed"
        jog.show_halt(link.state.halt)
        link.state.connectionChanged.connect(self._on_connection)
        link.state.alarmsChanged.connect(self._on_alarms)
        link.state.statusChanged.connect(self._on_status)
        link.state.connectionChanged.connect(self._on_status)
        run_controller.runningChanged.connect(self._on_run_active)
        self._apply()
        if step is not None:
            self.add_step_panel(step)
        if program is not None:
            self.add_program_panel(program)

    @Slot()
    def _on_stop_requested(self) -> None:
        self._link.submit(Stop())

    @Slot()
    def _on_jog_released(self) -> None:
        self._link.submit(JogRelease())

    @Slot()
    def _on_pause_requested(self) -> None:
        """The window's Pause: a plan run under way is paused as its own Pause would (it then
        holds its next move; a Pause that failed is sent again through it), anything else at the link."""
        if self._runs.can_pause:
            self._runs.pause()
        else:
            self._link.submit(Pause())

    @Slot()
    def _on_resume_requested(self) -> None:
        """The window's Resume: a paused plan run resumes through the run (which refuses while
        the another-master hold lasts, and sends what its pause held back), anything else at the link."""
        if self._runs.running and self._runs.paused:
            self._runs.resume()
        else:
            self._link.submit(Resume())

    def add_step_panel(self, step: StepPanel) -> None:
        """Drive and gate ``step`` from now on (enabled or not at once, as the others)."""
        if self._step is not None:
            raise RuntimeError("the step panel is already attached")
        self._step = step
        step.stepRequested.connect(self._on_step_requested)
        step.set_motion_enabled(self._panels_enabled())
        step.set_pose(self._link.state.pose)
        self._link.state.poseChanged.connect(step.set_pose)
        self._on_caps()

    def add_program_panel(self, program: ProgramPanel) -> None:
        """Drive and gate ``program`` from now on (enabled or not at once, as the others)."""
        if self._program is not None:
            raise RuntimeError("the program panel is already attached")
        self._program = program
        program.programRequested.connect(self._on_program_requested)
        program.goZeroRequested.connect(self._on_go_zero)
        program.set_motion_enabled(self._panels_enabled())
        program.set_caps(self._caps())
        self._on_status()

    @property
    def safety(self) -> SafetyController | None:
        """The guard rails (set once by ``install_safety``): the envelope's checks and caps."""
        return self._safety

    @safety.setter
    def safety(self, safety: SafetyController | None) -> None:
        if self._safety is not None:
            self._safety.capsChanged.disconnect(self._on_caps)
        self._safety = safety
        if safety is not None:
            safety.capsChanged.connect(self._on_caps)
        self._on_caps()

    def _caps(self) -> MotionCaps | None:
        return self._safety.caps if self._safety is not None else None

    @Slot()
    def _on_caps(self) -> None:
        """Show the caps in force where each speed is set (reduced speed, the envelope's jog cap)."""
        safety = self._safety
        caps = self._caps()
        self._jog.set_ratio_cap(
            safety.jog_ratio_cap() if safety is not None else None, reduced=caps is not None
        )
        if self._step is not None:
            self._step.set_caps(caps)
            if safety is not None:  # the offset fields and the keypad follow the envelope's limits
                self._step.set_limits(safety.envelope.joint_limits, safety.envelope.keep_in)
        if self._program is not None:
            self._program.set_caps(caps)

    @Slot()
    def _on_status(self) -> None:
        """The program panel's confirmations name a switch from manual (the mode as last read)."""
        state = self._link.state
        status: ControllerStatus | None = state.status if state.connected else None
        if self._program is not None:
            self._program.set_controller_mode(status.mode if status is not None else None)

    @property
    def motion_enabled(self) -> bool:
        return self._enabled

    @property
    def run_active(self) -> bool:
        return self._run_active

    @property
    def alarm_hold(self) -> bool:
        """An emergency stop or servo alarm is set: motion controls are held (Stop is not)."""
        return self._alarm_hold

    @Slot(int)
    def _on_alarms(self, alarms: int) -> None:
        hold = blocks_motion(alarms)
        if hold == self._alarm_hold:
            return
        self._alarm_hold = hold
        if hold:
            self._jog.release_all()
        self._apply()
        self.alarmHoldChanged.emit(hold)

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        if not connection.connected:
            self._jog.release_all()  # link lost: the worker makes it safe on return
        self._apply()

    @Slot(bool)
    def _on_run_active(self, active: bool) -> None:
        self._run_active = active
        if active:
            self._jog.release_all()
        self._apply()

    def _panels_enabled(self) -> bool:
        """The jog, step and program panels: the link writable, no plan running, no alarm hold."""
        return self._link.state.writable and not self._run_active and not self._alarm_hold

    def _apply(self) -> None:
        enabled = self._link.state.writable
        panels_enabled = self._panels_enabled()
        for panel in (self._jog, self._step, self._program):
            if panel is not None:
                panel.set_motion_enabled(panels_enabled)
        self._bar.set_motion_enabled(enabled)
        self._bar.set_alarm_hold(self._alarm_hold)
        if enabled != self._enabled:
            self._enabled = enabled
            self.motionEnabledChanged.emit(enabled)

    @Slot(object)
    def _on_jog_pressed(self, request: JogRequest) -> None:
        if self._alarm_hold:
            return  # the panel is disabled; an intent already queued is dropped, not written
        safety = self.safety
        if safety is not None:  # the envelope: the ratio capped, a jog over a boundary refused
            request = dataclasses.replace(request, ratio=safety.jog_ratio(request.ratio))
            refused = safety.check_jog(self._link.state.pose, request)
            if refused:
                safety.message.emit(refused)
                return
        self._link.submit(JogPress(request))

    @Slot(float)
    def _on_ratio_changed(self, ratio: float) -> None:
        self._link.submit(SetJogRatio(self.safety.jog_ratio(ratio) if self.safety is not None else ratio))

    @Slot(object)
    def _on_step_requested(self, request: StepRequest) -> None:
        if self._alarm_hold:
            return
        safety, pose = self.safety, self._link.state.pose
        if safety is not None and pose is not None:
            refused = safety.check_step(
                pose, list(request.offsets), joint=request.frame is StepFrame.JOINT, speed=request.speed
            )
            if refused:
                safety.message.emit(refused)
                return
        self._link.submit(Step(request.frame, request.offsets, request.ext_offsets, request.speed))

    @Slot(object)
    def _on_program_requested(self, request: ProgramRequest) -> None:
        if self._alarm_hold:
            return
        self._link.submit(
            RunProgram(
                request.program_id,
                ProgramMotionMode(request.mode),
                request.cycles,
                request.speed_ratio,
                switch_to_auto=request.switch_to_auto,
            )
        )

    @Slot(object)
    def _on_go_zero(self, request: ZeroRequest) -> None:
        if not self._alarm_hold:
            self._link.submit(GoZero(request.axis, switch_to_auto=request.switch_to_auto))

    @Slot(object)
    def _on_mode_requested(self, mode: WorkMode) -> None:
        self._jog.release_all()
        self._link.submit(SetMode(mode))

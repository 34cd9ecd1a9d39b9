"""Measured stopping in the window: times each Stop and each jog release (an observer).

:class:`StopTiming` listens where the operator's intents are (the control bar's Stop, the
menu's Stop and Esc through :meth:`StopTiming.note_stop`, the jog panel's release) and to
every good poll (``RobotState.polled``, with the pose ``RobotState.pose`` holds then), while the
link is connected (a Stop without a link sends nothing: not measured); it sends
nothing and changes nothing of the stop itself (the intents reach the link through
:class:`~ui.controllers.motion.MotionController` as before). The measuring is
:class:`app.safety.stopping.StopWatch`; each result goes to the session's
:class:`~app.safety.stopping.StopLog` (the support bundle's summary), the audit trail (one
``action`` line, ``stop measured``) and ``measured`` (the monitor's "last stop" line).
"""

from __future__ import annotations

import time

from PySide6.QtCore import QObject, QTimer, Signal, Slot

from app.link.state import RobotState
from app.safety.audit import AuditLog
from app.safety.stopping import StopKind, StopLog, StopMeasurement, StopWatch
from ui.panels.control_bar import ControlBar
from ui.panels.jog_panel import JogPanel

__all__ = ["StopTiming"]

AUDIT_COMMAND = {StopKind.STOP: "stop measured", StopKind.JOG_RELEASE: "jog release measured"}


class StopTiming(QObject):
    """See the module docstring. ``measured(StopMeasurement)`` after each measured stop."""

    measured = Signal(object)

    def __init__(
        self, state: RobotState, control_bar: ControlBar, jog: JogPanel, parent: QObject | None = None
    ) -> None:
        super().__init__(parent)
        self._state = state
        self.watch = StopWatch()
        self.log = StopLog()
        #: the audit trail the measurements are written to (set once the guard rails exist)
        self.audit: AuditLog | None = None
        self._clock = time.monotonic
        self._timeout = QTimer(self)  # no poll at all (a lost link): the timeout still ends it
        self._timeout.setSingleShot(True)
        self._timeout.timeout.connect(self._on_timeout)
        # timed from the click, which the bar and the panel note before their signal: the Stop or
        # release goes out in its first slot (the motion controller), this one hears it after
        self._bar, self._jog = control_bar, jog
        control_bar.stopRequested.connect(self._on_stop_button)
        jog.jogReleased.connect(self._on_jog_released)
        state.polled.connect(self._on_polled)

    @Slot()
    def _on_stop_button(self) -> None:
        self.note_stop(self._bar.stop_clicked_at)

    @Slot()
    def _on_jog_released(self) -> None:
        self.note_jog_release(self._jog.released_at)

    def note_stop(self, at: float | None = None) -> None:
        """The operator asked for a Stop (the button, the menu, Esc) at ``at`` (``time.monotonic()``,
        noted before the Stop was sent; None: now)."""
        self._start(StopKind.STOP, at)

    def note_jog_release(self, at: float | None = None) -> None:
        self._start(StopKind.JOG_RELEASE, at)

    def _start(self, kind: StopKind, at: float | None) -> None:
        if not self._state.connected:
            return  # nothing was sent, nothing to see: not measured
        now = self._clock()
        # the click's time, not this slot's: on a loaded machine sending the Stop (the stop line's
        # write, its hand-off) can take milliseconds, and the arm may already rest (stop 29)
        clicked = now if at is None or at > now else at
        age = self._state.age(now)
        self.watch.click(kind, clicked, self._state.pose, None if age is None else now - age)
        self._timeout.start(int(self.watch.timeout * 1000) + 50)

    def cancel(self) -> None:
        """Give up the measurement under way (the window closes)."""
        self._timeout.stop()
        self.watch.cancel()

    @Slot(float)
    def _on_polled(self, when: float) -> None:
        pose = self._state.pose
        if pose is None or not self.watch.measuring:
            return
        result = self.watch.sample(when, pose)
        if result is not None:
            self._done(result)

    @Slot()
    def _on_timeout(self) -> None:
        result = self.watch.expire(self._clock())
        if result is not None:
            self._done(result)
        elif self.watch.measuring:  # the timer fired a little early: look again at the deadline
            deadline = self.watch.deadline or self._clock()
            self._timeout.start(max(1, int((deadline - self._clock()) * 1000) + 1))

    def _done(self, result: StopMeasurement) -> None:
        self._timeout.stop()
        self.log.add(result)
        if self.audit is not None:
            self.audit.record(
                "action", AUDIT_COMMAND[result.kind], args=result.audit_args(), detail=result.text
            )
        self.measured.emit(result)

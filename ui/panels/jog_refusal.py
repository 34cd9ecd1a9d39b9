"""The motion area's refusal line: the latest refusal of a motion, in words, under the jog / step /
program buttons -- where the operator's eyes are when a press does nothing (issue 21).

What it shows (amber, wrapped, hidden while there is nothing to say):

* a motion the guard rails refused before it went out -- a jog press or a step out of the work
  space, a move to a point through a keep-out zone (:attr:`~ui.controllers.safety.
  SafetyController.motionRefused`), and the jog guard's own stop ("Jog stopped before the limit:
  X = 550.2 ...");
* a motion the link refused before the wire (a :class:`~app.link.types.WorkerError` or a
  :class:`~app.models.CommandResult` of a motion whose reason is one of :data:`REFUSAL_CODES`:
  reduced speed and go to zero, manual mode, another master's hold, a stop not yet confirmed, a
  motion still under way).

The rule for taking it away: the **next accepted motion** clears it (a jog, step or move the guard
rails let go; a motion command the controller finished without refusing it), and so does time:
a refusal shown for :data:`REFUSAL_SHOWN_MS` is stale (the operator has moved on; the status dock's
*Last command* and the event log keep it). A lost connection clears it too (the motion banner then
says why nothing moves: :class:`~ui.window_column.ControlColumn`). A newer refusal replaces it.
The text is kept as a way to word it, not as words: a language change re-words it in place.

Room: under the jog buttons at 1280×800 the six rows have a few pixels to spare, so while the
line shows, the jog panel's keys hint and its standing "hold to move" line give it their height
(:meth:`~ui.panels.jog_panel.JogPanel.make_room`; an unconfirmed stop is never hidden).
"""

from __future__ import annotations

from collections.abc import Callable

from PySide6.QtCore import QEvent, Qt, QTimer, Signal, Slot
from PySide6.QtWidgets import QLabel, QSizePolicy, QWidget

from app.link.types import WorkerError
from app.models import CommandResult
from app.protocol.enums import RunCommand
from ui.palette import COLOR_WARN, COLOR_WARN_BG, COLOR_WARN_DARK

__all__ = ["REFUSAL_CODES", "REFUSAL_SHOWN_MS", "MotionRefusalLine", "Words"]

#: How long a refusal stays in the motion area when nothing else clears it (ms)
REFUSAL_SHOWN_MS = 30_000

#: A way to word the refusal in the language in force (called again on a language change)
Words = Callable[[], str]

#: The link's refusals of a motion before anything was sent (reason codes, app/errors.py and
#: app/link): shown in the motion area; any other result is left to *Last command*.
REFUSAL_CODES = frozenset(
    {
        "reduced_speed_refused",
        "manual_mode",
        "foreign_master",
        "controller_busy",
        "halt_unconfirmed",
        "envelope_refused",
        "busy",
    }
)
# the motions (a result naming one of these, by its 440 command or its operation, is a motion's)
_MOTION_COMMANDS = frozenset(
    {RunCommand.RUN_PROGRAM, RunCommand.STEP_JOINT, RunCommand.STEP_BASE, RunCommand.MOVE_TO_POINT}
)
_MOTION_OPERATIONS = frozenset({"jog", "step", "go to zero", "run program", "move to point"})

_STYLE = (
    f"QLabel {{ background: {COLOR_WARN_BG}; color: {COLOR_WARN_DARK}; border: 1px solid {COLOR_WARN};"
    " border-radius: 3px; padding: 1px 3px; font-weight: bold; }"
)


def is_motion_result(result: CommandResult) -> bool:
    """``result`` is a motion's (a step, a move, a program, go to zero, a jog)."""
    if result.command is not None and result.command in _MOTION_COMMANDS:
        return True
    operation = result.reason.args.get("operation") if result.reason is not None else None
    return isinstance(operation, str) and operation in _MOTION_OPERATIONS


class MotionRefusalLine(QLabel):
    """See the module docstring. ``show_words(words)`` shows a refusal, ``clear_refusal()`` takes
    it away; ``on_result`` follows the link's results (refusals shown, a finished motion clears).
    ``shownChanged(bool)``: the line appeared or went (the jog panel makes room for it)."""

    shownChanged = Signal(bool)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("MotionRefusal")
        self.setWordWrap(True)
        self.setAlignment(Qt.AlignmentFlag.AlignLeft | Qt.AlignmentFlag.AlignVCenter)
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Minimum)
        self.setStyleSheet(_STYLE)
        self.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self._words: Words | None = None
        self._stale = QTimer(self)
        self._stale.setSingleShot(True)
        self._stale.timeout.connect(self.clear_refusal)
        self.setVisible(False)

    @property
    def shown(self) -> bool:
        """A refusal is being shown."""
        return self._words is not None

    def show_words(self, words: Words) -> None:
        """Show the refusal ``words`` gives (replacing any shown) for :data:`REFUSAL_SHOWN_MS`."""
        was = self.shown
        self._words = words
        self._render()
        self.setVisible(True)
        self._stale.start(REFUSAL_SHOWN_MS)
        if not was:
            self.shownChanged.emit(True)

    @Slot()
    def clear_refusal(self) -> None:
        """The next accepted motion, or time: nothing to say any more."""
        self._stale.stop()
        was = self.shown
        self._words = None
        self.setText("")
        self.setToolTip("")
        self.setVisible(False)
        if was:
            self.shownChanged.emit(False)

    @Slot(object)
    def on_result(self, result: CommandResult) -> None:
        """A motion refused by the link before the wire is shown; a motion the controller carried
        out (or took and ended by itself) clears the line; other results leave it as it is."""
        if not is_motion_result(result):
            return
        reason = result.reason
        if not result.ok and reason is not None and reason.code in REFUSAL_CODES:
            from ui.messages import result_text  # the product's words: read when first needed

            self.show_words(lambda: result_text(result))
        elif result.ok:
            self.clear_refusal()

    @Slot(WorkerError)
    def on_error(self, error: WorkerError) -> None:
        """A motion the link refused before anything was sent is shown; other errors are not
        refusals of a motion (the status bar and the event log have them)."""
        reason = error.reason
        if error.operation in _MOTION_OPERATIONS and reason is not None and reason.code in REFUSAL_CODES:
            from ui.messages import error_text  # (each of these sentences names the motion)

            self.show_words(lambda: error_text(error))

    def _render(self) -> None:
        text = self._words() if self._words is not None else ""
        self.setText(text)
        self.setToolTip(text)

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange and self._words is not None:
            self._render()
        super().changeEvent(event)

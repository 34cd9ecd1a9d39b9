"""Garbage collection in the GUI process: on the GUI thread only, from a timer.

Why (issue 18). CPython collects in whichever thread's allocation crosses the threshold, and a
pass frees every unreachable cycle, whoever made it. In the GUI process that thread was often the
link's worker (it allocates at every poll): 1 pass in 30 s of an idle window, 13-29 in a working
session. A Qt object owned by Python (no parent: a pyqtgraph item or menu taken off its scene, a
Pending, a helper made by a slot) in such a cycle was then destroyed on the worker thread; Qt
objects must be destroyed in their own thread (their timers, posted events and widgets), and the
issue's crash ("RobotWorker: segfault ... in libQt6Core") has exactly that signature.

So the GUI process keeps automatic collection off for its whole run (from the start:
:class:`~ui.startup_gc.StartupGcPause`) and :class:`GuiThreadCollector` collects from a timer in
the GUI thread: every :data:`GC_CHECK_MS` it looks at the allocation counts and collects the
generation CPython itself would (its thresholds, ``gc.get_threshold()``). The objects alive when it
starts (after the first paint: the window, the modules) are frozen (``gc.freeze``): they live for
the session, and later full passes need not walk them. :meth:`GuiThreadCollector.stop` unfreezes
them; the pause gives automatic collection back as it found it.
"""

from __future__ import annotations

import gc

from PySide6.QtCore import QObject, QTimer, Slot

from ui.startup_gc import StartupGcPause

__all__ = ["GC_CHECK_MS", "GuiThreadCollector", "due_generation"]

#: ms between two looks at the allocation counts. An idle window makes ~3 generation-0 passes'
#: worth of allocations a second (measured: 102 automatic passes in 30 s), so one look per
#: 250 ms collects about as often as CPython would; a look with nothing due costs microseconds.
GC_CHECK_MS = 250


def due_generation(counts: tuple[int, int, int], thresholds: tuple[int, ...]) -> int | None:
    """The generation CPython's automatic collection would collect now (None: none is due):
    once generation 0 has passed its threshold, the oldest generation past its own. (CPython also
    holds back a full pass until the long-lived objects grew by a quarter; that count is not
    visible from Python, and the frozen start-up objects keep full passes short anyway.)"""
    if not thresholds or thresholds[0] <= 0 or counts[0] <= thresholds[0]:
        return None
    for generation in (2, 1):
        if counts[generation] > thresholds[generation]:
            return generation
    return 0


class GuiThreadCollector(QObject):
    """Collects garbage from a timer of the thread it lives in (the GUI thread); see the module
    docstring. ``pause`` is the start-up pause that switched automatic collection off: this
    collector runs only when that pause will give it back (the process collected before)."""

    def __init__(
        self, pause: StartupGcPause, parent: QObject | None = None, *, check_ms: int = GC_CHECK_MS
    ) -> None:
        super().__init__(parent)
        self._pause = pause
        self._timer = QTimer(self)
        self._timer.setInterval(check_ms)
        self._timer.timeout.connect(self.collect_due)
        self._frozen = False
        self._stopped = False
        self.passes = 0  # collections run by this collector

    @property
    def running(self) -> bool:
        return self._timer.isActive()

    @Slot()
    def start(self) -> None:
        """From now on (once the window is up): the objects alive now frozen, collection by the
        timer. Does nothing a second time, after :meth:`stop`, or when the process had
        automatic collection off before the pause (it chose no collection)."""
        if self._stopped or self._timer.isActive() or not self._pause.pausing:
            return
        gc.freeze()
        self._frozen = True
        self._timer.start()

    @Slot()
    def collect_due(self) -> int | None:
        """Collect the generation that is due (see :func:`due_generation`), here; which one."""
        generation = due_generation(gc.get_count(), gc.get_threshold())
        if generation is not None:
            gc.collect(generation)
            self.passes += 1
        return generation

    def stop(self) -> None:
        """No more collections by the timer; the frozen objects back in the oldest generation.
        Automatic collection comes back with the pause's ``resume``."""
        self._stopped = True
        self._timer.stop()
        if self._frozen:
            self._frozen = False
            gc.unfreeze()

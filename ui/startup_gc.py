"""The garbage collector paused over start-up, resumed once the window is on screen.

Start-up (importing the window's modules, then building the window up to its first paint)
allocates tens of thousands of objects (classes, functions, Qt enums, widget wrappers) and frees
almost none: each collection the allocation count triggers walks the growing heap and finds
next to nothing (measured from importing ui.main to the first paint on a loaded 2-core machine:
44 passes, ~13 ms CPU; paused, 2 passes, ~8 ms). ``ui/main.py`` imports the window's modules in
:func:`gc_paused` with ``freeze``: what they made is frozen, so the first collection after them
does not walk it (that walk was ~6 ms of the 8), and builds the window in a :class:`StartupGcPause`
until the first paint. :class:`StartupGcPause` turns automatic collection off for such a stretch;
:meth:`~StartupGcPause.resume` turns it back on (once, and only if it was on: a process that
switched the collector off itself keeps it off). Nothing is lost meanwhile: objects in cycles
wait for the first collection after the pause.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["StartupGcPause", "gc_paused"]


class StartupGcPause:
    """Automatic garbage collection off from its creation until :meth:`resume`."""

    def __init__(self) -> None:
        self._resume = gc.isenabled()
        gc.disable()

    @property
    def pausing(self) -> bool:
        """The pause is on and will turn collection back on (it was on before)."""
        return self._resume

    def resume(self) -> None:
        """Collection back on (if it was on before the pause); later calls do nothing."""
        if self._resume:
            self._resume = False
            gc.enable()


@contextmanager
def gc_paused(*, freeze: bool = False) -> Iterator[None]:
    """Automatic garbage collection off inside the ``with`` block. With ``freeze`` the objects
    alive when it ends are frozen first (``gc.freeze``): made to live for the process (a
    program's modules), they are then not walked by the first collection after the block
    (measured ~6 ms for the window's modules, before the first paint) nor by later full ones.
    Frozen at the end of a block ended by an error too: what it imported stays imported."""
    pause = StartupGcPause()
    try:
        yield
    finally:
        if freeze:
            gc.freeze()
        pause.resume()

"""Signals for the command-line servers' main loops (``teachpad-sim``, its replay, the gateway),
noted by a handler that takes no lock.

A Python signal handler runs in the main thread between two of its bytecodes -- also between two
where that thread holds a lock. The servers' handlers were ``done.set()`` on the
``threading.Event`` their main loop waits on (``while not done.wait(0.2)``). ``Event.wait`` takes
the Event's lock (a plain ``Lock``) again when its 0.2 s are up and gives it back a few bytecodes
later; a signal handled in between ran ``set``, which waited for that same lock, held by the same
thread, forever: the process never stopped, and a second SIGTERM met the same wait. The window is a
few microseconds every 0.2 s on a quiet machine and milliseconds when the thread is descheduled in
it: ``teachpad-sim`` ignored a Ctrl-C in a suite run beside two busy loops (stop 30), and this is the
likely cause of ``teachpad-gateway`` outliving a SIGTERM once at stop 28.

:class:`SignalNote`'s handler only counts (an attribute written, no lock taken, nothing logged);
the main loop, which wakes every period anyway, reads the count: a signal is acted on within one
period of the loop (0.2 s), as the old ``set`` would have been at best.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable
from types import FrameType

__all__ = ["SignalNote", "stop_signals"]

_Handler = Callable[[int, FrameType | None], object] | int | signal.Handlers | None


def stop_signals() -> tuple[signal.Signals, ...]:
    """The signals that stop a server cleanly: Ctrl-C and SIGTERM (``terminate()`` on POSIX; on
    Windows a hard kill, no handler), and Windows' Ctrl-Break (SIGBREAK) where there is one."""
    ctrl_break: signal.Signals | None = getattr(signal, "SIGBREAK", None)
    return (signal.SIGINT, signal.SIGTERM) + ((ctrl_break,) if ctrl_break is not None else ())


class SignalNote:
    """``signals`` noted while installed: how many came (:attr:`count`) and the last one
    (:attr:`signum`). Installed only from the main thread (elsewhere Python cannot install a
    handler: nothing is noted then, and :meth:`restore` does nothing)."""

    def __init__(self, signals: tuple[signal.Signals, ...]) -> None:
        self._signals = signals
        self._previous: dict[signal.Signals, _Handler] = {}
        #: how many of the signals came since :meth:`install` (the handler's only write)
        self.count = 0
        #: the number of the last one (None before the first)
        self.signum: int | None = None
        self._taken = 0

    def install(self) -> SignalNote:
        if threading.current_thread() is threading.main_thread():
            for sig in self._signals:
                self._previous[sig] = signal.signal(sig, self._note)
        return self

    def restore(self) -> None:
        """The handlers that were there before :meth:`install`."""
        previous, self._previous = self._previous, {}
        for sig, handler in previous.items():
            signal.signal(sig, handler)

    def _note(self, signum: int, _frame: FrameType | None) -> None:
        # No lock here, nor anything that takes one (logging, Event.set, print): see the docstring.
        self.signum = signum
        self.count += 1

    @property
    def came(self) -> bool:
        """At least one of the signals came."""
        return self.count > 0

    def take(self) -> bool:
        """One or more came since the last ``take`` (a signal that repeats its meaning: SIGHUP)."""
        count = self.count
        if count == self._taken:
            return False
        self._taken = count
        return True

    def wait(self, period: float, done: threading.Event | None = None) -> bool:
        """Wait ``period`` s (less when ``done`` is set meanwhile); True when a signal came or
        ``done`` is set (another way to stop: the end of stdin, a ``quit`` typed)."""
        if done is None:
            time.sleep(period)
            return self.came
        return done.wait(period) or self.came

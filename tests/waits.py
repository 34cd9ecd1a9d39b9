"""Bounded waits for tests on child processes, their pipes and threads.

Every wait has a deadline and, when it passes, fails the test saying what did not happen (and a
child is killed, never left behind). pytest-timeout would end most of these waits too, but only
after its 120 s, without saying what was awaited, and a stuck child would outlive the test."""

from __future__ import annotations

import queue
import subprocess
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO, Any

import pytest

LOOP_DEADLINE = 40.0  # s for an in-process ``teachpad`` run (main()); a healthy one takes 1-5 s
LOOP_DEADLINE_EXIT = 97  # what the loop returns when the deadline ended it
CHILD_TIMEOUT = 30.0  # s for a child process to do its part (a loaded machine starts Python slowly)
THREAD_TIMEOUT = 10.0  # s for a test's helper thread to end


def wait_child(proc: subprocess.Popen[Any], what: str, timeout: float = CHILD_TIMEOUT) -> int:
    """``proc``'s exit code; kills it and fails when it has not ended within ``timeout``."""
    try:
        return proc.wait(timeout)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout)
        pytest.fail(f"{what} did not end within {timeout:g} s (killed)", pytrace=False)


def kill_child(proc: subprocess.Popen[Any], timeout: float = CHILD_TIMEOUT) -> None:
    """Kill ``proc`` when it still runs, reap it (bounded) and close its pipes."""
    if proc.poll() is None:
        proc.kill()
    try:
        proc.wait(timeout)
    finally:
        for stream in (proc.stdin, proc.stdout, proc.stderr):
            if stream is not None:
                stream.close()


def read_line(stream: IO[Any], what: str, timeout: float = CHILD_TIMEOUT) -> Any:
    """One line from a child's pipe (``""`` / ``b""`` at its end); fails when none came in time.
    The read runs in a daemon thread: it ends when the child ends and its pipe closes."""
    lines: queue.Queue[tuple[Any, BaseException | None]] = queue.Queue()

    def read() -> None:
        try:
            lines.put((stream.readline(), None))
        except BaseException as exc:  # handed to the test's thread
            lines.put((None, exc))

    threading.Thread(target=read, name="test-read-line", daemon=True).start()
    try:
        line, error = lines.get(timeout=timeout)
    except queue.Empty:
        pytest.fail(f"{what}: no line within {timeout:g} s", pytrace=False)
    if error is not None:
        raise error
    return line


def join(thread: threading.Thread, what: str = "", timeout: float = THREAD_TIMEOUT) -> None:
    """Join ``thread``; fails when it still runs after ``timeout``."""
    thread.join(timeout)
    assert not thread.is_alive(), f"{what or thread.name} did not end within {timeout:g} s"


@contextmanager
def loop_deadline(what: str, seconds: float = LOOP_DEADLINE) -> Iterator[None]:
    """Bound a block that runs the application's event loop (``app.exec()``, e.g. main()): after
    ``seconds`` the loop is ended (``QApplication.exit``) and the test fails saying so. A SIGALRM
    (pytest-timeout) cannot do that: its exception is raised inside a slot and swallowed."""
    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QApplication

    fired: list[bool] = []

    def end_the_loop() -> None:
        fired.append(True)
        QApplication.exit(LOOP_DEADLINE_EXIT)

    timer = QTimer()
    timer.setSingleShot(True)
    timer.timeout.connect(end_the_loop)
    timer.start(round(seconds * 1000))
    try:
        yield
    finally:
        timer.stop()
    assert not fired, f"{what} did not leave its event loop within {seconds:g} s: the test ended it"

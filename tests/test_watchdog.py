"""The suite's last line of defence (tests/conftest.py): a test that hangs where pytest-timeout
cannot end it ends the run within minutes, naming the test. Checked on a pytest run in a child
process with the watchdog's time cut to seconds; the hanging tests below run only there."""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import HUNG_EXIT_CODE
from tests.waits import CHILD_TIMEOUT

ROOT = Path(__file__).resolve().parents[1]
HANG = "TEACHPAD_TEST_HANG_HERE"
if HANG in os.environ:  # collected only in the child runs below: these hang on purpose

    def test_hangs_in_a_qt_event_loop(qtbot: object) -> None:
        from PySide6.QtCore import QEventLoop

        QEventLoop().exec()  # nothing ends it, and no SIGALRM can

    def test_hangs_in_c_holding_the_gil() -> None:
        # a C call that blocks with the GIL held, and that no signal interrupts: a mutex locked twice
        libc = ctypes.PyDLL(None)  # PyDLL: the GIL stays held during the call
        mutex = ctypes.create_string_buffer(128)  # zeroes: PTHREAD_MUTEX_INITIALIZER (a normal mutex)
        libc.pthread_mutex_lock(mutex)
        libc.pthread_mutex_lock(mutex)  # deadlock: no Python thread runs again


def _run_hanging(test: str, hung_after: float, backstop: float) -> subprocess.CompletedProcess[str]:
    env = {
        **os.environ,
        HANG: "1",
        "TEACHPAD_TEST_HUNG_AFTER": str(hung_after),
        "TEACHPAD_TEST_HUNG_BACKSTOP": str(backstop),
        "QT_QPA_PLATFORM": "offscreen",
    }
    argv = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--timeout=1", "--no-cov"]
    return subprocess.run(
        [*argv, f"tests/test_watchdog.py::{test}"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=CHILD_TIMEOUT + hung_after + backstop,
        check=False,
    )


@pytest.mark.timeout(90)
def test_a_test_hung_in_a_qt_loop_ends_the_run_naming_it() -> None:
    done = _run_hanging("test_hangs_in_a_qt_event_loop", hung_after=3.0, backstop=30.0)
    assert done.returncode == HUNG_EXIT_CODE, done.stderr[-2000:]
    last = done.stderr.strip().splitlines()[-1]
    assert last == "HUNG: tests/test_watchdog.py::test_hangs_in_a_qt_event_loop"
    assert "QEventLoop().exec()" in done.stderr  # where the main thread was


@pytest.mark.timeout(90)
def test_a_test_hung_holding_the_gil_still_ends_the_run() -> None:
    done = _run_hanging("test_hangs_in_c_holding_the_gil", hung_after=2.0, backstop=2.0)
    assert done.returncode == 1, done.stderr[-2000:]  # faulthandler's exit
    assert "Timeout (" in done.stderr and "test_hangs_in_c_holding_the_gil" in done.stderr

"""Ctrl-C to a real ``teachpad-cli`` child: :func:`interrupt_cli` and how the child is started.

Why the child runs without coverage's tracer (:data:`COVERAGE_STARTUP_VARS` are dropped from
its environment): ``make test`` measures subprocesses too (``[tool.coverage.run] patch =
["subprocess"]`` sets ``COVERAGE_PROCESS_CONFIG``, the ``.pth`` file coverage installs starts
the tracer in every Python child). Coverage's C tracer calls ``Collector.lock_data`` (Python:
``self.data_lock.acquire()``, a plain ``threading.Lock``) on function calls; a SIGINT handled
right after that ``acquire()`` raises KeyboardInterrupt inside ``lock_data`` with the lock held,
and the next traced call blocks on it for ever: the child never ends and prints nothing. That was
``test_ctrl_c_is_interrupted``'s CI timeout. Found by force: SIGINT to CLI children right
after motion, the simulator's answers jittered, two busy loops beside: under coverage 2 of 212
children hung, both in ``coverage/collector.py`` ``lock_data``; without coverage none of several
hundred. In a loop of calls into ``app/`` under coverage, 14 % of the KeyboardInterrupts a
signal handler raised left that lock held. Nothing of the CLI is involved, so these children run
untraced; what they ran after Ctrl-C is measured in-process (``tests/cli/test_ctrl_c.py``).
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
# s for a teachpad-cli child to get going, or to wind down after Ctrl-C: generous, a loaded
# machine (load 12 on 2 cores) took more than 10 s
CHILD_TIMEOUT = 30.0

#: What starts coverage's tracer in a Python child (coverage's .pth file reads them).
COVERAGE_STARTUP_VARS = ("COVERAGE_PROCESS_START", "COVERAGE_PROCESS_CONFIG")

_WITH_CTRL_C = (
    "import runpy, signal; signal.signal(signal.SIGINT, signal.default_int_handler); "
    "runpy.run_module('app.cli.main', run_name='__main__')"
)


def untraced_env() -> dict[str, str]:
    """This process's environment without what would start coverage's tracer in a child."""
    return {k: v for k, v in os.environ.items() if k not in COVERAGE_STARTUP_VARS}


def ctrl_c_child(port: int, args: list[str]) -> list[str]:
    """The command line of a teachpad-cli child that takes Ctrl-C.

    The child gets Python's own Ctrl-C handler back: a test runner started in the background
    (``pytest ... &`` from a script) has SIGINT ignored, its children inherit that, and Python
    then leaves Ctrl-C ignored -- the CLI would never see it (right for a background job).
    ``-X faulthandler``: a child that does not end after Ctrl-C dumps where it is (SIGABRT)."""
    return [sys.executable, "-X", "faulthandler", "-c", _WITH_CTRL_C, "--port", str(port), *args]


def interrupt_cli(csim: Any, args: list[str], started: Callable[[Any], bool]) -> tuple[int, str]:
    """Run teachpad-cli in a subprocess (untraced, see the module), press Ctrl-C once
    ``started(state)``; (exit code, stderr)."""
    proc = subprocess.Popen(
        ctrl_c_child(csim.port, args),
        cwd=ROOT,
        env=untraced_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert csim.wait_for(started, CHILD_TIMEOUT)
        proc.send_signal(signal.SIGINT)
        try:
            _, err = proc.communicate(timeout=CHILD_TIMEOUT)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGABRT)  # every thread's stack to stderr, then it ends
            _, err = proc.communicate(timeout=CHILD_TIMEOUT)
            pytest.fail(f"teachpad-cli did not end {CHILD_TIMEOUT:g} s after Ctrl-C; where it was:\n{err}")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate(timeout=CHILD_TIMEOUT)
    return proc.returncode, err

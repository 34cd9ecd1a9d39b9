"""``teachpad --sim``: the simulator runs in its own process, stops with the window, and stops by
itself when the GUI process dies (its stdin pipe closes)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import pytest

from tests.waits import kill_child, read_line, wait_child
from ui.main import SimProcess

pytestmark = pytest.mark.timeout(60)
ROOT = Path(__file__).resolve().parents[2]


def _gone(pid: int, timeout: float) -> bool:
    """True once process ``pid`` has exited (polled: it is not our child)."""
    import os

    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        try:  # a zombie of an exited parent is reaped by init; read its state
            state = Path(f"/proc/{pid}/stat").read_text().split()[2]
            if state == "Z":
                return True
        except OSError:
            return True
        time.sleep(0.05)
    return False


def test_the_simulator_process_answers_and_stops_cleanly(make_client: Any) -> None:
    sim = SimProcess.start()
    try:
        assert sim.process.pid != 0 and sim.port > 0
        client = make_client(port=sim.port)
        assert client.read_status().alarms == 0
        client.close()
    finally:
        code = sim.stop()
    assert code == 0  # stopped by itself when its stdin closed, not killed


@pytest.mark.skipif(sys.platform == "win32", reason="reads /proc")
def test_the_simulator_stops_when_the_gui_process_dies() -> None:
    parent = subprocess.run(
        [
            sys.executable,
            "-c",
            textwrap.dedent("""
            import os
            from ui.main import SimProcess
            sim = SimProcess.start()
            print(sim.process.pid, flush=True)
            os._exit(3)  # a crash: no stop(), no cleanup
        """),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
    )
    assert parent.returncode == 3, parent.stderr
    child = int(parent.stdout.split()[0])
    assert _gone(child, 10.0)


def test_the_simulator_exits_quietly_when_the_window_goes_away() -> None:
    """The GUI gone (closed, killed, crashed) closes both pipes: the child stops by itself and
    its last line meets a pipe nobody reads -- no BrokenPipeError traceback, exit code 0."""
    command, env = SimProcess.command()  # started as the GUI starts it
    child = subprocess.Popen(
        command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        assert child.stdout is not None and child.stdin is not None and child.stderr is not None
        assert "listening on" in read_line(child.stdout, "the simulator's port")
        child.stdout.close()  # the GUI's reader is gone ...
        child.stdin.close()  # ... and so is its end of the stdin pipe: the child stops itself
        code = wait_child(child, "the simulator after its parent went away")
        errors = child.stderr.read()
    finally:
        kill_child(child)
    assert "Traceback" not in errors and "BrokenPipeError" not in errors, errors
    assert "Exception ignored" not in errors, errors
    assert code == 0, errors


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_the_simulator_stops_cleanly_on_ctrl_c_with_the_window_still_there() -> None:
    """Ctrl-C in the terminal of ``teachpad --sim`` reaches the child too, while its stdin watch
    still waits: it stops with exit code 0 (it aborted at exit: "Fatal Python error:
    _enter_buffered_busy", the watch held sys.stdin's lock)."""
    import signal

    command, env = SimProcess.command()
    child = subprocess.Popen(
        command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    try:
        assert child.stdout is not None and child.stderr is not None
        assert "listening on" in read_line(child.stdout, "the simulator's port")
        child.send_signal(signal.SIGINT)
        code = wait_child(child, "the simulator after Ctrl-C")
        errors = child.stderr.read()
    finally:
        kill_child(child)
    assert "Fatal Python error" not in errors and "Traceback" not in errors, errors
    assert code == 0, errors

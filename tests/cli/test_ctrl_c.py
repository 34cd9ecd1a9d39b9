"""Ctrl-C in teachpad-cli: the stop after it (in-process, deterministic) and the Ctrl-C children.

The children that get a real SIGINT (``interrupt_cli``, tests/cli/ctrl_c.py) run without
coverage's tracer: a SIGINT handled inside the tracer's ``lock_data`` leaves coverage's lock held
and the child hangs for ever (the CI timeout of ``test_ctrl_c_is_interrupted``). The code the
children ran after Ctrl-C is measured here instead: ``wait_motion`` gets its KeyboardInterrupt
from the motion it runs, against the real simulator over a real socket.
"""

from __future__ import annotations

import argparse
import io
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from app.cli import controller, run_plan
from app.cli.context import CliContext, sigint_deferred, wait_motion
from app.cli.exit_codes import ExitCode
from app.cli.main import build_parser
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.link.transport import TrafficRecord
from app.link.types import StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.protocol.enums import ProgramState
from tests.cli.ctrl_c import CHILD_TIMEOUT, COVERAGE_STARTUP_VARS, ROOT, interrupt_cli, untraced_env


def _ctx(sim: Any, *, timeout: float = 5.0, monitor_only: bool = False) -> CliContext:
    """A context whose client talks to ``sim`` (a request timeout no loaded machine reaches)."""
    settings = ConnectionSettings(port=sim.port, timeout=timeout, monitor_only=monitor_only)
    return CliContext(argparse.Namespace(), settings, out=io.StringIO(), err=io.StringIO())


def _interrupted_step(ctx: CliContext, sim: Any) -> CommandResult:
    """A slow joint step that is under way and seen so by the client, then Ctrl-C (as the poll
    loop gets it)."""
    client = ctx.client
    client.step(StepFrame.JOINT, [90.0, 0, 0, 0, 0, 0], speed=1.0, wait=False)
    tracker = client.last_tracker
    assert tracker is not None and sim.wait_for(lambda s: s.moving, 5.0)
    deadline = time.monotonic() + 5.0
    while not tracker.acknowledged and time.monotonic() < deadline:
        assert client.poll(tracker) is None
    assert tracker.acknowledged  # the step was taken: one stop is enough (see the next test)
    raise KeyboardInterrupt


# --- the children that get SIGINT run untraced ---------------------------------------------------


def test_a_ctrl_c_child_runs_without_coverage_tracing(
    sim_factory: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What would start coverage in a child (as ``make test`` sets it) does not reach it."""
    monkeypatch.setenv("COVERAGE_PROCESS_START", str(ROOT / "pyproject.toml"))
    monkeypatch.setenv("COVERAGE_FILE", str(tmp_path / ".coverage"))
    assert not set(COVERAGE_STARTUP_VARS) & set(untraced_env())
    sim = sim_factory(command_latency=0.02)
    code, err = interrupt_cli(sim, ["step", "--frame", "joint", "J1=90", "--speed", "1"], lambda s: s.moving)
    assert code == ExitCode.INTERRUPTED, err
    assert list(tmp_path.iterdir()) == []  # a traced child writes its .coverage.* file at exit


# --- wait_motion: the stop after Ctrl-C ----------------------------------------------------------


def test_ctrl_c_in_a_motion_stops_it_on_a_fresh_link(sim_factory: Any) -> None:
    sim = sim_factory(command_latency=0.02)
    ctx = _ctx(sim)
    # (function, register, the Ctrl-C handler) per request; from the frame itself: the observer runs
    # after the send, when the simulator (another thread) may already have stored it -- counting its
    # stop writes here failed CI once
    seen: list[tuple[int, int, object]] = []

    def observe(record: TrafficRecord) -> None:
        if record.direction == "tx":
            function, register = record.frame[7], int.from_bytes(record.frame[8:10], "big")  # after MBAP
            seen.append((function, register, signal.getsignal(signal.SIGINT)))

    before = signal.getsignal(signal.SIGINT)
    try:
        ctx.client.add_observer(observe)
        links = ctx.client.stats.reconnects
        with pytest.raises(KeyboardInterrupt):
            wait_motion(ctx, lambda: _interrupted_step(ctx, sim))
        assert ctx.err.getvalue() == "teachpad-cli: warning: interrupted: stop sent\n"  # type: ignore[attr-defined]
        assert sim.writes_to(registers.REG_STOP)[-1].values == (1,)
        assert sim.wait_for(lambda s: not s.moving, 2.0)
        # the half-done link was closed: the stop went out on a new connection, with Ctrl-C ignored
        assert ctx.client.stats.reconnects == links + 1
        # the last request was the one stop (0x06 to 441), sent with Ctrl-C ignored
        assert seen[-1] == (0x06, registers.REG_STOP, signal.SIG_IGN)
        assert len(sim.writes_to(registers.REG_STOP)) == 1
        assert signal.getsignal(signal.SIGINT) is before  # and Ctrl-C is back afterwards
        tracker = ctx.client.last_tracker
        assert tracker is not None and tracker.finished
    finally:
        ctx.close()


def test_a_motion_command_the_controller_takes_after_the_stop_is_stopped_too(sim_factory: Any) -> None:
    """Ctrl-C while the step's 440 write is on its way and the controller holds it (0.3 s): the
    stop on the fresh link is taken first, the step after it. A second stop, once the step is
    older than the link timeout, stops it."""
    sim = sim_factory(command_latency=0.02)
    settings = ConnectionSettings(port=sim.port, timeout=1.0, completion="observe")
    ctx = CliContext(argparse.Namespace(), settings, out=io.StringIO(), err=io.StringIO())
    speed_reg = registers.gv_reg(registers.GV_EXPECTED_SPEED)

    def hold_the_command(record: TrafficRecord) -> None:
        if record.direction != "tx":
            return
        address = int.from_bytes(record.frame[8:10], "big")
        if address == speed_reg:
            sim.set_response_delay(0.3)  # the next request, the step's 440, waits in the controller
        elif address == registers.REG_RUN_COMMAND:
            sent = ctx.client.stats.requests
            deadline = time.monotonic() + 5.0
            while sim.requests_count < sent and time.monotonic() < deadline:
                time.sleep(0.001)  # until the controller holds the 440 (its delay is decided)
            sim.set_response_delay(0.0)  # the stop will be taken at once
            raise KeyboardInterrupt  # the 440 sent, its answer not read

    try:
        ctx.client.add_observer(hold_the_command)
        with pytest.raises(KeyboardInterrupt):
            wait_motion(ctx, lambda: ctx.client.step(StepFrame.JOINT, [90.0, 0, 0, 0, 0, 0], speed=1.0))
    finally:
        ctx.close()
    assert ctx.err.getvalue() == "teachpad-cli: warning: interrupted: stop sent\n"  # type: ignore[attr-defined]
    assert sim.wait_for(lambda _: bool(sim.writes_to(registers.REG_RUN_COMMAND)), 2.0)
    (command,) = sim.writes_to(registers.REG_RUN_COMMAND)
    first, second = sim.writes_to(registers.REG_STOP)
    assert first.t < command.t < second.t  # the controller took the step after the first stop
    assert sim.wait_for(lambda s: not s.moving, 2.0)


def test_ctrl_c_with_a_silent_controller_says_the_stop_failed_within_the_timeout(sim_factory: Any) -> None:
    sim = sim_factory(command_latency=0.02)
    ctx = _ctx(sim, timeout=0.3)

    def interrupted() -> CommandResult:
        # the step's writes must be answered: roomy (a loaded test process can hold an answer
        # 0.3 s); the stop after the silence keeps the 0.3 s this test is about
        with ctx.client.io_timeout(2.0):
            ctx.client.step(StepFrame.JOINT, [90.0, 0, 0, 0, 0, 0], speed=1.0, wait=False)
        assert sim.wait_for(lambda s: s.moving, 5.0)
        sim.set_silent(True)
        raise KeyboardInterrupt

    try:
        started = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            wait_motion(ctx, interrupted)
        took = time.monotonic() - started
        warning = ctx.err.getvalue()  # type: ignore[attr-defined]
        assert warning.startswith("teachpad-cli: warning: interrupted, and stop failed: ")
        assert "did not answer within 0.3 s" in warning and warning.count("\n") == 1
        assert took < 5.0, took  # one request's timeout (retries 0), not a wait on the motion
    finally:
        sim.set_silent(False)
        ctx.close()


def test_ctrl_c_before_a_command_went_out_sends_nothing(sim: Any) -> None:
    ctx = _ctx(sim)

    def interrupted() -> None:
        ctx.client.read_status()
        raise KeyboardInterrupt

    try:
        with pytest.raises(KeyboardInterrupt):
            wait_motion(ctx, interrupted)
        assert ctx.err.getvalue() == ""  # type: ignore[attr-defined]
        assert sim.writes == []
    finally:
        ctx.close()


def test_ctrl_c_in_monitor_only_mode_sends_nothing(sim_factory: Any) -> None:
    sim = sim_factory(command_latency=0.02)
    ctx = _ctx(sim, monitor_only=True)

    def interrupted() -> None:
        ctx.client.read_pose()
        raise KeyboardInterrupt

    try:
        with pytest.raises(KeyboardInterrupt):
            wait_motion(ctx, interrupted)
        assert sim.writes == [] and ctx.err.getvalue() == ""  # type: ignore[attr-defined]
    finally:
        ctx.close()


# --- sigint_deferred -----------------------------------------------------------------------------


def test_sigint_deferred_ignores_ctrl_c_inside_and_restores_the_handler_after_an_error() -> None:
    before = signal.getsignal(signal.SIGINT)
    with pytest.raises(RuntimeError), sigint_deferred():
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
        raise RuntimeError("cleanup failed")
    assert signal.getsignal(signal.SIGINT) is before


def test_sigint_deferred_off_the_main_thread_changes_nothing() -> None:
    handlers: list[object] = []

    def body() -> None:
        with sigint_deferred():
            handlers.append(signal.getsignal(signal.SIGINT))

    before = signal.getsignal(signal.SIGINT)
    thread = threading.Thread(target=body)
    thread.start()
    thread.join(5.0)
    assert handlers == [before]


# --- run: the runner's halt -----------------------------------------------------------------------


def test_ctrl_c_in_a_run_stops_on_a_fresh_link_and_says_nothing_failed(
    sim_factory: Any, tmp_path: Path
) -> None:
    """Ctrl-C while a status read of the move is on the wire (its answer comes 0.2 s later): on
    the old link that late answer was read as the stop's ("the stop command failed too:
    malformed answer ... an answer to another request") although the stop went out."""
    sim = sim_factory(command_latency=0.02)
    project = tmp_path / "demo.teachpad.json"
    project.write_bytes((ROOT / "resources" / "samples" / "demo.teachpad.json").read_bytes())
    args = build_parser().parse_args(
        ["--port", str(sim.port), "run", str(project), "--plan", "pick and place"]
    )
    client = RobotClient(ConnectionSettings(port=sim.port, timeout=2.0))  # 2nd stop: after 2 s
    cut: list[float] = []

    def ctrl_c_on_the_wire(record: TrafficRecord) -> None:
        if not cut and record.direction == "tx" and record.frame[7] == 0x03 and sim.state().moving:
            cut.append(time.monotonic())
            sim.set_response_delay(0.2)  # this read's answer, and every later one, comes late
            raise KeyboardInterrupt  # the read is sent, its answer not read: cut in half

    client.add_observer(ctrl_c_on_the_wire)
    ctx = CliContext(args, client.settings, out=io.StringIO(), err=io.StringIO(), make_client=lambda: client)
    try:
        code = run_plan.cmd_run(ctx)
    finally:
        ctx.close()
    err = ctx.err.getvalue()  # type: ignore[attr-defined]
    assert code == ExitCode.INTERRUPTED, err
    assert cut and err == "teachpad-cli: error: stopped: segment 1/3 (loop 1/2): interrupted (Ctrl-C)\n"
    assert "to resume: teachpad-cli run" in ctx.out.getvalue()  # type: ignore[attr-defined]
    stop = sim.writes_to(registers.REG_STOP)[-1]
    assert stop.values == (1,) and stop.t > cut[0]
    assert client.stats.reconnects == 1 and client.stats.timeouts == 0  # the stop's own link
    assert sim.wait_for(lambda s: not s.moving, 2.0)


def test_ctrl_c_while_a_program_starts_stops_it(sim_factory: Any) -> None:
    sim = sim_factory(command_latency=0.02)
    args = build_parser().parse_args(["--port", str(sim.port), "program", "run", "2", "--mode", "cycle"])
    client = RobotClient(ConnectionSettings(port=sim.port, timeout=2.0))  # 2nd stop: after 2 s

    def ctrl_c_after_the_run_command(record: TrafficRecord) -> None:
        if record.direction == "tx" and record.frame[7] == 0x03 and sim.writes_to(registers.REG_RUN_COMMAND):
            client.remove_observer(ctrl_c_after_the_run_command)
            raise KeyboardInterrupt  # in the wait for the program to show running

    client.add_observer(ctrl_c_after_the_run_command)
    ctx = CliContext(args, client.settings, out=io.StringIO(), err=io.StringIO(), make_client=lambda: client)
    try:
        with pytest.raises(KeyboardInterrupt):
            controller.cmd_program_run(ctx)
    finally:
        ctx.close()
    assert ctx.err.getvalue() == "teachpad-cli: warning: interrupted: stop sent\n"  # type: ignore[attr-defined]
    (run,) = sim.writes_to(registers.REG_RUN_COMMAND)
    assert sim.writes_to(registers.REG_STOP)[-1].t > run.t
    assert sim.wait_for(lambda s: s.program_state == ProgramState.STOPPED and not s.moving, 2.0)


# --- a Ctrl-C Python drops -----------------------------------------------------------------------

_CTRL_C_IN_A_FINALISER = """
import signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
from app.cli import main as cli

class CtrlCInAFinaliser:
    def __del__(self):
        signal.raise_signal(signal.SIGINT)  # its KeyboardInterrupt: "Exception ignored in ..."

real = cli.settings_from_args

def settings_from_args(args):
    CtrlCInAFinaliser()  # collected at once, before the link is opened
    return real(args)

cli.settings_from_args = settings_from_args
sys.exit(cli.main(sys.argv[1:]))
"""


def test_a_ctrl_c_python_drops_still_ends_the_command_before_anything_is_sent(sim: Any) -> None:
    """The hunt saw a Ctrl-C at start-up land in an import's weakref callback: Python printed
    "Exception ignored ... KeyboardInterrupt", dropped it, and the step ran to its end (exit 0)."""
    proc = subprocess.run(
        [
            sys.executable,
            "-c",
            _CTRL_C_IN_A_FINALISER,
            "--port",
            str(sim.port),
            "step",
            "--frame",
            "joint",
            "J1=5",
        ],
        cwd=ROOT,
        env=untraced_env(),  # a signal in a traced child can hang it (tests/cli/ctrl_c.py)
        capture_output=True,
        text=True,
        timeout=CHILD_TIMEOUT,
        check=False,
    )
    assert (proc.returncode, proc.stdout) == (ExitCode.INTERRUPTED, "")
    assert proc.stderr == "teachpad-cli: error: interrupted\n"
    assert sim.writes == [] and not sim.state().moving


def test_a_second_ctrl_c_while_the_old_link_closes_cancels_no_stop(
    sim_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Operators press Ctrl-C more than once: one landing while the half-used link is being closed
    (before the stop) is ignored too, and the stop goes out. Before, the link was closed before
    Ctrl-C was deferred: that second Ctrl-C ended the CLI with no stop sent."""
    import os

    from app.cli.context import stop_on_a_fresh_link

    sim = sim_factory(command_latency=0.02)
    ctx = _ctx(sim)
    before = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a shell's foreground
    try:
        client = ctx.client
        client.step(StepFrame.JOINT, [90.0, 0, 0, 0, 0, 0], speed=1.0, wait=False)
        assert sim.wait_for(lambda s: s.moving, 5.0)
        close = client.close
        pressed: list[bool] = []

        def close_with_a_second_ctrl_c() -> None:
            if not pressed:  # the stop's own close, not the test's at the end
                pressed.append(True)
                os.kill(os.getpid(), signal.SIGINT)
            close()

        monkeypatch.setattr(client, "close", close_with_a_second_ctrl_c)
        try:
            stop_on_a_fresh_link(client)
        except KeyboardInterrupt:
            pytest.fail("the second Ctrl-C ended the stop before it was sent")
        assert sim.writes_to(registers.REG_STOP)[-1].values == (1,)
        assert sim.wait_for(lambda s: not s.moving, 2.0)
    finally:
        signal.signal(signal.SIGINT, before)
        ctx.close()

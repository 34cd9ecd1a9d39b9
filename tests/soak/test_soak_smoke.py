"""The soak (``make soak``, tests/soak/run.py) in ``make test``: a short session of random operator
actions on the real window against the simulator, judged as ``make soak`` judges its sessions; the
soak's own detectors on an injected Qt warning and an injected exception (each in a thread of its
own); and the judge on made-up outputs."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.cli.ctrl_c import COVERAGE_STARTUP_VARS
from tests.soak.run import SessionResult, _judge, run_session

# A session is a GUI process and its simulator child: start-up, 12 s of actions and the close
# take ~30 s, far more on a loaded machine (the session's own hang limit is minutes).
pytestmark = pytest.mark.timeout(600)

SMOKE_SECONDS = 12.0
SMOKE_SEED = 18  # fixed: the same actions every run (their timing follows the machine)


@pytest.fixture(autouse=True)
def _untraced(monkeypatch: pytest.MonkeyPatch) -> None:
    """The session's processes without coverage's tracer: traced, the GUI and the worker run
    several times slower, and the session would measure the tracer, not the window."""
    for name in COVERAGE_STARTUP_VARS:
        monkeypatch.delenv(name, raising=False)


def _explain(result: SessionResult, out: Path) -> str:
    err = (out / f"session-{result.number}.err").read_text(errors="replace").splitlines()
    actions = (out / f"session-{result.number}.out").read_text(errors="replace").splitlines()
    relevant = [line for line in err if " INFO " not in line][-60:]
    return "\n".join([*result.problems, "--- stderr ---", *relevant, "--- actions ---", *actions[-20:]])


def test_a_short_soak_is_clean(tmp_path: Path) -> None:
    result = run_session(1, SMOKE_SEED, SMOKE_SECONDS, tmp_path, echo=False)
    assert result.ok, _explain(result, tmp_path)
    assert result.code == 0 and result.actions >= 5, _explain(result, tmp_path)


@pytest.mark.parametrize(
    ("inject", "expected"),
    [
        ("qt-warning", "Qt QtWarningMsg in thread soak-inject: soak self-test"),  # aborts: a crash
        ("exception", "exception in thread soak-inject: ZeroDivisionError"),
    ],
)
def test_the_soak_catches_a_failure_in_any_thread(tmp_path: Path, inject: str, expected: str) -> None:
    result = run_session(1, SMOKE_SEED, 60.0, tmp_path, echo=False, inject=inject)
    for core in tmp_path.glob("core*"):
        core.unlink()  # the abort's core dump (hundreds of MB): proof enough that it was written
    assert not result.ok
    err = (tmp_path / "session-1.err").read_text(errors="replace")
    assert expected in err, _explain(result, tmp_path)
    if inject == "qt-warning":
        assert result.code is not None and result.code < 0  # SIGABRT
        assert any("killed by SIGABRT" in p for p in result.problems), result.problems
        assert "Current thread" in err or "Thread 0x" in err  # faulthandler's stacks
    else:
        assert result.code == 1 and any("SOAK FAILURE" in p for p in result.problems), result.problems


def test_the_judge(tmp_path: Path) -> None:
    done = ["    5.000 s  #00001 stop: STOP\n", "    9.000 s  soak session done: seed 1, 1 actions\n"]
    clean = SessionResult(1, 1, 5.0, code=0)
    _judge(clean, done, ["2026-01-01 INFO app.sim.server: simulator stopped\n"], tmp_path)
    assert clean.ok and clean.actions == 1
    crashed = SessionResult(1, 1, 5.0, code=-11)
    _judge(crashed, done[:1], ["Fatal Python error: Segmentation fault\n"], tmp_path)
    assert any("SIGSEGV" in p for p in crashed.problems)
    assert any("Fatal Python error" in p for p in crashed.problems)
    assert any("did not report its end" in p for p in crashed.problems)
    child = SessionResult(1, 1, 5.0, code=0)
    _judge(child, done, ["Traceback (most recent call last):\n", "BrokenPipeError: [Errno 32]\n"], tmp_path)
    assert len(child.problems) == 2  # the simulator child's traceback fails the session

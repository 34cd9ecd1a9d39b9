"""``make soak``: the real window against the simulator for N minutes of random operator actions.

    python -m tests.soak.run [--minutes 30] [--seed S] [--session-minutes 10] [--out DIR]

(``make soak SOAK_MINUTES=30 SOAK_SEED=S``.) The time is spent in sessions: each one is a fresh
GUI process (``python -m tests.soak.gui``: ``teachpad --sim``'s ``main()``, its simulator child,
the operator of tests/soak/operator.py) with its own seed (the run's seed + its number), so the
start-up and every first-time path (the first support bundle, the traffic dock's first showing)
are walked again and again. Everything a session prints goes to ``DIR/session-K.out`` (its seed,
the action log) and ``DIR/session-K.err`` (its stderr and the simulator child's, which inherits
it); the action log is echoed here too.

A session fails on: an exit code other than 0 (a crash: killed by a signal, its core in ``DIR``),
``SOAK FAILURE`` (the GUI's hooks: a Python exception in any thread, a Python warning, a Qt
warning -- which aborts with every thread's stack), a Python traceback or fatal error on stderr
from either process (the simulator child's BrokenPipeError included), a hang (no end within its
time + :data:`HANG_MARGIN`: SIGABRT, so faulthandler dumps every stack), or a simulator child
that outlives its window. The run stops at the first failed session and exits 1.

Not part of ``make test`` (this folder's only test module is the short smoke run,
tests/soak/test_soak_smoke.py).
"""

from __future__ import annotations

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

from app.user_dirs import fresh_user_dirs_env

__all__ = ["SessionResult", "main", "run_session"]

ROOT = Path(__file__).resolve().parents[2]
HANG_MARGIN = 300.0  # s beyond a session's time for start-up and close on a loaded machine
SIM_EXIT_WAIT = 60.0  # s for the simulator child to end (its stderr to close) after the window
# What fails a session when either process writes it to stderr.
MARKERS = (
    "SOAK FAILURE",
    "Traceback (most recent call last)",
    "Fatal Python error",
    "Exception ignored",
    "Segmentation fault",
    "BrokenPipeError",
)
_SIM_PID = re.compile(r"simulator pid (\d+)")
_ACTION = re.compile(r" s  #\d{5} ")  # an action's line in the log (tests/soak/gui.py: say)


@dataclass
class SessionResult:
    number: int
    seed: int
    seconds: float
    code: int | None = None
    actions: int = 0
    problems: list[str] = field(default_factory=list)
    wall: float = 0.0

    @property
    def ok(self) -> bool:
        return not self.problems


def _pump(stream: IO[str], sink: IO[str], echo: bool, lines: list[str]) -> None:
    """Copy a child's pipe to ``sink`` (and our stdout) until every writer closed it."""
    for line in stream:
        sink.write(line)
        lines.append(line)
        if echo:
            sys.stdout.write(line)
            sys.stdout.flush()
    sink.flush()


def run_session(
    number: int, seed: int, seconds: float, out: Path, *, echo: bool = True, inject: str = ""
) -> SessionResult:
    """One GUI process for ``seconds`` of actions, judged (see the module docstring). ``inject``:
    the self-test's failure (tests/soak/test_soak_smoke.py)."""
    result = SessionResult(number, seed, seconds)
    home = out / f"session-{number}"
    env = dict(os.environ)
    env.update(
        QT_QPA_PLATFORM="offscreen",
        PYTHONPATH=os.pathsep.join(p for p in (str(ROOT), env.get("PYTHONPATH", "")) if p),
        PYTHONUNBUFFERED="1",
        **fresh_user_dirs_env(home),
    )
    command = [sys.executable, "-X", "faulthandler", "-m", "tests.soak.gui"]
    command += ["--seed", str(seed), "--seconds", f"{seconds:g}", "--home", str(home / "home")]
    command += ["--inject", inject] if inject else []
    start = time.monotonic()
    out_lines: list[str] = []
    err_lines: list[str] = []
    with (
        open(out / f"session-{number}.out", "w") as out_file,
        open(out / f"session-{number}.err", "w") as err_file,
    ):
        child = subprocess.Popen(
            command,
            cwd=out,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            errors="replace",
        )
        assert child.stdout is not None and child.stderr is not None
        pumps = [
            threading.Thread(target=_pump, args=(child.stdout, out_file, echo, out_lines), daemon=True),
            threading.Thread(target=_pump, args=(child.stderr, err_file, False, err_lines), daemon=True),
        ]
        for pump in pumps:
            pump.start()
        result.code = _wait(child, seconds + HANG_MARGIN, result)
        for pump in pumps:  # stderr ends when the simulator child (which inherits it) ends too
            pump.join(SIM_EXIT_WAIT)
        if any(pump.is_alive() for pump in pumps):
            result.problems.append(f"the simulator child still runs {SIM_EXIT_WAIT:g} s after its window")
            _kill_simulator(out_lines)
            for pump in pumps:
                pump.join(SIM_EXIT_WAIT)
        child.stdout.close()
        child.stderr.close()
    result.wall = time.monotonic() - start
    _judge(result, out_lines, err_lines, out)
    return result


def _kill_simulator(out_lines: list[str]) -> None:
    """Kill the simulator child the session named (``simulator pid N``), so its pipe closes."""
    for line in out_lines:
        found = _SIM_PID.search(line)
        if found:
            try:
                os.kill(int(found[1]), signal.SIGKILL)
            except OSError:
                pass


def _wait(child: subprocess.Popen[str], timeout: float, result: SessionResult) -> int:
    try:
        return child.wait(timeout)
    except subprocess.TimeoutExpired:
        result.problems.append(f"hung: no end within {timeout:g} s (SIGABRT: every thread's stack in .err)")
        child.send_signal(signal.SIGABRT)
        try:
            return child.wait(60)
        except subprocess.TimeoutExpired:
            child.kill()
            return child.wait()


def _judge(result: SessionResult, out_lines: list[str], err_lines: list[str], out: Path) -> None:
    code = result.code
    if code is not None and code < 0:
        name = signal.Signals(-code).name if -code in signal.valid_signals() else str(-code)
        cores = sorted(str(p) for p in out.glob("core*"))
        result.problems.append(f"crashed: killed by {name}; core: {', '.join(cores) or 'see core_pattern'}")
    elif code != 0:
        result.problems.append(f"exit code {code}")
    for marker in MARKERS:
        hits = [line.rstrip() for line in err_lines if marker in line]
        if hits:
            result.problems.append(f"stderr has {marker!r} ({len(hits)}x), first: {hits[0][:200]}")
    result.actions = sum(1 for line in out_lines if _ACTION.search(line))
    if not any("soak session done" in line for line in out_lines):
        result.problems.append("the session did not report its end")


def _report_failure(result: SessionResult, out: Path) -> None:
    err = (out / f"session-{result.number}.err").read_text(errors="replace").splitlines()
    relevant = [line for line in err if " INFO " not in line]
    print(f"\n--- session {result.number} (seed {result.seed}): stderr without INFO lines, last 150 ---")
    print("\n".join(relevant[-150:]))
    actions = (out / f"session-{result.number}.out").read_text(errors="replace").splitlines()
    print(f"--- its last 30 actions (all in {out}/session-{result.number}.out) ---")
    print("\n".join(actions[-30:]))


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.soak.run", description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=float(os.environ.get("SOAK_MINUTES", "30")))
    parser.add_argument("--seed", type=int, default=None, help="default: SOAK_SEED or from the clock")
    parser.add_argument("--session-minutes", type=float, default=10.0, help="one GUI process's share")
    parser.add_argument("--out", type=Path, default=None, help="logs and cores (default: a new temp dir)")
    parser.add_argument("--quiet", action="store_true", help="no action log here (it is in the files)")
    args = parser.parse_args(argv)
    seed = args.seed if args.seed is not None else int(os.environ.get("SOAK_SEED") or time.time_ns() % 10**6)
    out: Path = args.out or Path(tempfile.mkdtemp(prefix="teachpad-soak-"))
    out.mkdir(parents=True, exist_ok=True)
    total = args.minutes * 60.0
    print(
        f"soak: seed {seed}, {args.minutes:g} min in sessions of {args.session_minutes:g} min, logs in {out}"
    )
    results: list[SessionResult] = []
    spent = 0.0
    while spent < total - 1.0:
        seconds = min(args.session_minutes * 60.0, total - spent)
        number = len(results) + 1
        print(f"soak: session {number}: seed {seed + number - 1}, {seconds:g} s", flush=True)
        result = run_session(number, seed + number - 1, seconds, out, echo=not args.quiet)
        results.append(result)
        spent += seconds
        verdict = "clean" if result.ok else "FAILED: " + "; ".join(result.problems)
        print(f"soak: session {number} (seed {result.seed}): {result.actions} actions, {verdict}", flush=True)
        if not result.ok:
            _report_failure(result, out)
            break
    actions = sum(r.actions for r in results)
    wall = sum(r.wall for r in results)
    ok = all(r.ok for r in results) and spent >= total - 1.0
    seeds = ", ".join(str(r.seed) for r in results)
    print(
        f"soak: {'CLEAN' if ok else 'FAILED'}: {len(results)} session(s), seeds {seeds}, "
        f"{spent / 60:.1f} min of actions ({wall / 60:.1f} min wall), {actions} actions; logs in {out}"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

"""`make bench`: run every benchmark and print one JSON object.

Usage: python -m benchmarks.run [--quick] [--long] [--only SUITE,...] (default: every suite but safety)

``goals`` (:mod:`benchmarks.goals`) prints each of the issue's figures beside its goal.
``--long`` adds the 10-minute memory soak (``gui.memory.soak``).
``gateway`` (:mod:`benchmarks.gateway`): the Sparkplug gateway with 64 simulated controllers at
10 Hz through a real mosquitto, one dead controller of 16, a bare pymodbus loop beside it.
``cell_view`` (:mod:`benchmarks.cell_view`): the GUI's Cell tab with 16 simulated controllers at
20 Hz (GUI-thread CPU, event-loop p99).
``bundle`` (:mod:`benchmarks.bundle`): the size and start-up of ``make dist``'s bundle beside the
venv's; null figures with the reason when it is not built.

Bytecode: ``app/`` and ``ui/`` are compiled first (``compileall``), so the start-up figures
measure what an installed TeachPad does (a wheel install compiles them; a normal interpreter
writes them on the first run). With ``PYTHONDONTWRITEBYTECODE=1`` in the environment and no
``__pycache__``, every start compiled ~450 ms of source (measured on the 2-core machine: project
modules' import 879 ms without bytecode, 433 ms with). ``--no-compile`` measures that case.
"""

from __future__ import annotations

import argparse
import compileall
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from app.user_dirs import fresh_user_dirs_env
from benchmarks.goals import goals, guarded, table


def _core(args: argparse.Namespace) -> dict[str, Any]:
    from benchmarks import core

    return guarded("core", lambda: core.run(args.quick))


def _gui(args: argparse.Namespace) -> dict[str, Any]:
    try:
        from benchmarks import gui, gui_memory
    except ImportError as exc:  # suite not written yet
        return {"skipped": str(exc)}
    out = guarded("gui", lambda: gui.run(args.quick))
    out["memory"] = guarded("gui.memory", lambda: gui_memory.run_memory(args.quick, args.long))
    return out


def _points(args: argparse.Namespace) -> dict[str, Any]:
    try:
        from benchmarks import points
    except ImportError as exc:
        return {"skipped": str(exc)}
    return guarded("points", lambda: points.run(args.quick))


def _noisy_line(args: argparse.Namespace) -> dict[str, Any]:
    """A 200-point RTU upload through a line damaging 1 byte in 500."""
    noisy_line = __import__("benchmarks.noisy_line", fromlist=["run"])
    return guarded("noisy_line", lambda: noisy_line.run(args.quick))


def _bundle(args: argparse.Namespace) -> dict[str, Any]:
    """Report only: the bundle beside the venv (null + reason when not built)."""
    from benchmarks import bundle

    return guarded("bundle", lambda: bundle.run(args.quick))


def _safety(args: argparse.Namespace) -> dict[str, Any]:
    """Not in the default set: --only safety (or core,gui,points,safety)."""
    safety = __import__("benchmarks.safety", fromlist=["run"])
    return guarded("safety", lambda: safety.run(args.quick))


def _gateway(args: argparse.Namespace) -> dict[str, Any]:
    """The gateway at scale (issue 23): 64 controllers at 10 Hz to a real mosquitto, one dead of 16,
    a bare pymodbus loop beside it, the simulator in one process against many."""
    gateway = __import__("benchmarks.gateway", fromlist=["run"])
    return guarded("gateway", lambda: gateway.run(args.quick))


def _cell_view(args: argparse.Namespace) -> dict[str, Any]:
    """The GUI's cell view at scale (issue 23): 16 controllers at 20 Hz in the Cell tab at 1280×800."""
    cell_view = __import__("benchmarks.cell_view", fromlist=["run"])
    return guarded("cell_view", lambda: cell_view.run(args.quick))


def _watch_list(args: argparse.Namespace) -> dict[str, Any]:
    """The watch list's poll budget and cost beside the pose poll alone (issue 24)."""
    watch_list = __import__("benchmarks.watch_list", fromlist=["run"])
    return guarded("watch_list", lambda: watch_list.run(args.quick))


#: The suites in the order they run; each imported only when it runs.
SUITES: dict[str, Callable[[argparse.Namespace], dict[str, Any]]] = {
    "core": _core,
    "gui": _gui,
    "points": _points,
    "noisy_line": _noisy_line,
    "bundle": _bundle,
    "safety": _safety,
    "gateway": _gateway,
    "cell_view": _cell_view,
    "watch_list": _watch_list,
}


def _warm_dataclass_code(root: Path) -> str:
    """One start of the window before the figures, with bytecode written: it leaves the methods
    of the dataclasses compiled in ``ui/__pycache__`` (ui/dataclass_code.py), as any earlier start
    of an installed TeachPad has. What happened, in words (a start that fails is no figure lost:
    the start-ups then compile those methods, as a first start does)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["QT_QPA_PLATFORM"] = "offscreen"
    with tempfile.TemporaryDirectory(prefix="teachpad-warm-") as tmp:
        env.update(fresh_user_dirs_env(tmp))
        shot = Path(tmp) / "shot.png"
        try:
            done = subprocess.run(
                [
                    sys.executable,
                    "-c",
                    "import sys; from ui.main import main; sys.exit(main(sys.argv[1:]))",  # as `teachpad`
                    "--sim",
                    "--settings",
                    str(Path(tmp) / "t.ini"),
                    "--screenshot",
                    str(shot),
                ],
                cwd=root,
                env=env,
                capture_output=True,
                timeout=120,
                check=False,
            )
        except (OSError, subprocess.SubprocessError) as exc:
            return f"not warmed: {exc}"[:300]
    if done.returncode != 0:
        return f"not warmed: the start ended with {done.returncode}"
    return "warmed by one start before the run"


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="small N and short windows")
    parser.add_argument("--long", action="store_true", help="memory soak of 10 minutes (RSS every 30 s)")
    parser.add_argument(
        "--only",
        default="core,gui,points,noisy_line,bundle,gateway,cell_view,watch_list",
        help="comma-separated suites",
    )
    parser.add_argument(
        "--no-compile",
        action="store_true",
        help="do not compile app/ and ui/ first (start-up then includes compiling)",
    )
    return parser


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    suites = {s.strip() for s in args.only.split(",") if s.strip()}
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

    out: dict[str, Any] = {
        "machine": {
            "python": platform.python_version(),
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
        },
        "quick": args.quick,
        "long": args.long,
        "bytecode": "as found" if args.no_compile else "compiled before the run",
        "load_avg_1m_at_start": os.getloadavg()[0],
    }
    if not args.no_compile:
        root = Path(__file__).resolve().parents[1]
        for package in ("app", "ui"):
            compileall.compile_dir(root / package, quiet=1)
        out["dataclass_code"] = _warm_dataclass_code(root)
    t0 = time.perf_counter()
    for name, run_suite in SUITES.items():
        if name in suites:
            out[name] = run_suite(args)
    out["total_s"] = time.perf_counter() - t0
    out["goals"] = goals(out)
    json.dump(out, sys.stdout, indent=2, sort_keys=True)
    sys.stdout.write("\n")
    sys.stderr.write(table(out["goals"]) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""The bundle (`make dist`, dist/teachpad/) beside the venv: its size and start-up (report only).

Start-up is the wall time of a whole process, median of ``runs`` alternating bundle and venv runs
(the same machine state for both), in an environment with a temporary HOME:

* ``cli_version_s``: ``teachpad-cli --version`` -- the CLI's imports, no network;
* ``cli_help_s``: ``teachpad-cli --help`` -- the same plus every command's help text;
* ``cli_status_s``: ``teachpad-cli status`` against a simulator in this process (connect, read
  the status, print, exit);
* ``gui_help_s``: ``teachpad --help`` -- the GUI's module imports (PySide6, the window's
  modules), no window.

When the bundle is not built, every figure is null and ``reason`` says why (the bench goes on).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
BUNDLE = REPO / "dist" / "teachpad"
EXE_SUFFIX = ".exe" if sys.platform == "win32" else ""
NAMES = ("teachpad", "teachpad-cli", "teachpad-sim")
RUN_TIMEOUT_S = 60.0
FIGURES = ("cli_version_s", "cli_help_s", "cli_status_s", "gui_help_s")


def folder_mb(folder: Path) -> float:
    """Bytes of the files under ``folder`` (symbolic links not followed, not counted), in MB."""
    total = sum(p.stat().st_size for p in folder.rglob("*") if p.is_file() and not p.is_symlink())
    return round(total / 1e6, 1)


def _timed(command: Sequence[str], env: dict[str, str], cwd: Path) -> float:
    t0 = time.perf_counter()
    done = subprocess.run(
        list(command), env=env, cwd=cwd, capture_output=True, text=True, timeout=RUN_TIMEOUT_S, check=False
    )
    seconds = time.perf_counter() - t0
    if done.returncode != 0:
        raise RuntimeError(f"{Path(command[0]).name} exited {done.returncode}: {done.stderr.strip()[-300:]}")
    return seconds


def _compare(
    bundle: Sequence[str], venv: Sequence[str], runs: int, env: dict[str, str], cwd: Path
) -> dict[str, Any]:
    """Median and minimum wall time of both, runs interleaved; ratio = bundle / venv (medians)."""
    _timed(bundle, env, cwd)  # one cold run each, not counted (page cache)
    _timed(venv, env, cwd)
    times: dict[str, list[float]] = {"bundle": [], "venv": []}
    for _ in range(runs):
        times["bundle"].append(_timed(bundle, env, cwd))
        times["venv"].append(_timed(venv, env, cwd))
    out: dict[str, Any] = {}
    for kind, values in times.items():
        out[kind] = round(statistics.median(values), 3)
        out[f"{kind}_min"] = round(min(values), 3)
    out["ratio_bundle_vs_venv"] = round(out["bundle"] / out["venv"], 2)
    return out


def not_built(reason: str) -> dict[str, Any]:
    return {
        "built": False,
        "reason": reason,
        "not_measured": reason,  # the bench's word for it (benchmarks.goals.reason_for)
        "size_mb": None,
        "internal_mb": None,
        "executables_mb": None,
        **{figure: None for figure in FIGURES},
    }


def run(quick: bool, bundle: Path = BUNDLE) -> dict[str, Any]:
    exes = {name: bundle / f"{name}{EXE_SUFFIX}" for name in NAMES}
    missing = [name for name, exe in exes.items() if not exe.is_file()]
    if missing:
        return not_built(f"{bundle} has no {', '.join(missing)}: run `make dist` first")
    venv_bin = Path(sys.executable).parent
    venv = {name: venv_bin / f"{name}{EXE_SUFFIX}" for name in NAMES}
    if not all(p.is_file() for p in venv.values()):
        return not_built(f"the venv's console scripts are not in {venv_bin}")
    out: dict[str, Any] = {
        "built": True,
        "reason": None,
        "path": str(bundle),
        "size_mb": folder_mb(bundle),
        "internal_mb": folder_mb(bundle / "_internal"),
        "executables_mb": {name: round(exe.stat().st_size / 1e6, 1) for name, exe in exes.items()},
        "built_at": time.strftime("%Y-%m-%dT%H:%M:%S", time.localtime(exes["teachpad"].stat().st_mtime)),
    }
    runs = 3 if quick else 7
    out["runs"] = runs
    from app.sim.config import SimConfig
    from app.sim.server import SimController

    with tempfile.TemporaryDirectory(prefix="teachpad-bench-bundle-") as tmp_name:
        home = Path(tmp_name)
        env = {**os.environ, "HOME": str(home), "QT_QPA_PLATFORM": "offscreen"}
        env.pop("PYTHONPATH", None)
        cli = (str(exes["teachpad-cli"]), str(venv["teachpad-cli"]))
        out["cli_version_s"] = _compare([cli[0], "--version"], [cli[1], "--version"], runs, env, home)
        out["cli_help_s"] = _compare(
            [str(exes["teachpad-cli"]), "--help"], [str(venv["teachpad-cli"]), "--help"], runs, env, home
        )
        out["gui_help_s"] = _compare(
            [str(exes["teachpad"]), "--help"], [str(venv["teachpad"]), "--help"], runs, env, home
        )
        sim = SimController(SimConfig(host="127.0.0.1", port=0))
        sim.start()
        try:
            link = ["--host", "127.0.0.1", "--port", str(sim.port), "status"]
            out["cli_status_s"] = _compare(
                [str(exes["teachpad-cli"]), *link], [str(venv["teachpad-cli"]), *link], runs, env, home
            )
        finally:
            sim.stop()
    return out

"""``make bench``'s cell view suite (issue 23): its quick run (the real main window offscreen, a
``teachpad-sim --controllers 16`` process) prints its keys beside their goals."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from benchmarks.goals import GOALS

ROOT = Path(__file__).resolve().parents[2]
RUN_TIMEOUT = 180.0  # s: the quick suite takes ~20 s; a loaded 2-core machine more

CELL_VIEW_GOALS = (
    "cell_view.cell_16.gui_thread_cpu_pct_no_probe",  # ≤ 15 % of a core
    "cell_view.cell_16.event_loop.p99_ms",  # ≤ 16 ms
)


def _lookup(data: dict[str, Any], key: str) -> Any:
    node: Any = data
    for part in key.split("."):
        assert isinstance(node, dict) and part in node, f"{key}: no {part!r} in {node!r:.300}"
        node = node[part]
    return node


def test_the_cell_view_suite_quick_run_prints_its_keys_beside_their_goals() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.run", "--quick", "--only", "cell_view", "--no-compile"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout)
    assert "not_measured" not in out["cell_view"], out["cell_view"]
    figures = out["cell_view"]["cell_16"]
    assert figures["controllers"] == 16 and figures["poll_hz"] == 20.0
    assert figures["window"] == "1280x800" and figures["compact_tiles"] is True and figures["columns"] == 4
    assert figures["answers_per_s"] > 0
    for key in CELL_VIEW_GOALS:
        value = _lookup(out, key)
        assert isinstance(value, int | float) and value > 0, (key, value)
    entries = {e["key"]: e for e in out["goals"]["entries"]}
    for key in CELL_VIEW_GOALS:
        assert entries[key]["met"] in (True, False) and entries[key]["bound"] is not None
    assert {key for key, *_ in GOALS} >= set(CELL_VIEW_GOALS)

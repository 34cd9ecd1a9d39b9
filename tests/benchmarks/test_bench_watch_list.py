"""``make bench``'s watch list suite: its quick run prints the watch list's cost per poll beside the
pose poll alone, and its goals."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from benchmarks.goals import GOALS

ROOT = Path(__file__).resolve().parents[2]
RUN_TIMEOUT = 120.0  # s: the quick suite takes a few seconds; a loaded 2-core machine more

KEYS = ("watch_list.entries_10.ratio_vs_pose_alone", "watch_list.entries_50.ratio_vs_pose_alone")


def test_the_watch_list_suite_prints_its_cost_beside_the_pose_poll() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.run", "--quick", "--only", "watch_list", "--no-compile"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout)["watch_list"]
    assert "not_measured" not in out, out
    cost = out["watch_list_poll_cost_ms"]
    assert cost["entries_0"] == 0.0 and {"entries_10", "entries_50"} <= set(cost)
    assert out["pose_poll_alone"]["mean_ms"] > 0
    assert out["entries_10"]["budget"]["slow_blocks"] == 0  # ten GVs together: all in the fast lane
    assert out["entries_50"]["budget"]["slow_blocks"] > 0
    assert {key for key, *_ in GOALS} >= set(KEYS)

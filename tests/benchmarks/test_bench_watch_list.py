"""``make bench``'s watch list suite: its quick run prints the watch list's cost per poll beside the
pose poll alone, and its goals."""

from __future__ import annotations

import pytest

from benchmarks.goals import GOALS
from tests.benchmarks.quick_suite import QUICK_RUN_LIMIT, quick_run

KEYS = ("watch_list.entries_10.ratio_vs_pose_alone", "watch_list.entries_50.ratio_vs_pose_alone")


@pytest.mark.timeout(QUICK_RUN_LIMIT)
def test_the_watch_list_suite_prints_its_cost_beside_the_pose_poll() -> None:
    out = quick_run("watch_list")["watch_list"]
    cost = out["watch_list_poll_cost_ms"]
    assert cost["entries_0"] == 0.0 and {"entries_10", "entries_50"} <= set(cost)
    assert out["pose_poll_alone"]["mean_ms"] > 0
    assert out["entries_10"]["budget"]["slow_blocks"] == 0  # ten GVs together: all in the fast lane
    assert out["entries_50"]["budget"]["slow_blocks"] > 0
    assert {key for key, *_ in GOALS} >= set(KEYS)

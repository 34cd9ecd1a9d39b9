"""``make bench``'s cell view suite (issue 23): its quick run (the real main window offscreen, a
``teachpad-sim --controllers 16`` process) prints its keys beside their goals."""

from __future__ import annotations

import pytest

from benchmarks.goals import GOALS
from tests.benchmarks.quick_suite import QUICK_RUN_LIMIT, lookup, quick_run

CELL_VIEW_GOALS = (
    "cell_view.cell_16.gui_thread_cpu_pct_no_probe",  # ≤ 15 % of a core
    "cell_view.cell_16.event_loop.p99_ms",  # ≤ 16 ms
)


@pytest.mark.timeout(QUICK_RUN_LIMIT)
def test_the_cell_view_suite_quick_run_prints_its_keys_beside_their_goals() -> None:
    out = quick_run("cell_view")
    figures = out["cell_view"]["cell_16"]
    assert figures["controllers"] == 16 and figures["poll_hz"] == 20.0
    assert figures["window"] == "1280x800" and figures["compact_tiles"] is True and figures["columns"] == 4
    assert figures["answers_per_s"] > 0
    for key in CELL_VIEW_GOALS:
        value = lookup(out, key)
        assert isinstance(value, int | float) and value > 0, (key, value)
    entries = {e["key"]: e for e in out["goals"]["entries"]}
    for key in CELL_VIEW_GOALS:
        assert entries[key]["met"] in (True, False) and entries[key]["bound"] is not None
    assert {key for key, *_ in GOALS} >= set(CELL_VIEW_GOALS)

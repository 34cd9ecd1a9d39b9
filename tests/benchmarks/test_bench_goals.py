"""make bench's goals object: every goal of issue 10 beside its figure, met or not; the busy
neighbour starts and ends its own load processes."""

from __future__ import annotations

import os

from benchmarks.goals import GOALS, goals, lookup, table

STABLE_KEYS = {
    "core.monitor_cycle.ratio_robot_vs_bare",
    "core.upload_points.ratio_batched_vs_bound",
    "points.restore_all.ratio_vs_bound",
    "gui.sim_separate_process.stop_latency.gui_stop_button.p99_ms",
    "gui.sim_separate_process.event_loop_stall.streaming.p99_ms",
    "gui.sim_separate_process.event_loop_stall.streaming.gui_thread_cpu_pct",
    "gui.startup.ratio_first_paint_vs_bare",
    "points.project_load.ratio_load_vs_json",
}


def test_every_stable_key_has_an_entry() -> None:
    assert {key for key, *_ in GOALS} >= STABLE_KEYS


def test_goals_judge_present_figures_and_list_missing_ones() -> None:
    out = {
        "points": {"project_load": {"ratio_load_vs_json": 1.4}, "restore_all": {"ratio_vs_bound": 1.5}},
        "gui": {"startup": {"ratio_first_paint_vs_bare": 2.0, "teachpad_sim": {"first_paint_ms": 300.0}}},
    }
    result = goals(out)
    by_key = {e["key"]: e for e in result["entries"]}
    assert by_key["points.project_load.ratio_load_vs_json"]["met"] is True
    assert by_key["points.project_load.ratio_load_vs_json"]["goal"] == "≤ 3x"
    assert by_key["points.restore_all.ratio_vs_bound"]["met"] is False
    # no sim_start_begin mark in the GUI process: the simulator ran elsewhere
    assert by_key["gui.startup.sim_in_gui_process"]["value"] == 0
    assert by_key["gui.startup.sim_in_gui_process"]["met"] is True
    assert by_key["core.monitor_cycle.ratio_robot_vs_bare"]["met"] is None  # report only
    assert "gui.sim_separate_process.stop_latency.gui_stop_button.p99_ms" in result["missing"]
    assert result["all_met"] is False
    assert "NOT MET" in table(result)
    assert lookup(out, "gui.startup.ratio_first_paint_vs_bare") == 2.0
    assert lookup(out, "gui.nothing.here") is None


def test_busy_neighbour_ends_its_processes() -> None:
    from benchmarks.gui_stalls import BusyNeighbour

    with BusyNeighbour(1) as busy:
        children = list(busy._children)
        assert len(children) == 1 and children[0].poll() is None
    assert all(child.poll() is not None for child in children)
    assert BusyNeighbour().procs == max(1, (os.cpu_count() or 2) - 1)


def test_a_figure_without_samples_is_null_with_a_reason() -> None:
    from benchmarks.gui_common import _summary_ms, ratio

    empty = _summary_ms([], "the time budget ran out before a stop was measured")
    assert empty["n"] == 0 and empty["p50_ms"] is None and empty["p99_ms"] is None
    assert empty["not_measured"].startswith("the time budget")
    assert ratio(empty["p50_ms"], 1.0) is None and ratio(2.0, 0.0) is None and ratio(2.0, 1.0) == 2.0
    out = {"gui": {"sim_separate_process": {"stop_latency": {"gui_stop_button": empty}}}}
    result = goals(out)
    entry = next(
        e
        for e in result["entries"]
        if e["key"] == "gui.sim_separate_process.stop_latency.gui_stop_button.p99_ms"
    )
    assert entry["status"] == "not measured" and entry["met"] is None
    assert entry["reason"].startswith("the time budget")
    assert "not measured" in table(result) and result["all_met"] is False


def test_a_failing_suite_is_reported_not_raised() -> None:
    from benchmarks.goals import guarded

    def broken() -> dict[str, object]:
        raise KeyError("p50_ms")

    out = {"gui": {"startup": guarded("startup", broken)}}
    assert "KeyError" in out["gui"]["startup"]["not_measured"]
    entry = next(e for e in goals(out)["entries"] if e["key"] == "gui.startup.ratio_first_paint_vs_bare")
    assert entry["status"] == "not measured" and "startup failed" in entry["reason"]

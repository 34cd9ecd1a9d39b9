"""The upload time split (benchmarks/completion_split.py) runs and reports every point created."""

from __future__ import annotations

from benchmarks.completion_split import run


def test_the_split_runs_both_ways_and_every_point_is_held() -> None:
    out = run(points=6, rounds=1)
    for name in ("staged", "unstaged"):
        figures = out[name]
        assert figures["failed_or_not_held"] == 0
        assert figures["requests"] >= 4  # pose, id, 440 and at least one status read per point
        assert figures["wall"] > 0 and figures["bound"] > 0 and len(figures["ratio_each_round"]) == 1

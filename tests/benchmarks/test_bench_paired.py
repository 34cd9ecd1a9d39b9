"""How make bench judges the goals near their bounds: the upload as restore-all (rounds, each against
the bare loop sampled beside it), the project load beside a json.load round by round, and each GUI
stop split at its send on the stop line (this process's part, the simulator's part)."""

from __future__ import annotations

import json
import statistics
from pathlib import Path
from typing import Any

import pytest

from app.points.ledger import PointLedger
from app.points.project import load_project, save_project
from app.points.project_model import Project
from app.sim.config import SimConfig
from app.sim.server import SimController
from benchmarks import points
from benchmarks.core import bench_upload
from benchmarks.restore import ROUNDS


def test_the_upload_ratio_is_the_median_of_rounds_judged_by_the_bare_loop_beside_them() -> None:
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    try:
        out = bench_upload(sim, 2 * ROUNDS, sample_s=0.02)
    finally:
        sim.stop()
    assert out["points"] == 2 * ROUNDS and out["failed"] == 0
    assert len(out["round_ratios"]) == ROUNDS
    # the median of the unrounded ratios, rounded to 2 places (the listed ones to 3)
    assert abs(out["ratio_batched_vs_bound"] - statistics.median(out["round_ratios"])) <= 0.0051
    assert out["bound_per_point_ms"] >= out["controller_latency_ms"]  # the bare loop waits too
    assert out["requests_per_point"] >= 5.0  # pose, params, 440, two status reads
    assert out["ratio_requests_vs_bound"] == out["requests_per_point"] / 4
    for key in ("batched_s", "seed_sequence_s", "min_transactions_bound_s", "rtt_ms", "ratio_total"):
        assert out[key] > 0, key


def test_the_project_load_is_timed_beside_a_json_load_round_by_round(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "bench.teachpad.json"
    save_project(Project("bench", PointLedger(points._points(50))), path)
    calls: list[str] = []
    real_json = json.load

    def load(p: Path) -> object:
        calls.append("product")
        return load_project(p)

    def json_load(f: Any) -> object:
        calls.append("json")
        return real_json(f)

    monkeypatch.setattr(points, "load_project", load)
    monkeypatch.setattr(json, "load", json_load)
    out = points.bench_load(path, 3)
    # one warm-up load, then a load and a json.load in each round, interleaved
    assert calls == ["product"] + ["product", "json"] * 3
    assert out["repeats"] == 3 and out["ratio_load_vs_json"] > 0 and out["ratio_of_medians"] > 0


def test_the_stop_bench_times_each_send_on_the_stop_line_and_puts_the_line_back() -> None:
    from app.link.stop_line import StopLine
    from benchmarks.gui_stop import _SendClock

    original = StopLine.send_stop
    line = StopLine()  # not connected: it cannot take a stop (the worker's queue carries it)
    with _SendClock() as clock:
        assert StopLine.send_stop is not original
        assert line.send_stop() is None
        assert line.stops_requested == 1  # the product's own method ran
    assert clock.sent == [None]  # a stop the line did not carry has no send time
    assert StopLine.send_stop is original

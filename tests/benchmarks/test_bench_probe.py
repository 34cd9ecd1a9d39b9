"""The streaming benchmark measures the GUI thread's own CPU without its 1 ms probe timer."""

from __future__ import annotations

from typing import Any

from benchmarks.gui_stalls import add_no_probe, measure_cpu, measure_stalls


def test_the_probe_costs_the_gui_thread_and_the_quiet_window_does_not_carry_it(qtbot: Any) -> None:
    with_probe = measure_stalls(0.3)
    figures: dict[str, Any] = {"gui_thread_cpu_pct": with_probe["gui_thread_cpu_pct"]}
    add_no_probe(figures, 0.3)
    assert with_probe["firings"] > 10  # the probe ran
    assert 0.0 <= figures["gui_thread_cpu_pct_no_probe"] <= 100.0
    assert figures["process_cpu_pct_no_probe"] >= 0.0
    assert figures["probe_cpu_pct"] == figures["gui_thread_cpu_pct"] - figures["gui_thread_cpu_pct_no_probe"]


def test_a_quiet_event_loop_uses_little_of_the_gui_thread(qtbot: Any) -> None:
    assert measure_cpu(0.2)["gui_thread_cpu_pct"] < 50.0  # waiting, not spinning

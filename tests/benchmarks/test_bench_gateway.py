"""``make bench``'s gateway suite: its quick run (real simulators, a real mosquitto, the product's
edge node) prints its keys and their goals."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from benchmarks.goals import GOALS

ROOT = Path(__file__).resolve().parents[2]
RUN_TIMEOUT = 360.0  # s: the quick suite takes ~20 s; beside eight engineers' work it took over 120

GATEWAY_KEYS = (
    "gateway.gateway_64.cpu_pct_of_one_core",
    "gateway.gateway_64.poll_period_p99_vs_period",
    "gateway.gateway_64.answer_to_subscriber.p99_ms",
    "gateway.dead_one_of_16.others_p99_dead_vs_alive",
)


def _lookup(data: dict[str, Any], key: str) -> Any:
    node: Any = data
    for part in key.split("."):
        assert isinstance(node, dict) and part in node, f"{key}: no {part!r} in {node!r:.300}"
        node = node[part]
    return node


@pytest.mark.timeout(RUN_TIMEOUT + 60)  # its own limit, not the suite's 120 s
def test_the_gateway_suite_quick_run_prints_its_keys_beside_their_goals() -> None:
    env = dict(os.environ, PYTHONPATH=str(ROOT), QT_QPA_PLATFORM="offscreen")
    done = subprocess.run(
        [sys.executable, "-m", "benchmarks.run", "--quick", "--only", "gateway", "--no-compile"],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=RUN_TIMEOUT,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout)
    assert "not_measured" not in out["gateway"], out["gateway"]
    for key in GATEWAY_KEYS:
        value = _lookup(out, key)
        assert isinstance(value, int | float) and value > 0, (key, value)
    assert _lookup(out, "gateway.gateway_64.messages.DDATA") > 0
    # stopped: at most the one answer that was under way when it stopped
    assert _lookup(out, "gateway.dead_one_of_16.one_dead.dead_controller_answers") <= 1
    assert _lookup(out, "gateway.bare_64.poll_period.p99_ms") is not None
    # every SIGSTOPped controller got its DDEATH (the bound's share is a figure, not asserted here)
    assert _lookup(out, "gateway.ddeath_64.silenced") > 0
    assert _lookup(out, "gateway.ddeath_64.sigstop_to_ddeath.n") > 0
    assert isinstance(_lookup(out, "gateway.ddeath_64.within_250_ms_pct"), int | float)
    assert isinstance(_lookup(out, "gateway.ddeath_64.false_ddeaths"), int)
    assert _lookup(out, "gateway.simulators.one_process.cpu_pct_per_controller") is not None
    entries = {e["key"]: e for e in out["goals"]["entries"]}
    for key in GATEWAY_KEYS:
        assert entries[key]["met"] in (True, False) and entries[key]["bound"] is not None
    assert {key for key, *_ in GOALS} >= set(GATEWAY_KEYS)

"""``make bench``'s gateway suite: its quick run (real simulators, a real mosquitto, the product's
edge node) prints its keys and their goals."""

from __future__ import annotations

import pytest

from benchmarks.goals import GOALS
from tests.benchmarks.quick_suite import QUICK_RUN_LIMIT, lookup, quick_run

GATEWAY_KEYS = (
    "gateway.gateway_64.cpu_pct_of_one_core",
    "gateway.gateway_64.poll_period_p99_vs_period",
    "gateway.gateway_64.answer_to_subscriber.p99_ms",
    "gateway.dead_one_of_16.others_p99_dead_vs_alive",
)


@pytest.mark.timeout(QUICK_RUN_LIMIT)
def test_the_gateway_suite_quick_run_prints_its_keys_beside_their_goals() -> None:
    out = quick_run("gateway")
    for key in GATEWAY_KEYS:
        value = lookup(out, key)
        assert isinstance(value, int | float) and value > 0, (key, value)
    assert lookup(out, "gateway.gateway_64.messages.DDATA") > 0
    # stopped: at most the one answer that was under way when it stopped
    assert lookup(out, "gateway.dead_one_of_16.one_dead.dead_controller_answers") <= 1
    assert lookup(out, "gateway.bare_64.poll_period.p99_ms") is not None
    # every SIGSTOPped controller got its DDEATH (the bound's share is a figure, not asserted here)
    assert lookup(out, "gateway.ddeath_64.silenced") > 0
    assert lookup(out, "gateway.ddeath_64.sigstop_to_ddeath.n") > 0
    assert isinstance(lookup(out, "gateway.ddeath_64.within_250_ms_pct"), int | float)
    assert isinstance(lookup(out, "gateway.ddeath_64.false_ddeaths"), int)
    assert lookup(out, "gateway.simulators.one_process.cpu_pct_per_controller") is not None
    entries = {e["key"]: e for e in out["goals"]["entries"]}
    for key in GATEWAY_KEYS:
        assert entries[key]["met"] in (True, False) and entries[key]["bound"] is not None
    assert {key for key, *_ in GOALS} >= set(GATEWAY_KEYS)


def test_every_controller_has_its_answer_list_before_the_pollers_start() -> None:
    # The pollers only append to their lists, so the bench's thread may read the dict while they
    # answer; a poller adding its own key raced that read once ("dictionary changed size during
    # iteration" lost every gateway figure of a make bench).
    from benchmarks.gateway import _edge_node

    node = _edge_node([15020, 15021, 15022], broker_port=1883)  # not started: nothing connects
    assert node.answers_at == {"r00": [], "r01": [], "r02": []}

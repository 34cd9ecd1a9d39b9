"""The watch list's poll budget and what it costs (issue 24), against the simulator.

A poll cycle as the worker's poller runs it (status 560..583, pose 412..511, then the watch list's
reads: :class:`app.link.watch_list.WatchListReader`), timed back to back, beside the pose poll
alone, interleaved in thirds so machine noise hits all alike:

* ``pose_poll_alone``: status + pose (what a poll costs with an empty watch list: the poller
  reads nothing more, ``watch_list_poll_cost_ms.entries_0``);
* ``entries_10``: ten GVs together (GV10..GV19: one block, the fast lane, every poll);
* ``entries_50``: fifty GVs spread over GV0..GV490 (seven inside the pose and status blocks are
  decoded from the poll's own reads; the fast lane holds the first of the others, the rest are
  read one block per poll on the slow clock, each block every
  :data:`app.watchlist.plan.SLOW_PERIOD` s).

``watch_list_poll_cost_ms``: the median cycle minus the pose poll alone's, per list (and the same
of the means, ``_mean``); ``ratio_vs_pose_alone``: the medians' ratio (one extra read beside the
poll's two: about 1.5x expected); ``budget``: the
plan's figures (fast lane reads and registers, slow blocks, the slow refresh at 50 Hz polling).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable
from typing import Any

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.link.ops import SetWatchList
from app.link.watch_list import WatchListReader
from app.sim.config import SimConfig
from app.sim.server import SimController
from app.timing import POLL_HZ_DEFAULT
from app.watchlist import plan as budget
from app.watchlist.entry import Source, WatchEntry
from app.watchlist.plan import ReadPlan

ROUNDS = 30  # turns of each cycle, interleaved

LISTS: dict[str, tuple[WatchEntry, ...]] = {
    "entries_10": tuple(WatchEntry.make(Source.GV, n) for n in range(10, 20)),
    "entries_50": tuple(WatchEntry.make(Source.GV, n) for n in range(0, 500, 10)),
}


def _cycles(fn: Callable[[], object], seconds: float) -> list[float]:
    lat: list[float] = []
    end = time.perf_counter() + seconds
    while True:
        t0 = time.perf_counter()
        fn()
        t1 = time.perf_counter()
        lat.append(t1 - t0)
        if t1 >= end:
            return lat


def _figures(runs: list[list[float]]) -> dict[str, float]:
    lat = sorted(x for run in runs for x in run)
    return {
        "cycles": len(lat),
        "mean_ms": 1000 * statistics.fmean(lat),
        "p50_ms": 1000 * lat[len(lat) // 2],
        "p99_ms": 1000 * lat[min(len(lat) - 1, int(len(lat) * 0.99))],
    }


def _budget(entries: tuple[WatchEntry, ...]) -> dict[str, Any]:
    plan = ReadPlan.of(entries)
    slow = len(plan.slow)
    period = 1.0 / POLL_HZ_DEFAULT
    return {
        "served_by_the_poll_reads": len(plan.served),
        "fast_entries": len(plan.fast_entries()),
        "fast_reads": len(plan.fast),
        "fast_registers": sum(b.count for b in plan.fast),
        "slow_blocks": slow,
        "slow_refresh_s_at_default_poll": max(budget.SLOW_PERIOD, slow * period / budget.SLOW_READS_PER_POLL)
        if slow
        else None,
    }


def bench(sim: SimController, seconds: float) -> dict[str, Any]:
    # a roomy poll timeout: the simulator answers from this process, which a loaded machine holds
    # past the product's 0.15 s; this measures what a poll costs, not silence
    client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, poll_timeout=1.0))
    client.connect()
    timeout = client.settings.effective_poll_timeout
    readers: dict[str, WatchListReader] = {}
    for name, entries in LISTS.items():
        reader = WatchListReader(None, lambda _readings: None)  # type: ignore[arg-type]  # reads only
        reader.set_list(SetWatchList(entries))
        readers[name] = reader

    def pose_alone() -> None:
        client.read_status(timeout=timeout)
        client.read_pose(timeout=timeout)

    def with_list(reader: WatchListReader) -> Callable[[], None]:
        def cycle() -> None:
            pose_alone()
            reader.read(client, timeout)

        return cycle

    cycles = {"pose_poll_alone": pose_alone, **{name: with_list(r) for name, r in readers.items()}}
    runs: dict[str, list[list[float]]] = {name: [] for name in cycles}
    try:
        for fn in cycles.values():
            _cycles(fn, 0.2)  # warm
        for _ in range(ROUNDS):  # short turns, so machine noise hits all alike
            for name, fn in cycles.items():
                runs[name].append(_cycles(fn, seconds / ROUNDS))
    finally:
        client.close()
    out: dict[str, Any] = {name: _figures(r) for name, r in runs.items()}
    alone = out["pose_poll_alone"]
    out["watch_list_poll_cost_ms"] = {"entries_0": 0.0}
    for name, entries in LISTS.items():
        # the medians: a loaded machine's stalls land in the means of whichever cycle they hit
        out[name]["ratio_vs_pose_alone"] = out[name]["p50_ms"] / alone["p50_ms"]
        out[name]["budget"] = _budget(entries)
        out["watch_list_poll_cost_ms"][name] = out[name]["p50_ms"] - alone["p50_ms"]
        out["watch_list_poll_cost_ms"][f"{name}_mean"] = out[name]["mean_ms"] - alone["mean_ms"]
    out["budget"] = {
        "fast_reads": budget.FAST_READS,
        "fast_registers": budget.FAST_REGISTERS,
        "slow_period_s": budget.SLOW_PERIOD,
        "slow_reads_per_poll": budget.SLOW_READS_PER_POLL,
        "merge_gap_registers": budget.MERGE_GAP,
        "slow_merge_gap_registers": budget.SLOW_MERGE_GAP,
    }
    return out


def run(quick: bool) -> dict[str, Any]:
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    try:
        return bench(sim, seconds=3.0 if quick else 9.0)
    finally:
        sim.stop()


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick=True), indent=2))

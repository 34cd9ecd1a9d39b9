"""Requests and time per created point on each simulator timing profile (issue 13).

For every (timing, GV291) profile of the simulator: ``RobotClient.upload_points`` (the GUI's
restore-all path) of N points with completion "auto", one point refused by the controller in
the middle. Reported per profile: the rule the client chose, requests per point (the client's
own transaction count), ms per point, failures other than the injected one, false successes
(reported ok, not held by the controller) and unconfirmed results. Part of the ``points``
suite (``points.completion_profiles``).
"""

from __future__ import annotations

import time
from typing import Any

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.sim.config import GV291_MODES, TIMING_PROFILES, SimConfig
from app.sim.server import SimController


def _poses(n: int) -> list[tuple[int, list[float]]]:
    return [
        (i, [300.0 + i % 100, -100.0 + i % 50, 300.0 + i % 20, 180.0, 0.0, float(i % 90)])
        for i in range(1, n + 1)
    ]


def bench_profile(timing: str, gv291: str, n: int) -> dict[str, Any]:
    sim = SimController(SimConfig(host="127.0.0.1", port=0, timing=timing, gv291=gv291))  # type: ignore[arg-type]
    sim.start()
    refused = n // 2
    try:
        sim.refuse_point(refused)
        client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port))
        client.connect()
        try:
            assert client.create_point(n + 1, pose=[300.0, 0.0, 300.0, 180.0, 0.0, 0.0]).ok  # probe, warm up
            before = client.stats.requests
            t0 = time.perf_counter()
            results = client.upload_points(_poses(n))
            seconds = time.perf_counter() - t0
            requests = client.stats.requests - before
            rule = client.completion_rule
        finally:
            client.close()
        held = sim.state().points
    finally:
        sim.stop()
    ids = [int(r.details["point_id"]) for r in results]
    return {
        "rule": rule,
        "points": n,
        "requests_per_point": round(requests / n, 2),
        "ms_per_point": round(1000.0 * seconds / n, 3),
        "failed_other": sum(1 for i, r in zip(ids, results, strict=True) if not r.ok and i != refused),
        "injected_error_reported": any(i == refused and not r.ok for i, r in zip(ids, results, strict=True)),
        "false_successes": sum(1 for i, r in zip(ids, results, strict=True) if r.ok and i not in held),
        "unconfirmed": sum(1 for r in results if r.unconfirmed),
    }


def bench_profiles(n: int) -> dict[str, Any]:
    return {
        f"{t}_{g.replace('-', '_')}": bench_profile(t, g, n) for t in TIMING_PROFILES for g in GV291_MODES
    }

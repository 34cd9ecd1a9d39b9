"""Where a created point's time goes in ``RobotClient.upload_points`` (issue 10), staged vs not.

Against the simulator in this process (classic timing, 1 ms command latency, as ``core``'s upload),
interleaved rounds of N points with the next pose staged (the default) and without
(``stage=False``), so machine noise hits both alike. Per point (ms, median over the rounds):

* ``wall``; ``requests`` (per point) and ``in_requests`` (wall time inside our transport's
  request calls: framing, the wire, the simulator's answer);
* ``python_outside`` (our thread's CPU between requests: tracker, encoding, loop);
* ``waits`` (the rest: the pacer's sleeps while the controller works, and being scheduled);
* ``bound`` (``core``'s minimal-transactions bound: 4 x the round trip of a bare pymodbus read
  measured around each round, plus the latency) and ``ratio`` = wall / bound.

Usage: python -m benchmarks.completion_split [--points 500] [--rounds 6]. Prints one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from collections.abc import Callable
from typing import Any

from pymodbus.client import ModbusTcpClient

from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.protocol import registers as R  # noqa: N812
from app.sim.config import SimConfig
from app.sim.server import SimController


def _poses(n: int) -> list[tuple[int, list[float]]]:
    return [
        (i + 1, [300.0 + (i % 100), -100.0 + (i % 50), 300.0 + (i % 20), 180.0, 0.0, float(i % 90)])
        for i in range(n)
    ]


def _rtt(bare: ModbusTcpClient) -> float:
    samples = []
    for _ in range(300):
        t0 = time.perf_counter()
        bare.read_holding_registers(R.gv_reg(291), count=2, device_id=1)
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples)


class _Timed:
    """Wraps the transport's ``execute``: wall and thread CPU spent inside requests."""

    def __init__(self, execute: Callable[..., Any]) -> None:
        self._execute = execute
        self.wall = self.cpu = 0.0
        self.count = 0

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        w0, c0 = time.perf_counter(), time.thread_time()
        try:
            return self._execute(*args, **kwargs)
        finally:
            self.wall += time.perf_counter() - w0
            self.cpu += time.thread_time() - c0
            self.count += 1


def run(points: int, rounds: int) -> dict[str, Any]:
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    latency = sim.config.command_latency
    client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port))
    bare = ModbusTcpClient("127.0.0.1", port=sim.port, timeout=1.0)
    rows: dict[str, list[dict[str, float]]] = {"staged": [], "unstaged": []}
    loads = []
    try:
        client.connect()
        bare.connect()
        batch = _poses(points)
        client.upload_points(batch[:50])  # completion "auto" probes GV291 here, not in a round
        timed = _Timed(client._transport.execute)
        client._transport.execute = timed  # type: ignore[method-assign]
        for _ in range(rounds):
            for name in rows:
                sim.restart_controller()
                loads.append(os.getloadavg()[0])
                rtt = _rtt(bare)
                timed.wall = timed.cpu = 0.0
                timed.count = 0
                c0, w0 = time.thread_time(), time.perf_counter()
                results = client.upload_points(batch, stage=name == "staged")
                wall, cpu = time.perf_counter() - w0, time.thread_time() - c0
                rtt = (rtt + _rtt(bare)) / 2
                held = sim.state().points
                bad = sum(1 for r in results if not r.ok) + sum(1 for pid, _ in batch if pid not in held)
                python_outside = cpu - timed.cpu
                bound = 4 * rtt + latency
                rows[name].append(
                    {
                        "wall": 1000 * wall / points,
                        "requests": timed.count / points,
                        "in_requests": 1000 * timed.wall / points,
                        "python_outside": 1000 * python_outside / points,
                        "waits": 1000 * (wall - timed.wall - python_outside) / points,
                        "bound": 1000 * bound,
                        "ratio": wall / points / bound,
                        "failed_or_not_held": float(bad),
                    }
                )
    finally:
        client.close()
        bare.close()
        sim.stop()
    out: dict[str, Any] = {
        "points": points,
        "rounds": rounds,
        "controller_latency_ms": 1000 * latency,
        "load": [round(min(loads), 2), round(max(loads), 2)],
    }
    for name, samples in rows.items():
        out[name] = {k: round(statistics.median(s[k] for s in samples), 4) for k in samples[0]}
        out[name]["failed_or_not_held"] = sum(s["failed_or_not_held"] for s in samples)
        out[name]["ratio_each_round"] = [round(s["ratio"], 3) for s in samples]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=500)
    parser.add_argument("--rounds", type=int, default=6)
    args = parser.parse_args()
    print(json.dumps(run(args.points, args.rounds), indent=1))


if __name__ == "__main__":
    main()

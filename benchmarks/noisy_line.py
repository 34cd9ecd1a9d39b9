"""A 200-point upload over a noisy RTU serial line (issue 19 section 4, its "Done when" figure).

The simulator serves one pty, ``teachpad-cli points upload``'s own upload
(:func:`app.cli.points_upload.staged_upload`) drives a :class:`~app.link.client.RobotClient` on the
other, and the relay between them (:class:`tests.link.serial.relay.PtyRelay`) damages one byte in
``damage_one_in`` in both directions (seeded: run ``i`` uses seed ``i``). Per run: did the upload
finish (every point reported uploaded, nothing aborted), and how many of the project's points the
controller holds wrong (missing, another pose, another tool) -- counted at the simulator.

Usage: python -m benchmarks.noisy_line [--runs N] [--points N] [--damage N]
"""

from __future__ import annotations

import argparse
import json
import random
import struct
import sys
import time
from typing import Any

from app.cli.points_upload import staged_upload
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.points.point import TempPoint
from app.sim.config import SimConfig
from app.sim.server import SimController
from tests.link.serial.relay import PtyRelay

BAUD = 115200
# s per request: the longest answer (125 registers, 255 bytes) is 22 ms on the wire at 115200 baud;
# a damaged request is never answered, so each costs one timeout
TIMEOUT = 0.3


def _f32(value: float) -> float:
    return float(struct.unpack("<f", struct.pack("<f", value))[0])


def project_points(n: int, seed: int = 19) -> list[TempPoint]:
    rng = random.Random(seed)
    points = []
    for i in range(n):
        x, y, z = (round(rng.uniform(-600.0, 600.0), 3) for _ in range(3))
        a, b, c = (round(rng.uniform(-180.0, 180.0), 3) for _ in range(3))
        points.append(TempPoint(i + 1, f"P{i + 1}", x, y, z, a, b, c, tool=(i // 50) % 2))
    return points


def _same_pose(held: tuple[float, ...], sent: tuple[float, ...]) -> bool:
    """``held`` (the controller's float32 values) is ``sent`` as float32."""
    return all(abs(h - _f32(s)) <= 1e-6 * max(1.0, abs(s)) for h, s in zip(held, sent, strict=True))


def wrong_points(sim: SimController, points: list[TempPoint]) -> int:
    """The project's points the controller does not hold as sent (missing, another pose or tool)."""
    with sim.lock:
        stored = dict(sim.robot.points)
    wrong = 0
    for p in points:
        got = stored.get(p.id)
        if got is None or got.tool != p.tool or not _same_pose(got.pose, p.xyzabc):
            wrong += 1
    return wrong


def one_run(n: int, damage_one_in: int, seed: int) -> dict[str, Any]:
    relay = PtyRelay(BAUD, damage_one_in=damage_one_in, seed=seed)
    sim = SimController(SimConfig(serial_port=relay.sim_port, baudrate=BAUD))
    client = RobotClient(ConnectionSettings(serial_port=relay.host_port, baudrate=BAUD, timeout=TIMEOUT))
    points = project_points(n)
    try:
        sim.start()
        client.connect()
        started = time.perf_counter()
        try:
            report = staged_upload(client, points)
            aborted = report.aborted
            uploaded = sum(1 for o in report.outcomes if o.ok)
        except Exception as exc:  # today's code may raise out of it: the run did not finish
            aborted, uploaded = f"{type(exc).__name__}: {exc}", 0
        seconds = time.perf_counter() - started
        stats = client.stats
        return {
            "finished": aborted is None and uploaded == n,
            "uploaded": uploaded,
            "wrong_points": wrong_points(sim, points),
            "seconds": round(seconds, 2),
            "bytes_damaged": sum(relay.damaged.values()),
            "malformed_answers": stats.malformed,
            "timeouts": stats.timeouts,
            "ended": (aborted or "")[:160],
        }
    finally:
        client.close()
        sim.stop()
        relay.close()


def bench_noisy_upload(n: int = 200, damage_one_in: int = 500, runs: int = 3) -> dict[str, Any]:
    results = [one_run(n, damage_one_in, seed) for seed in range(runs)]
    return {
        "points": n,
        "damage_one_byte_in": damage_one_in,
        "baud": BAUD,
        "runs": runs,
        "finished": sum(1 for r in results if r["finished"]),
        "wrong_points_total": sum(r["wrong_points"] for r in results),
        "runs_detail": results,
    }


def run(quick: bool) -> dict[str, Any]:
    return {"rtu_upload_200_points_1_in_500": bench_noisy_upload(runs=1 if quick else 3)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--points", type=int, default=200)
    parser.add_argument("--damage", type=int, default=500, help="one byte in N damaged")
    args = parser.parse_args(argv)
    json.dump(bench_noisy_upload(args.points, args.damage, args.runs), sys.stdout, indent=2)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

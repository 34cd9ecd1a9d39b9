"""Restore-all (``RobotClient.upload_points``, the GUI's path) vs a bare pymodbus loop in the same run.

The restore is split into rounds (one ``upload_points`` call each; a call costs one status read
and the tool write's cache check more than a point does, nothing measurable per 1,000 points).
Right before the first round and after every round a bare pymodbus client (its own connection to
the same simulator) runs the minimal transactions of one point for :data:`SAMPLE_S`. Each round
is compared with the bare loop sampled beside it (the samples before and after it, pooled), and
the reported ratio is the **median** of the round ratios: a slow stretch of the machine hits a
round and the samples beside it alike, and one bad round does not move the median.

The bare bound of one point (``bound_per_point_ms``), with the product's frame shapes:
the parameters write (0x10, GV200-202), a one-register write (0x06: a general-purpose GV, not
440, so the bare loop sends no command and costs the simulator less than the product's 440),
and the status-block read (0x03, 560..583) in a row, plus the larger of the controller's
latency and the pose write (0x10, six GVs) -- a client can write the next pose while the
controller works, as the product's staging does. That is 3 round trips + the latency; the old
bound, kept as ``ratio_total`` (whole run, one pooled median), was 4 x a two-register read +
the latency.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from pymodbus.client import ModbusTcpClient

from app.cli.points_upload import staged_upload
from app.link.client import ConnectionSettings, RobotClient
from app.points.ledger import TempPoint
from app.protocol import registers as R  # noqa: N812
from app.protocol.codec import encode_floats
from app.sim import SimConfig, SimController

__all__ = ["BareSample", "RestoreRound", "bare_sample", "bench_restore", "summarize"]

ROUNDS = 10
SAMPLE_S = 0.25  # s of bare transactions before the first round and after each round
QUICK_SAMPLE_S = 0.1
WARM_CYCLES = 5  # unmeasured bare cycles at the start of each sample (the product just ran)
OLD_TX_PER_POINT = 4  # the old bound: 4 x a GV291 read + the latency
_BARE_POSE_GV = 12  # GV12..GV17: neither of the upload's pose blocks (GV0.., GV6..)
_BARE_SINGLE_REG = R.gv_reg(R.GV_GENERAL_LAST)  # a general GV's word: an 0x06 that starts nothing
_UNIT = 1


@dataclass
class BareSample:
    """One stretch of the bare loop (seconds per transaction or per cycle)."""

    cycle: list[float] = field(default_factory=list)  # params 0x10 + 0x06 + status read, in a row
    pose: list[float] = field(default_factory=list)  # the pose write (0x10, 12 registers)
    read: list[float] = field(default_factory=list)  # a GV291 read (2 registers): the old rtt


@dataclass
class RestoreRound:
    points: int
    seconds: float


def bare_sample(bare: ModbusTcpClient, seconds: float) -> BareSample:
    """Run the bare per-point transactions for ``seconds`` (after :data:`WARM_CYCLES` unmeasured)."""
    pose = encode_floats([300.0, -100.0, 300.0, 180.0, 0.0, 45.0])
    params = encode_floats([1.0, 1.0, 0.0])
    sample = BareSample()
    clock = time.perf_counter
    end = None
    n = 0
    while end is None or clock() < end:
        t0 = clock()
        bare.write_registers(R.gv_reg(_BARE_POSE_GV), pose, device_id=_UNIT)
        t1 = clock()
        bare.write_registers(R.gv_reg(R.GV_PARAM0), params, device_id=_UNIT)
        bare.write_register(_BARE_SINGLE_REG, 0, device_id=_UNIT)
        bare.read_holding_registers(R.STATUS_BLOCK_START, count=R.STATUS_BLOCK_COUNT, device_id=_UNIT)
        t2 = clock()
        bare.read_holding_registers(R.gv_reg(R.GV_COMMAND_STATUS), count=2, device_id=_UNIT)
        t3 = clock()
        n += 1
        if n > WARM_CYCLES:
            sample.pose.append(t1 - t0)
            sample.cycle.append(t2 - t1)
            sample.read.append(t3 - t2)
        elif n == WARM_CYCLES:
            end = clock() + seconds
    return sample


def _pooled(samples: Sequence[BareSample]) -> BareSample:
    out = BareSample()
    for s in samples:
        out.cycle += s.cycle
        out.pose += s.pose
        out.read += s.read
    return out


def bound_per_point(sample: BareSample, latency: float) -> float:
    """The bare loop's time for one point (s): 3 round trips + max(latency, pose write)."""
    return statistics.median(sample.cycle) + max(latency, statistics.median(sample.pose))


def summarize(
    rounds: Sequence[RestoreRound], samples: Sequence[BareSample], latency: float
) -> dict[str, Any]:
    """The figures of a restore split into ``rounds``; ``samples[k]`` was taken before round k and
    ``samples[k + 1]`` after it (``len(samples) == len(rounds) + 1``)."""
    if len(samples) != len(rounds) + 1 or not rounds:
        raise ValueError(f"{len(rounds)} rounds need {len(rounds) + 1} bare samples, got {len(samples)}")
    ratios, bounds = [], []
    for k, rnd in enumerate(rounds):
        bound = rnd.points * bound_per_point(_pooled(samples[k : k + 2]), latency)
        bounds.append(bound)
        ratios.append(rnd.seconds / bound)
    n = sum(r.points for r in rounds)
    restore_s = sum(r.seconds for r in rounds)
    everything = _pooled(samples)
    rtt = statistics.median(everything.read)
    old_bound = n * (OLD_TX_PER_POINT * rtt + latency)
    return {
        "restore_s": round(restore_s, 3),
        "points_per_s": round(n / restore_s, 1),
        "min_transactions_bound_s": round(sum(bounds), 3),
        "ratio_vs_bound": round(statistics.median(ratios), 2),
        "ratio_method": (
            f"median over {len(rounds)} rounds of round time / (points x bare per-point bound "
            "sampled just before and after that round)"
        ),
        "round_ratios": [round(r, 3) for r in ratios],
        "round_s": [round(r.seconds, 3) for r in rounds],
        "ratio_whole_run_vs_bound": round(restore_s / sum(bounds), 2),
        "ratio_total": round(restore_s / old_bound, 2),
        "ratio_total_method": "the old figure: whole run / (n x (4 x median GV291 read + latency))",
        "rtt_ms": round(1000.0 * rtt, 4),
        "bare_cycle_ms": round(1000.0 * statistics.median(everything.cycle), 4),
        "bare_pose_write_ms": round(1000.0 * statistics.median(everything.pose), 4),
        "bound_per_point_ms": round(1000.0 * bound_per_point(everything, latency), 4),
        "bound_transactions": (
            "params 0x10 (GV200-202) + 0x06 + status read (560..583) + max(latency, pose 0x10)"
        ),
        "bare_cycles_per_sample": [len(s.cycle) for s in samples],
    }


def bench_restore(
    points: Sequence[TempPoint], cli_n: int, *, rounds: int = ROUNDS, sample_s: float = SAMPLE_S
) -> dict[str, Any]:
    """Restore ``points`` in ``rounds`` calls of ``upload_points``; the CLI's path on the first ``cli_n``."""
    n = len(points)
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    try:
        bare = ModbusTcpClient("127.0.0.1", port=sim.port, timeout=1.0)
        if not bare.connect():
            raise RuntimeError("the bare pymodbus client cannot connect to the simulator")
        client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port))
        client.connect()
        try:
            samples = [bare_sample(bare, sample_s)]
            done: list[RestoreRound] = []
            results = []
            size = -(-n // rounds)
            for start in range(0, n, size):
                chunk = [(p.id, p.xyzabc) for p in points[start : start + size]]
                t0 = time.perf_counter()
                results += client.upload_points(chunk)
                done.append(RestoreRound(len(chunk), time.perf_counter() - t0))
                samples.append(bare_sample(bare, sample_s))
            failed = sum(1 for r in results if not r.ok) + n - len(results)
            held = len(sim.state().points)
            sim.restart_controller()
            cli = _cli_path(client, list(points[:cli_n]))
        finally:
            client.close()
            bare.close()
        latency = sim.config.command_latency
    finally:
        sim.stop()
    figures = summarize(done, samples, latency)
    out: dict[str, Any] = {
        "points": n,
        "path": "RobotClient.upload_points (the GUI's restore-all, via the worker)",
        "rounds": len(done),
        "points_per_round": size,
        "failed": failed,
        "held_by_controller": held,
        "controller_latency_ms": 1000.0 * latency,
        "bare_sample_s": sample_s,
        **figures,
    }
    cli["restore_ms_per_point"] = round(1000.0 * figures["restore_s"] / n, 3)
    cli["ratio_cli_vs_restore"] = round(cli["ms_per_point"] / cli["restore_ms_per_point"], 2)
    out["cli_path"] = cli
    return out


def _cli_path(client: RobotClient, sample: list[TempPoint]) -> dict[str, Any]:
    t0 = time.perf_counter()
    report = staged_upload(client, sample)
    cli_s = time.perf_counter() - t0
    return {
        "path": "app.cli.points_upload.staged_upload (teachpad-cli points upload)",
        "points": len(sample),
        "failed": len(report.failed) + len(report.not_attempted),
        "ms_per_point": round(1000.0 * cli_s / len(sample), 3),
    }

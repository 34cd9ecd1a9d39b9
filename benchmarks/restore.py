"""Restore-all (``RobotClient.upload_points``, the GUI's path) vs a bare pymodbus loop in the same run.

The restore is split into rounds (one ``upload_points`` call each: a call costs one status read
more than its points do, ``requests_per_point`` shows it). Right before the first round and
after every round a bare pymodbus client (its own connection to the same simulator) runs one
point's minimal work in a loop for :data:`SAMPLE_S` (:func:`bare_sample`). Each round is
compared with the bare cycles sampled beside it (before and after it, pooled), and the reported
``ratio_vs_bound`` is the **median** of the round ratios: a slow stretch of the machine hits a
round and the samples beside it alike, and one bad round does not move the median. Within a
round both sides are means (the round's time per point, the bare loop's time per cycle): a
wake-up that comes late on a busy machine counts for both; a bare median against the product's
mean (as the old figure did) would count it for the product only.

The bare cycle, with the product's frame shapes: parameters (0x10, GV200-202), a one-register
write standing for 440 (0x06 into a general-purpose GV: it starts nothing and costs the
simulator less than a command), the next pose (0x10, six GVs) while the controller would work --
as the product's staging does --, a real sleep until the controller's latency has passed, the
status-block read (0x03, 560..583): 4 transactions, one of them hidden in the latency. Kept for
comparison: ``ratio_vs_formula_bound`` (the same round trips + the latency as a number, no
sleep), ``ratio_vs_median_cycle`` and ``ratio_total``, the old figure (whole run / n x
(4 x a two-register read + latency)).
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from pymodbus.client import ModbusTcpClient

from app.cli.points_upload import staged_upload
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.models import CommandResult
from app.points.point import TempPoint
from app.protocol import registers as R  # noqa: N812
from app.protocol.codec import encode_floats
from app.sim.config import SimConfig
from app.sim.server import SimController

__all__ = ["BareSample", "RestoreRound", "bare_sample", "bench_restore", "summarize", "upload_in_rounds"]

ROUNDS = 20
SAMPLE_S = 0.2  # s of the bare loop before the first round and after each round
QUICK_SAMPLE_S = 0.1
WARM_CYCLES = 5  # unmeasured bare cycles at the start of each sample (the product just ran)
OLD_TX_PER_POINT = 4  # the old bound: 4 x a GV291 read + the latency
_BARE_POSE_GV = 12  # GV12..GV17: neither of the upload's pose blocks (GV0.., GV6..)
_BARE_SINGLE_REG = R.gv_reg(R.GV_GENERAL_LAST)  # a general GV's word: an 0x06 that starts nothing
_UNIT = 1


@dataclass
class BareSample:
    """One stretch of the bare loop: per cycle (one point's work), seconds."""

    cpu: float = 0.0  # s of this thread's CPU over the measured cycles (time.thread_time)
    cycle: list[float] = field(default_factory=list)  # the whole cycle, the wait included: the bound
    formula: list[float] = field(default_factory=list)  # its 3 round trips + max(latency, pose write)
    pose: list[float] = field(default_factory=list)  # the pose write (0x10, 12 registers)
    read: list[float] = field(default_factory=list)  # a GV291 read (2 registers): the old rtt


@dataclass
class RestoreRound:
    points: int
    seconds: float
    cpu: float = 0.0  # s of this thread's CPU in the round (the simulator runs in other threads)


def bare_sample(bare: ModbusTcpClient, seconds: float, latency: float) -> BareSample:
    """Run the bare loop for ``seconds`` (after :data:`WARM_CYCLES` unmeasured cycles).

    A cycle is one point's minimal work: parameters (0x10), the one-register write that stands
    for 440 (0x06), the next pose (0x10) while the controller would work, a sleep until
    ``latency`` after that write reached the controller (the middle of its round trip), the
    status read (0x03). The sleep is a real one: the product waits for the controller too, and
    on a busy machine a wake-up is late for both. A GV291 read after each cycle, not in it, keeps
    the old figure's round trip.
    """
    pose = encode_floats([300.0, -100.0, 300.0, 180.0, 0.0, 45.0])
    params = encode_floats([1.0, 1.0, 0.0])
    sample = BareSample()
    clock = time.perf_counter
    end = None
    n = 0
    cpu0 = 0.0
    while end is None or clock() < end:
        t0 = clock()
        bare.write_registers(R.gv_reg(R.GV_PARAM0), params, device_id=_UNIT)
        t1 = clock()
        bare.write_register(_BARE_SINGLE_REG, 0, device_id=_UNIT)
        t2 = clock()
        bare.write_registers(R.gv_reg(_BARE_POSE_GV), pose, device_id=_UNIT)
        t3 = clock()
        left = (t1 + t2) / 2.0 + latency - t3
        if left > 0:
            time.sleep(left)
        t4 = clock()
        bare.read_holding_registers(R.STATUS_BLOCK_START, count=R.STATUS_BLOCK_COUNT, device_id=_UNIT)
        t5 = clock()
        bare.read_holding_registers(R.gv_reg(R.GV_COMMAND_STATUS), count=2, device_id=_UNIT)
        t6 = clock()
        n += 1
        if n > WARM_CYCLES:
            sample.cycle.append(t5 - t0)
            sample.formula.append((t2 - t0) + (t5 - t4) + max(latency, t3 - t2))
            sample.pose.append(t3 - t2)
            sample.read.append(t6 - t5)
        elif n == WARM_CYCLES:
            end = clock() + seconds
            cpu0 = time.thread_time()
    sample.cpu = time.thread_time() - cpu0
    return sample


def _pooled(samples: Sequence[BareSample]) -> BareSample:
    out = BareSample()
    for s in samples:
        out.cpu += s.cpu
        out.cycle += s.cycle
        out.formula += s.formula
        out.pose += s.pose
        out.read += s.read
    return out


def bound_per_point(sample: BareSample) -> float:
    """The bare loop's time for one point (s): the mean cycle (as the round's time per point is)."""
    return statistics.fmean(sample.cycle)


def summarize(
    rounds: Sequence[RestoreRound], samples: Sequence[BareSample], latency: float
) -> dict[str, Any]:
    """The figures of a restore split into ``rounds``; ``samples[k]`` was taken before round k and
    ``samples[k + 1]`` after it (``len(samples) == len(rounds) + 1``)."""
    if len(samples) != len(rounds) + 1 or not rounds:
        raise ValueError(f"{len(rounds)} rounds need {len(rounds) + 1} bare samples, got {len(samples)}")
    ratios, bounds, formula_ratios, median_ratios = [], [], [], []
    for k, rnd in enumerate(rounds):
        beside = _pooled(samples[k : k + 2])
        bound = rnd.points * bound_per_point(beside)
        bounds.append(bound)
        ratios.append(rnd.seconds / bound)
        formula_ratios.append(rnd.seconds / (rnd.points * statistics.fmean(beside.formula)))
        median_ratios.append(rnd.seconds / (rnd.points * statistics.median(beside.cycle)))
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
            f"median over {len(rounds)} rounds of: round time / (points x mean bare cycle "
            "sampled just before and after that round)"
        ),
        "round_ratios": [round(r, 3) for r in ratios],
        "round_s": [round(r.seconds, 3) for r in rounds],
        "ratio_whole_run_vs_bound": round(restore_s / sum(bounds), 2),
        "ratio_vs_formula_bound": round(statistics.median(formula_ratios), 2),
        "ratio_vs_median_cycle": round(statistics.median(median_ratios), 2),
        "ratio_total": round(restore_s / old_bound, 2),
        "ratio_total_method": "the old figure: whole run / (n x (4 x median GV291 read + latency))",
        "rtt_ms": round(1000.0 * rtt, 4),
        "bound_per_point_ms": round(1000.0 * bound_per_point(everything), 4),
        "median_cycle_ms": round(1000.0 * statistics.median(everything.cycle), 4),
        "formula_bound_per_point_ms": round(1000.0 * statistics.fmean(everything.formula), 4),
        "bare_pose_write_ms": round(1000.0 * statistics.median(everything.pose), 4),
        "bare_cycle": (
            "params 0x10 (GV200-202), 0x06, pose 0x10, sleep to latency after the 0x06, "
            "status read (560..583); formula: its 3 round trips + max(latency, pose write)"
        ),
        "bare_cycles_per_sample": [len(s.cycle) for s in samples],
        # the client's own CPU (its thread; the simulator's threads excluded): under CPU contention
        # the side with more CPU per point is slowed more
        "client_cpu_ms_per_point": round(1000.0 * sum(r.cpu for r in rounds) / n, 4),
        # (a cycle's GV291 read for the old figure included: 5 transactions, as the product's point)
        "bare_cpu_ms_per_cycle": round(1000.0 * everything.cpu / max(1, len(everything.cycle)), 4),
    }


def upload_in_rounds(
    client: RobotClient,
    bare: ModbusTcpClient,
    items: Sequence[tuple[int, Sequence[float]]],
    size: int,
    sample_s: float,
    latency: float,
) -> tuple[list[RestoreRound], list[BareSample], list[CommandResult]]:
    """``client.upload_points`` on ``items`` in rounds of ``size``, a bare sample before the first
    round and after each (what :func:`summarize` takes): (rounds, samples, results)."""
    samples = [bare_sample(bare, sample_s, latency)]
    done: list[RestoreRound] = []
    results: list[CommandResult] = []
    for start in range(0, len(items), size):
        chunk = list(items[start : start + size])
        t0, cpu0 = time.perf_counter(), time.thread_time()
        results += client.upload_points(chunk)
        done.append(RestoreRound(len(chunk), time.perf_counter() - t0, time.thread_time() - cpu0))
        samples.append(bare_sample(bare, sample_s, latency))
    return done, samples, results


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
            latency = sim.config.command_latency
            size = -(-n // rounds)
            requests = client.stats.requests
            done, samples, results = upload_in_rounds(
                client, bare, [(p.id, p.xyzabc) for p in points], size, sample_s, latency
            )
            requests = client.stats.requests - requests
            failed = sum(1 for r in results if not r.ok) + n - len(results)
            held = len(sim.state().points)
            sim.restart_controller()
            cli = _cli_path(client, list(points[:cli_n]))
        finally:
            client.close()
            bare.close()
    finally:
        sim.stop()
    figures = summarize(done, samples, latency)
    out: dict[str, Any] = {
        "points": n,
        "path": (
            "RobotClient.upload_points in rounds: the call the GUI's restore-all makes through the "
            "worker (there per chunk of 20, with polls between chunks; here without the worker)"
        ),
        "rounds": len(done),
        "points_per_round": size,
        "failed": failed,
        "held_by_controller": held,
        "controller_latency_ms": 1000.0 * latency,
        "bare_sample_s": sample_s,
        "requests_per_point": round(requests / n, 3),  # the rounds' own: one status read per call
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

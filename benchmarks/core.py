"""Controller-core benchmarks: monitor cycle rate and temp-point upload, against the simulator.

Each figure is measured side by side in the same run with a baseline:
* monitor cycle (pose read 412..511 + status read 560..583): RobotClient vs a bare pymodbus
  loop doing the same two reads vs a raw-socket loop sending the same two Modbus TCP frames;
* uploading N temp points from host poses (case 2.2): RobotClient.upload_points (batched) vs
  the seed's step-by-step sequence (one write per parameter) vs the minimal-transactions bound
  (a bare pymodbus loop doing one point's minimal work, sampled around each of 20 rounds: the
  method of :mod:`benchmarks.restore`).
"""

from __future__ import annotations

import socket
import statistics
import struct
import time
from collections.abc import Callable
from typing import Any

from pymodbus.client import ModbusTcpClient

from app.connection import ConnectionSettings
from app.link import frames
from app.link.client import RobotClient
from app.protocol import registers as R  # noqa: N812
from app.protocol.codec import encode_floats
from app.protocol.enums import RunCommand, decode_status_registers
from app.sim.config import SimConfig
from app.sim.server import SimController
from benchmarks import restore


def _rate(fn: Callable[[], object], seconds: float) -> dict[str, float]:
    """Run fn repeatedly for about `seconds`; cycles per second and latency percentiles (ms)."""
    lat: list[float] = []
    end = time.perf_counter() + seconds
    while True:
        t0 = time.perf_counter()
        fn()
        t1 = time.perf_counter()
        lat.append(t1 - t0)
        if t1 >= end:
            break
    lat.sort()
    total = sum(lat)
    return {
        "cycles": len(lat),
        "hz": len(lat) / total,
        "p50_ms": 1000 * lat[len(lat) // 2],
        "p99_ms": 1000 * lat[min(len(lat) - 1, int(len(lat) * 0.99))],
    }


class RawModbusSocket:
    """The leanest possible Modbus TCP client: prebuilt request frames over one socket."""

    def __init__(self, host: str, port: int, unit: int = 1) -> None:
        self.sock = socket.create_connection((host, port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.unit = unit
        self.tid = 0

    def read(self, address: int, count: int) -> bytes:
        self.tid = (self.tid + 1) & 0xFFFF
        self.sock.sendall(struct.pack(">HHHBBHH", self.tid, 0, 6, self.unit, 3, address, count))
        return self._recv_frame()

    def _recv_frame(self) -> bytes:
        head = self._recv_exact(6)
        (length,) = struct.unpack(">H", head[4:6])
        return head + self._recv_exact(length)

    def _recv_exact(self, n: int) -> bytes:
        buf = b""
        while len(buf) < n:
            chunk = self.sock.recv(n - len(buf))
            if not chunk:
                raise ConnectionError("server closed the connection")
            buf += chunk
        return buf

    def close(self) -> None:
        self.sock.close()


def bench_monitor(sim: SimController, seconds: float) -> dict[str, Any]:
    host, port = "127.0.0.1", sim.port
    client = RobotClient(ConnectionSettings(host=host, port=port))
    client.connect()

    def robot_cycle() -> None:
        client.read_pose()
        client.read_status()

    bare = ModbusTcpClient(host, port=port, timeout=1.0)
    bare.connect()

    def bare_cycle() -> None:
        bare.read_holding_registers(R.POSE_BLOCK_START, count=R.POSE_BLOCK_COUNT, device_id=1)
        bare.read_holding_registers(R.STATUS_BLOCK_START, count=R.STATUS_BLOCK_COUNT, device_id=1)

    raw = RawModbusSocket(host, port)

    def raw_cycle() -> None:
        raw.read(R.POSE_BLOCK_START, R.POSE_BLOCK_COUNT)
        raw.read(R.STATUS_BLOCK_START, R.STATUS_BLOCK_COUNT)

    try:
        for warm in (robot_cycle, bare_cycle, raw_cycle):
            for _ in range(50):
                warm()
        # interleave the three in thirds so machine noise hits all alike
        names = ("robot_client", "bare_pymodbus", "raw_socket")
        results: dict[str, list[dict[str, float]]] = {name: [] for name in names}
        for _ in range(3):
            results["robot_client"].append(_rate(robot_cycle, seconds / 3))
            results["bare_pymodbus"].append(_rate(bare_cycle, seconds / 3))
            results["raw_socket"].append(_rate(raw_cycle, seconds / 3))
    finally:
        client.close()
        bare.close()
        raw.close()
    out: dict[str, Any] = {}
    for name, runs in results.items():
        out[name] = {
            "hz": statistics.median(r["hz"] for r in runs),
            "p50_ms": statistics.median(r["p50_ms"] for r in runs),
            "p99_ms": statistics.median(r["p99_ms"] for r in runs),
        }
    out["ratio_robot_vs_bare"] = out["robot_client"]["hz"] / out["bare_pymodbus"]["hz"]
    out["ratio_robot_vs_raw"] = out["robot_client"]["hz"] / out["raw_socket"]["hz"]
    return out


def _poses(n: int) -> list[tuple[int, list[float]]]:
    return [
        (i + 1, [300.0 + (i % 100), -100.0 + (i % 50), 300.0 + (i % 20), 180.0, 0.0, float(i % 90)])
        for i in range(n)
    ]


def _seed_upload(bare: ModbusTcpClient, points: list[tuple[int, list[float]]]) -> None:
    """Case 2.2 steps 3-9 as the seed prints them: one write per parameter, then poll GV291."""
    for pid, pose in points:
        bare.write_registers(R.gv_reg(201), encode_floats([1.0]), device_id=1)  # source: GVs
        bare.write_registers(R.gv_reg(245), encode_floats([float(R.TOOL_NONE)]), device_id=1)
        bare.write_registers(0, encode_floats(pose), device_id=1)  # GV0..GV5
        bare.write_registers(R.gv_reg(202), encode_floats([0.0]), device_id=1)  # first GV index
        bare.write_registers(R.gv_reg(200), encode_floats([float(pid)]), device_id=1)  # id
        bare.write_register(R.REG_RUN_COMMAND, int(RunCommand.CREATE_POINT), device_id=1)
        seen_ack = False
        deadline = time.monotonic() + 3.0
        while time.monotonic() < deadline:
            regs = bare.read_holding_registers(R.gv_reg(291), count=2, device_id=1).registers
            code = decode_status_registers(regs)
            if code != 0xFF:
                seen_ack = True
            elif seen_ack:
                break
        else:
            raise RuntimeError(f"seed-style upload: point {pid} never completed")


def bench_upload(sim: SimController, n: int, sample_s: float = restore.SAMPLE_S) -> dict[str, Any]:
    """The batched upload against the minimal-transactions bound, judged the way
    ``points.restore_all`` is (:mod:`benchmarks.restore`): the upload in rounds of
    :data:`~benchmarks.restore.ROUNDS`, a bare pymodbus client running one point's minimal work
    before and after each round, the ratio the median of the rounds' (round time / points x mean
    bare cycle). The old figure, whole run / n x (4 x median read + latency), is ``ratio_total``:
    on a machine whose speed drifts over the half minute it takes, it measured the minutes."""
    host, port = "127.0.0.1", sim.port
    points = _poses(n)
    sim.restart_controller()

    client = RobotClient(ConnectionSettings(host=host, port=port))
    client.connect()
    bare = ModbusTcpClient(host, port=port, timeout=1.0)  # the bound's loop, between the rounds
    if not bare.connect():
        raise RuntimeError("the bare pymodbus client cannot connect to the simulator")
    latency = sim.config.command_latency
    try:
        requests0 = client.stats.requests
        rounds, samples, results = restore.upload_in_rounds(
            client, bare, points, -(-n // restore.ROUNDS), sample_s, latency
        )
        requests = client.stats.requests - requests0
    finally:
        bare.close()
        client.close()
    figures = restore.summarize(rounds, samples, latency)
    batched_s = figures["restore_s"]
    failed = sum(1 for r in results if not r.ok) + n - len(results)
    sim.restart_controller()

    bare = ModbusTcpClient(host, port=port, timeout=1.0)
    bare.connect()
    try:
        t0 = time.perf_counter()
        _seed_upload(bare, points)
        seed_s = time.perf_counter() - t0
    finally:
        bare.close()
    # Minimal transactions per point with the GV route: pose write, id/source/index write, the
    # 0xE0 command, one status read that sees the result (a host that also proves the result
    # is fresh reads twice: the 0, then 0xFF). The controller's own latency adds to each point.
    # (RobotClient stages the next pose while the controller works, so its wall time overlaps
    # the pose write with that latency, as the bare loop of benchmarks.restore does.)
    min_tx_per_point = 4
    per_point = {  # where a point's time goes (ms): compare "wall" with the other three
        "wall": 1000.0 * batched_s / n,
        "requests_at_rtt": requests / n * figures["rtt_ms"],
        "controller_latency": 1000.0 * latency,
        "client_cpu": figures["client_cpu_ms_per_point"],
    }
    return {
        "points": n,
        "controller_latency_ms": 1000 * latency,
        "failed": failed,
        "batched_s": batched_s,
        "seed_sequence_s": seed_s,
        "min_transactions_bound_s": figures["min_transactions_bound_s"],
        "min_transactions_per_point": min_tx_per_point,
        "rtt_ms": figures["rtt_ms"],
        "ratio_batched_vs_seed": batched_s / seed_s,
        "ratio_batched_vs_bound": figures["ratio_vs_bound"],
        "ratio_method": figures["ratio_method"],
        "round_ratios": figures["round_ratios"],
        "ratio_total": figures["ratio_total"],
        "ratio_total_method": figures["ratio_total_method"],
        "bound_per_point_ms": figures["bound_per_point_ms"],
        "bare_cpu_ms_per_cycle": figures["bare_cpu_ms_per_cycle"],
        "requests_per_point": requests / n,
        "ratio_requests_vs_bound": requests / n / min_tx_per_point,
        "points_per_s_batched": n / batched_s,
        "per_point_ms": per_point,
    }


def bench_answer_check(n: int) -> dict[str, float]:
    """Microseconds to check one answer against its request (pose block: 100 registers)."""
    request = frames.read_request(R.POSE_BLOCK_START, R.POSE_BLOCK_COUNT)
    pdu = bytes([3, 200]) + bytes(range(200))
    tcp = struct.pack(">HHHB", 7, 0, len(pdu) + 1, 1) + pdu
    rtu_body = bytes([1]) + pdu
    rtu = rtu_body + frames.crc16(rtu_body).to_bytes(2, "big")
    out: dict[str, float] = {}
    for framing, frame, tid in (("tcp", tcp, 7), ("rtu", rtu, 0)):
        t0 = time.perf_counter()
        for _ in range(n):
            assert frames.frame_need(framing, request, 1, tid, frame) == len(frame)  # type: ignore[arg-type]
        out[f"{framing}_us"] = 1e6 * (time.perf_counter() - t0) / n
    return out


def run(quick: bool) -> dict[str, Any]:
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    try:
        monitor = bench_monitor(sim, seconds=3.0 if quick else 9.0)
        upload = bench_upload(sim, n=500 if quick else 10000)
    finally:
        sim.stop()
    # the same upload against a controller that answers instantly: transactions dominate
    instant = SimController(SimConfig(host="127.0.0.1", port=0, command_latency=0.0))
    instant.start()
    try:
        # a supplementary figure: 2,000 points show the ratio as well as 10,000 would
        upload_instant = bench_upload(instant, n=500 if quick else 2000)
    finally:
        instant.stop()
    return {
        "answer_check": bench_answer_check(2000 if quick else 20000),
        "monitor_cycle": monitor,
        "upload_points": upload,
        "upload_points_instant_controller": upload_instant,
    }

"""The gateway at scale (issue 23): ``make bench`` suite ``gateway``.

* ``simulators``: the simulator serving N controllers from one process (``teachpad-sim
  --controllers N``) against N processes of one each: CPU per controller (% of a core) and answer
  latency (a bare pymodbus client per controller reading the pose + status blocks at 10 Hz).
* ``gateway_64``: the gateway (an in-process :class:`~app.gateway.edge_node.EdgeNode`, the product's
  poller threads and paho client) polling 64 simulated controllers at 10 Hz and publishing to a real
  ``mosquitto`` started here (stopped by PID); an independent paho subscriber in its own process
  decodes every DDATA. Figures: the gateway process's CPU (% of one core; the benchmark's own
  thread only sleeps meanwhile), each controller's poll period p99 (from one answer to the next),
  poll answer -> subscriber (the DDATA's timestamp is the answer's wall-clock time; the subscriber
  notes its arrival).
* ``bare_64``: a bare pymodbus read loop (a thread per controller, the same two reads, 10 Hz) on
  the same simulators in the same run: the floor the gateway is compared to.
* ``ddeath_64``: the 64 again, and five times one simulator process (8 controllers) stopped by
  SIGSTOP: SIGSTOP -> DDEATH at the subscriber, the share within the issue's 250 ms, and the
  DDEATHs of controllers that were not stopped (false deaths: the gateway's death rule,
  :mod:`app.gateway.poller`, against a busy machine's late answers).
* ``dead_one_of_16``: 16 controllers at 10 Hz, all alive, then one of them stopped (SIGSTOP of its
  own simulator process: it accepts nothing and answers nothing); the other 15's poll period p99
  in both runs.

Where the simulators run: V measured 64 simulators in one Python process answering too late
(period p99 530 ms): one interpreter lock for 64 servers and 64 tickers. The simulators here are
spread over processes of :data:`PER_PROCESS` controllers each (their tickers at :data:`SIM_TICK_HZ`,
enough for arms that move between 10 Hz polls), so the figures measure the gateway and not the
simulator; ``simulators`` says what one process of N costs against N processes.
"""

from __future__ import annotations

import itertools
import json
import logging
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from app.protocol import registers

POLL_HZ = 10.0
PER_PROCESS = 8  # simulated controllers per simulator process
# The simulators' ticker in these runs: the default 100 Hz (for the pendant's smooth motion) costs
# 8 idle controllers 31 % of a core, 25 Hz 10 %, 10 Hz 7 % (measured, 2-core machine): at 10 Hz the
# arms still move between two 10 Hz polls, and 64 of them leave the gateway a core to run on.
SIM_TICK_HZ = 10.0
START_TIMEOUT = 30.0  # s for a process to say it is ready (a loaded machine)
MOSQUITTO_PATHS = ("/usr/sbin/mosquitto", "/usr/bin/mosquitto")
ROOT = Path(__file__).resolve().parents[1]


def _pct(values: Sequence[float], q: float) -> float | None:
    if not values:
        return None
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q / 100.0 * (len(ordered) - 1)))]


def _summary_ms(seconds: Sequence[float]) -> dict[str, Any]:
    if not seconds:
        return {"p50_ms": None, "p99_ms": None, "max_ms": None, "n": 0, "not_measured": "no samples"}
    p50, p99 = _pct(seconds, 50), _pct(seconds, 99)
    assert p50 is not None and p99 is not None
    return {"p50_ms": p50 * 1000, "p99_ms": p99 * 1000, "max_ms": max(seconds) * 1000, "n": len(seconds)}


def _cpu_of(pid: int) -> float:
    """CPU seconds (user + system) of process ``pid`` so far (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


# -- simulators in processes ---------------------------------------------------------------
class SimProcess:
    """``teachpad-sim --controllers N`` in its own process; its ports from its stdout. ``idle``: no
    program runs (``--controllers 1 --idle`` is a plain ``teachpad-sim``); ``tick_hz`` None: the
    simulator's default ticker. SIGSTOP of :attr:`pid` stops it dead (it accepts and answers
    nothing, as a hung controller); :meth:`stop` continues it first. The benchmarks' and the tests'
    one way to run simulators in a process of their own (tests/gateway/test_death_rule.py)."""

    def __init__(self, count: int = 1, *, idle: bool = False, tick_hz: float | None = SIM_TICK_HZ) -> None:
        command = [sys.executable, "-m", "app.sim.cli", "--port", "0", "--controllers", str(count)]
        command += [] if tick_hz is None else ["--tick-hz", str(tick_hz)]
        command += ["--no-stdin", "--stop-with-stdin"]
        self.proc = subprocess.Popen(
            command + (["--idle"] if idle else []),
            cwd=ROOT,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        assert self.proc.stdout is not None
        self.ports: list[int] = []
        deadline = time.monotonic() + START_TIMEOUT
        while len(self.ports) < count and time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            if "listening on" in line:
                self.ports.append(int(line.split("listening on ")[1].split()[0].rsplit(":", 1)[1]))
        if len(self.ports) < count:
            self.stop()
            raise RuntimeError(f"teachpad-sim --controllers {count} did not start")

    @property
    def pid(self) -> int:
        return self.proc.pid

    @property
    def port(self) -> int:
        """The (first) controller's port."""
        return self.ports[0]

    def stop(self) -> None:
        os.kill(self.proc.pid, signal.SIGCONT)  # a stopped one must run to stop
        assert self.proc.stdin is not None
        self.proc.stdin.close()  # --stop-with-stdin
        try:
            self.proc.wait(10.0)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait(5.0)
        if self.proc.stdout is not None:
            self.proc.stdout.close()


@contextmanager
def sim_processes(total: int, per_process: int, *, idle: bool = False) -> Iterator[list[SimProcess]]:
    made: list[SimProcess] = []
    try:
        for start in range(0, total, per_process):
            made.append(SimProcess(min(per_process, total - start), idle=idle))
        yield made
    finally:
        for proc in made:
            proc.stop()


# -- the broker and the subscriber -----------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


@contextmanager
def mosquitto() -> Iterator[int]:
    """A real ``mosquitto`` on a free loopback port (temporary config), stopped by PID."""
    binary = shutil.which("mosquitto") or next((p for p in MOSQUITTO_PATHS if Path(p).exists()), None)
    if binary is None:
        raise RuntimeError("mosquitto is not installed (Debian: apt-get install -y mosquitto)")
    with tempfile.TemporaryDirectory(prefix="teachpad-bench-mqtt-") as folder:
        port = _free_port()
        config = Path(folder) / "mosquitto.conf"
        config.write_text(f"listener {port} 127.0.0.1\nallow_anonymous true\npersistence false\n")
        proc = subprocess.Popen(
            [binary, "-c", str(config)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
        )
        try:
            deadline = time.monotonic() + START_TIMEOUT
            while True:
                try:
                    socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
                    break
                except OSError:
                    if proc.poll() is not None or time.monotonic() > deadline:
                        raise RuntimeError(f"mosquitto did not listen on {port}") from None
                    time.sleep(0.02)  # a port that is not open yet: nothing to wait on
            yield port
        finally:
            os.kill(proc.pid, signal.SIGTERM)
            proc.wait(10.0)


class SubscriberProcess:
    """``python -m benchmarks.gateway subscribe PORT``: latencies of every DDATA, as JSON at stdin's end."""

    def __init__(self, port: int) -> None:
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "benchmarks.gateway", "subscribe", str(port)],
            cwd=ROOT,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        assert self.proc.stdout is not None
        if self.proc.stdout.readline().strip() != "subscribed":
            raise RuntimeError("the benchmark's subscriber did not subscribe")

    def mark(self) -> None:
        """From now on the latencies count (the births and the start are behind)."""
        assert self.proc.stdin is not None
        self.proc.stdin.write("mark\n")
        self.proc.stdin.flush()

    def finish(self) -> dict[str, Any]:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.close()
        out = self.proc.stdout.read()
        self.proc.wait(10.0)
        result: dict[str, Any] = json.loads(out)
        return result


def _subscribe(port: int) -> None:
    """The subscriber process: an independent paho client decoding every Sparkplug payload."""
    import paho.mqtt.client as mqtt
    from paho.mqtt.enums import CallbackAPIVersion

    from app.gateway import payload as pb

    latencies: list[float] = []
    counting = threading.Event()
    subscribed = threading.Event()
    counts = {"DDATA": 0, "DBIRTH": 0, "DDEATH": 0}
    deaths: list[tuple[str, float]] = []  # (device, time.time() of its arrival)

    def on_message(_c: Any, _u: Any, message: mqtt.MQTTMessage) -> None:
        now_ms = time.time() * 1000.0
        kind = message.topic.split("/")[2]
        if kind in counts and counting.is_set():
            counts[kind] += 1
            if kind == "DDATA":
                latencies.append((now_ms - pb.decode(message.payload).timestamp) / 1000.0)
            elif kind == "DDEATH":
                deaths.append((message.topic.split("/")[4], now_ms / 1000.0))

    client = mqtt.Client(
        callback_api_version=CallbackAPIVersion.VERSION2, client_id=f"bench-sub-{os.getpid()}"
    )
    client.on_message = on_message
    client.on_subscribe = lambda *_a: subscribed.set()
    client.on_connect = lambda c, *_a: c.subscribe("spBv1.0/#", qos=0)
    client.connect("127.0.0.1", port, keepalive=30)
    client.loop_start()
    subscribed.wait(START_TIMEOUT)
    print("subscribed", flush=True)
    for line in sys.stdin:
        if line.strip() == "mark":
            counting.set()
    client.disconnect()
    client.loop_stop()
    print(json.dumps({"latency": _summary_ms(latencies), "messages": counts, "deaths": deaths}), flush=True)


# -- the gateway, in this process --------------------------------------------------------------
def _edge_node(ports: Sequence[int], broker_port: int, poll_timeout: float | None = None) -> Any:
    """An EdgeNode for ``ports`` whose every answer's time is noted per controller (``.answers_at``)."""
    from app.cell.cell_file import Cell, CellController
    from app.gateway.edge_node import BrokerSettings, EdgeNode
    from app.gateway.metrics import Reading
    from app.gateway.poller import GatewayTiming

    class TimedEdgeNode(EdgeNode):
        answers_at: dict[str, list[float]]
        handed_over: list[float]  # s from an answer to its DDATA handed to paho (the gateway's share)

        def answered(self, device: str, reading: Reading) -> None:  # the poller's thread
            self.answers_at.setdefault(device, []).append(reading.answered_at)
            super().answered(device, reading)

        def _answered(self, device: str, reading: Reading) -> None:  # the publisher thread
            super()._answered(device, reading)
            self.handed_over.append(time.monotonic() - reading.answered_at)

    cell = Cell(
        "bench", tuple(CellController(f"r{i:02d}", host="127.0.0.1", port=p) for i, p in enumerate(ports))
    )
    node = TimedEdgeNode(
        cell,
        BrokerSettings("127.0.0.1", broker_port),
        group="bench",
        node="gw",
        gateway=GatewayTiming(poll_hz=POLL_HZ, poll_timeout=poll_timeout),
    )
    # every controller's list made before the pollers start: they only append, so this thread can
    # read the dict while they answer (one that added its own key raced _settle's read: "dictionary
    # changed size during iteration" lost every gateway figure of a make bench)
    node.answers_at = {controller.name: [] for controller in cell.controllers}
    node.handed_over = []
    return node


def _periods(
    answers_at: dict[str, list[float]], since: float, devices: Sequence[str] | None = None
) -> list[float]:
    out: list[float] = []
    for device, times in answers_at.items():
        if devices is not None and device not in devices:
            continue
        recent = [t for t in times if t >= since]
        out += [b - a for a, b in itertools.pairwise(recent)]
    return out


def _window(seconds: float) -> tuple[float, float]:
    """Sleep ``seconds``; this process's CPU seconds and the wall seconds it took."""
    cpu0, wall0 = time.process_time(), time.monotonic()
    time.sleep(seconds)  # the measuring window: the gateway's threads work, this one waits
    return time.process_time() - cpu0, time.monotonic() - wall0


def _settle(node: Any, count: int, timeout: float = START_TIMEOUT, since: float = 0.0) -> None:
    """Until ``count`` controllers answered three times (since ``since``)."""
    deadline = time.monotonic() + timeout

    def answering() -> int:
        return sum(1 for times in node.answers_at.values() if len([t for t in times[-3:] if t >= since]) >= 3)

    while time.monotonic() < deadline and answering() < count:
        time.sleep(0.05)  # the pollers' first answers: nothing to wait on but time


def measure_gateway(
    ports: Sequence[int], broker_port: int, seconds: float, poll_timeout: float | None = None
) -> dict[str, Any]:
    """The gateway's figures; ``poll_timeout`` None: the product's (0.15 s over TCP)."""
    sub = SubscriberProcess(broker_port)
    node = _edge_node(ports, broker_port, poll_timeout)
    node.start()
    try:
        _settle(node, len(ports))
        sub.mark()
        since = time.monotonic()
        first = len(node.handed_over)
        cpu, wall = _window(seconds)
        handed_over = node.handed_over[first:]
    finally:
        node.stop()
    received = sub.finish()
    period = _summary_ms(_periods(node.answers_at, since))
    return {
        "controllers": len(ports),
        "poll_hz": POLL_HZ,
        "seconds": wall,
        "poll_timeout_s": poll_timeout if poll_timeout is not None else "the product's (0.15 over TCP)",
        "cpu_pct_of_one_core": 100.0 * cpu / wall,
        "poll_period": period,
        "poll_period_p99_vs_period": None
        if period["p99_ms"] is None
        else period["p99_ms"] / (1000.0 / POLL_HZ),
        "answer_to_subscriber": received["latency"],
        "answer_to_paho": _summary_ms(handed_over),
        "messages": received["messages"],
        "answers_per_s": sum(len([t for t in v if t >= since]) for v in node.answers_at.values()) / wall,
    }


# -- a silent controller's DDEATH at load -----------------------------------------------------------
DDEATH_BOUND_MS = 250.0  # issue 23: DDEATH within 250 ms of a controller going silent


def measure_ddeath(procs: Sequence[SimProcess], broker_port: int, rounds: int) -> dict[str, Any]:
    """The gateway polling every controller of ``procs`` at 10 Hz; ``rounds`` times one simulator
    process (its controllers) stopped by SIGSTOP and continued once every one of them got its
    DDEATH: from the SIGSTOP to each DDEATH at the subscriber (same clock: this machine's), and
    how many came within the issue's 250 ms."""
    ports = [port for p in procs for port in p.ports]
    sub = SubscriberProcess(broker_port)
    node = _edge_node(ports, broker_port)
    stops: list[tuple[list[str], float]] = []
    node.start()
    try:
        for k in range(rounds):
            _settle(node, len(ports), since=time.monotonic())
            if k == 0:
                sub.mark()
            victim = procs[k % len(procs)]
            names = [f"r{ports.index(port):02d}" for port in victim.ports]
            stopped_at = time.time()
            os.kill(victim.pid, signal.SIGSTOP)
            stops.append((names, stopped_at))
            time.sleep(1.0)  # far past any DDEATH the rule allows: nothing to wait on in this process
            os.kill(victim.pid, signal.SIGCONT)
    finally:
        node.stop()
        for proc in procs:
            os.kill(proc.pid, signal.SIGCONT)
    received = sub.finish()
    took: list[float] = []
    missing = 0
    for names, stopped_at in stops:
        for name in names:
            arrived = [t for device, t in received["deaths"] if device == name and t >= stopped_at]
            if arrived:
                took.append(min(arrived) - stopped_at)
            else:
                missing += 1
    within = sum(1 for t in took if t * 1000.0 <= DDEATH_BOUND_MS)
    silenced = sum(len(names) for names, _ in stops)
    return {
        "controllers": len(ports),
        "silenced": silenced,
        "sigstop_to_ddeath": _summary_ms(took),
        "within_250_ms_pct": 100.0 * within / silenced if silenced else None,
        "no_ddeath": missing,
        "false_ddeaths": received["messages"]["DDEATH"] - len(took),
    }


# -- the bare pymodbus loop ----------------------------------------------------------------------
def measure_bare(ports: Sequence[int], seconds: float) -> dict[str, Any]:
    """A thread per controller: the same two reads at 10 Hz with a bare pymodbus client."""
    from pymodbus.client import ModbusTcpClient

    stop = threading.Event()
    times: dict[str, list[float]] = {}
    latencies: list[float] = []

    def loop(port: int) -> None:
        client = ModbusTcpClient("127.0.0.1", port=port, timeout=1.0)
        client.connect()
        mine = times.setdefault(str(port), [])
        next_at = time.monotonic()
        while not stop.is_set():
            t0 = time.perf_counter()
            client.read_holding_registers(
                registers.STATUS_BLOCK_START, count=registers.STATUS_BLOCK_COUNT, device_id=1
            )
            client.read_holding_registers(
                registers.POSE_BLOCK_START, count=registers.POSE_BLOCK_COUNT, device_id=1
            )
            latencies.append(time.perf_counter() - t0)
            mine.append(time.monotonic())
            next_at = max(next_at + 1.0 / POLL_HZ, time.monotonic() - 1.0 / POLL_HZ)
            stop.wait(max(0.0, next_at - time.monotonic()))
        client.close()

    threads = [threading.Thread(target=loop, args=(p,), daemon=True) for p in ports]
    for t in threads:
        t.start()
    time.sleep(min(1.0, seconds / 2))  # connected and running
    since = time.monotonic()
    n0 = len(latencies)
    cpu, wall = _window(seconds)
    stop.set()
    for t in threads:
        t.join(5.0)
    period = _summary_ms(_periods(times, since))
    return {
        "controllers": len(ports),
        "poll_hz": POLL_HZ,
        "cpu_pct_of_one_core": 100.0 * cpu / wall,
        "poll_period": period,
        "answer": _summary_ms(latencies[n0:]),
    }


# -- one dead controller among 16 ---------------------------------------------------------------
def measure_dead_one(ports: Sequence[int], broker_port: int, seconds: float, rounds: int) -> dict[str, Any]:
    """``ports`` (15) alive plus one controller in its own process, stopped (SIGSTOP) and continued
    in turn: ``rounds`` x (all alive ``seconds``, one dead ``seconds``), so that a machine whose load
    drifts weighs on both alike."""
    alive: list[float] = []
    dead: list[float] = []
    silent_answers = 0
    with sim_processes(1, 1) as (victim,):
        all_ports = [*ports, victim.ports[0]]
        node = _edge_node(all_ports, broker_port)
        others = [f"r{i:02d}" for i in range(len(ports))]
        victim_name = f"r{len(ports):02d}"
        node.start()
        try:
            for _round in range(rounds):
                _settle(node, len(all_ports), since=time.monotonic())
                since = time.monotonic()
                _window(seconds)
                alive += _periods(node.answers_at, since, others)
                os.kill(victim.pid, signal.SIGSTOP)
                since = time.monotonic()
                _window(seconds)
                dead += _periods(node.answers_at, since, others)
                silent_answers += len([t for t in node.answers_at.get(victim_name, []) if t >= since])
                os.kill(victim.pid, signal.SIGCONT)
        finally:
            node.stop()
    alive_ms, dead_ms = _summary_ms(alive), _summary_ms(dead)
    ratio = (
        None
        if not alive_ms["p99_ms"] or dead_ms["p99_ms"] is None
        else dead_ms["p99_ms"] / alive_ms["p99_ms"]
    )
    return {
        "controllers": len(all_ports),
        "rounds": rounds,
        "all_alive": {"others_poll_period": alive_ms},
        "one_dead": {"others_poll_period": dead_ms, "dead_controller_answers": silent_answers},
        "others_p99_dead_vs_alive": ratio,
    }


# -- the simulator: one process of N against N processes -------------------------------------------
def _poll_sims(ports: Sequence[int], pids: Sequence[int], seconds: float) -> dict[str, Any]:
    cpu0 = sum(_cpu_of(p) for p in pids)
    wall0 = time.monotonic()
    bare = measure_bare(ports, seconds)
    cpu = sum(_cpu_of(p) for p in pids) - cpu0
    wall = time.monotonic() - wall0
    return {
        "controllers": len(ports),
        "processes": len(pids),
        "cpu_pct_per_controller": 100.0 * cpu / wall / len(ports),
        "cpu_pct_all": 100.0 * cpu / wall,
        "answer": bare["answer"],
    }


def measure_simulators(count: int, seconds: float, *, quick: bool) -> dict[str, Any]:
    """``count`` controllers in one process against one process each (and, full run only, 64 in one
    process against 64 in processes of :data:`PER_PROCESS`: what the gateway figures use)."""
    with sim_processes(count, count) as procs:
        one = _poll_sims(procs[0].ports, [procs[0].pid], seconds)
    with sim_processes(count, 1) as procs:
        many = _poll_sims([p.ports[0] for p in procs], [p.pid for p in procs], seconds)
    out: dict[str, Any] = {
        "poll_hz": POLL_HZ,
        "tick_hz": SIM_TICK_HZ,
        "one_process": one,
        "one_process_each": many,
        "benchmark_uses": f"processes of {PER_PROCESS} controllers each",
    }
    if quick:
        out["sixty_four"] = {"not_measured": "--quick"}
        return out
    with sim_processes(64, 64) as procs:
        in_one = _poll_sims(procs[0].ports, [procs[0].pid], seconds)
    with sim_processes(64, PER_PROCESS) as procs:
        spread = _poll_sims([port for p in procs for port in p.ports], [p.pid for p in procs], seconds)
    out["sixty_four"] = {"one_process": in_one, f"processes_of_{PER_PROCESS}": spread}
    return out


def run(quick: bool = False) -> dict[str, Any]:
    logging.getLogger("app.gateway").setLevel(logging.ERROR)  # "r15 stopped answering": expected here
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)  # the bare loop's late answers: in figures
    n_big = 16 if quick else 64
    window = 1.5 if quick else 10.0
    out: dict[str, Any] = {
        "load_avg_1m_at_start": os.getloadavg()[0],
        "quick_scaled_down": f"{n_big} controllers instead of 64" if quick else None,
        "simulators": measure_simulators(2 if quick else 16, 1.0 if quick else 5.0, quick=quick),
    }
    with mosquitto() as broker_port, sim_processes(n_big, PER_PROCESS) as procs:
        ports = [port for p in procs for port in p.ports]
        out["gateway_64"] = measure_gateway(ports, broker_port, window)
        # the same with a roomy poll timeout (the knob GatewayTiming.poll_timeout; the death window is
        # never shorter, so 1 s here): a simulator late by more than the product's 0.2 s window on a
        # loaded machine is not a DDEATH + backoff here, so this period is the gateway's own scheduling
        out["gateway_64_poll_timeout_1s"] = (
            {"not_measured": "--quick"} if quick else measure_gateway(ports, broker_port, window, 1.0)
        )
        out["bare_64"] = measure_bare(ports, window)
        out["ddeath_64"] = measure_ddeath(procs, broker_port, 2 if quick else 5)
        out["dead_one_of_16"] = measure_dead_one(
            ports[:15], broker_port, 0.75 if quick else 2.5, 1 if quick else 3
        )
    out["load_avg_1m_at_end"] = os.getloadavg()[0]
    gw, bare = out["gateway_64"], out["bare_64"]
    if gw["poll_period"]["p99_ms"] and bare["poll_period"]["p99_ms"]:
        out["gateway_vs_bare"] = {
            "period_p99_ratio": gw["poll_period"]["p99_ms"] / bare["poll_period"]["p99_ms"],
            "cpu_ratio": gw["cpu_pct_of_one_core"] / max(bare["cpu_pct_of_one_core"], 1e-9),
        }
    return out


if __name__ == "__main__":
    if sys.argv[1:2] == ["subscribe"]:
        _subscribe(int(sys.argv[2]))
    else:
        print(json.dumps(run("--quick" in sys.argv), indent=2))

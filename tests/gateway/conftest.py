"""A real Mosquitto per test (its own config file, a free loopback port, stopped by PID) and an
independent subscriber: a second paho client that decodes every Sparkplug payload it receives.

No mock broker. Without the ``mosquitto`` binary the tests FAIL saying how to install it (``.ci/run``
installs it), they are not skipped.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
import os
import shutil
import socket
import subprocess
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
import pytest
from paho.mqtt.enums import CallbackAPIVersion

from app.gateway import payload as pb

MOSQUITTO_PATHS = ("/usr/sbin/mosquitto", "/usr/bin/mosquitto")
BROKER_START_TIMEOUT = 10.0  # s for mosquitto to accept connections (a loaded machine)
WAIT = 10.0  # s a test waits for a message it expects
_ids = itertools.count()


def mosquitto_binary() -> str:
    found = shutil.which("mosquitto") or next((p for p in MOSQUITTO_PATHS if Path(p).exists()), None)
    if found is None:
        pytest.fail(
            "mosquitto is not installed: the gateway's conformance tests need a real MQTT broker "
            "(Debian: apt-get install -y mosquitto mosquitto-clients; .ci/run installs it)",
            pytrace=False,
        )
    return found


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


class Broker:
    """``mosquitto -c TMPFILE`` on 127.0.0.1:``port``; :meth:`restart` keeps the port."""

    def __init__(self, binary: str, folder: Path) -> None:
        self.binary = binary
        self.config = folder / "mosquitto.conf"
        self.log = folder / "mosquitto.log"
        self.proc: subprocess.Popen[bytes] | None = None
        self.port = 0

    def _configure(self) -> None:
        self.port = free_port()
        self.config.write_text(
            f"listener {self.port} 127.0.0.1\nallow_anonymous true\npersistence false\n"
            "log_dest stderr\nlog_type error\nlog_type warning\n"
        )

    def start_fresh(self) -> None:
        """On a free port; another one when another test took it between the choice and the bind."""
        for _attempt in range(3):
            self._configure()
            if self.start(give_up=False):
                return
        pytest.fail(f"mosquitto could not listen on a free port: {self.log.read_text()[-500:]}")

    def start(self, *, give_up: bool = True) -> bool:
        """Start on :attr:`port` (a restart: the same); True once it accepts connections."""
        with self.log.open("ab") as log:
            self.proc = subprocess.Popen([self.binary, "-c", str(self.config)], stdout=log, stderr=log)
        deadline = time.monotonic() + BROKER_START_TIMEOUT
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                if not give_up and "in use" in self.log.read_text():
                    return False
                pytest.fail(f"mosquitto exited ({self.proc.returncode}): {self.log.read_text()[-500:]}")
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=0.2).close()
                return True
            except OSError:
                time.sleep(0.02)  # polling a port that is not open yet: nothing to wait on
        pytest.fail(f"mosquitto did not listen on port {self.port} within {BROKER_START_TIMEOUT:g} s")

    def stop(self) -> None:
        proc, self.proc = self.proc, None
        if proc is None or proc.poll() is not None:
            return
        proc.terminate()
        try:
            proc.wait(5.0)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5.0)

    def restart(self) -> None:
        self.stop()
        self.start()


@pytest.fixture
def broker(tmp_path: Path) -> Iterator[Broker]:
    b = Broker(mosquitto_binary(), tmp_path)
    b.start_fresh()
    try:
        yield b
    finally:
        b.stop()


@dataclass(frozen=True)
class Received:
    topic: str
    kind: str  # NBIRTH, DDATA, ...
    device: str | None
    payload: Any  # the decoded Sparkplug payload
    at: float  # time.monotonic() when it arrived
    qos: int
    retain: bool

    @property
    def seq(self) -> int | None:
        return int(self.payload.seq) if self.payload.HasField("seq") else None

    def metric(self, name: str) -> Any:
        return next(m for m in self.payload.metrics if m.name == name)


class Subscriber:
    """An independent Sparkplug consumer: subscribes to ``spBv1.0/#`` and decodes every payload.

    After a broker restart it subscribes again (:attr:`subscriptions` counts them)."""

    def __init__(self, port: int) -> None:
        self.messages: list[Received] = []
        self.subscriptions = 0  # subscriptions made (one per connection)
        self._cond = threading.Condition()
        self._client = mqtt.Client(
            callback_api_version=CallbackAPIVersion.VERSION2, client_id=f"test-sub-{os.getpid()}-{next(_ids)}"
        )
        self._client.reconnect_delay_set(1, 1)
        self._client.enable_logger(logging.getLogger("tests.gateway.subscriber"))
        self._client.on_message = self._on_message
        subscribed = threading.Event()

        def on_subscribe(*_args: Any) -> None:
            self.subscriptions += 1
            subscribed.set()

        self._client.on_subscribe = on_subscribe
        self._client.on_connect = lambda client, *_: client.subscribe("spBv1.0/#", qos=1)
        self._client.connect("127.0.0.1", port, keepalive=5)
        self._client.loop_start()
        if not subscribed.wait(WAIT):
            pytest.fail("the test's subscriber did not get its subscription")

    def _on_message(self, _c: Any, _u: Any, message: mqtt.MQTTMessage) -> None:
        parts = message.topic.split("/")
        state = parts[1] == "STATE"  # spBv1.0/STATE/HOST_ID: JSON, not a Sparkplug payload
        got = Received(
            message.topic,
            "STATE" if state else parts[2],
            parts[4] if len(parts) > 4 else None,
            None if state else pb.decode(message.payload),
            time.monotonic(),
            message.qos,
            bool(message.retain),
        )
        with self._cond:
            self.messages.append(got)
            self._cond.notify_all()

    def wait_for(
        self, what: str, match: Callable[[Received], bool], timeout: float = WAIT, start: int = 0
    ) -> Received:
        """The first message from index ``start`` on that ``match``-es; fails saying ``what`` otherwise."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                found = next((m for m in self.messages[start:] if match(m)), None)
                if found is not None:
                    return found
                left = deadline - time.monotonic()
                if left <= 0:
                    kinds = [f"{m.kind}/{m.device}" for m in self.messages[-10:]]
                    pytest.fail(f"no {what} within {timeout:g} s (last messages: {kinds})", pytrace=False)
                self._cond.wait(left)

    def kind(
        self, kind: str, device: str | None = None, *, start: int = 0, timeout: float = WAIT
    ) -> Received:
        return self.wait_for(
            f"{kind} {device or ''}".strip(),
            lambda m: m.kind == kind and (device is None or m.device == device),
            timeout,
            start,
        )

    def count(self) -> int:
        with self._cond:
            return len(self.messages)

    def snapshot(self) -> list[Received]:
        with self._cond:
            return list(self.messages)

    def publish(self, topic: str, data: bytes, *, retain: bool = False) -> None:
        self._client.publish(topic, data, qos=1, retain=retain).wait_for_publish(WAIT)

    def close(self) -> None:
        self._client.disconnect()
        self._client.loop_stop()


@pytest.fixture
def subscriber(broker: Broker) -> Iterator[Subscriber]:
    sub = Subscriber(broker.port)
    try:
        yield sub
    finally:
        sub.close()


def write_cell(
    folder: Path,
    sims: dict[str, Any],
    name: str = "test cell",
    options: dict[str, dict[str, Any]] | None = None,
) -> Path:
    """A cell file with one controller per simulator (its name -> the simulator), written by the
    product; ``options``: more fields of a controller by its name (``plant_writes``, ``external_axes``)."""
    from app.cell.cell_file import Cell, CellController, save_cell

    path = folder / "cell.json"
    more = options or {}
    controllers = tuple(
        CellController(n, host="127.0.0.1", port=sim.port, **more.get(n, {})) for n, sim in sims.items()
    )
    save_cell(path, Cell(name, controllers))
    return path


#: short clocks for the tests: 50 Hz polls, 0.1 s poll timeout, quick backoff
FAST = {"poll_hz": 50.0, "poll_timeout": 0.1, "backoff": (0.05,), "keepalive": 5, "broker_retry": (1, 1)}


@pytest.fixture
def gateway_factory(broker: Broker, tmp_path: Path) -> Iterator[Callable[..., Any]]:
    """Start in-process edge nodes for simulators; every one is stopped after the test."""
    from app.cell.cell_file import load_cell
    from app.gateway.edge_node import BrokerSettings, EdgeNode
    from app.gateway.poller import GatewayTiming
    from app.safety.envelope import Envelope

    made: list[EdgeNode] = []

    def make(
        sims: dict[str, Any],
        deadbands: dict[str, float] | None = None,
        history_limit: int | None = None,
        port: int | None = None,
        primary_host: str | None = None,
        bdseq_file: Path | None = None,
        options: dict[str, dict[str, Any]] | None = None,
        envelope: Any = None,
        **clocks: Any,
    ) -> EdgeNode:
        cell = load_cell(write_cell(tmp_path, sims, options=options))
        node = EdgeNode(
            cell,
            BrokerSettings("127.0.0.1", port or broker.port),
            group="plant",
            node="pad1",
            gateway=GatewayTiming(**{**FAST, **clocks}),
            deadbands=deadbands,
            history_limit=history_limit,
            primary_host=primary_host,
            bdseq_file=bdseq_file,
            # the test's own envelope (the one in force is the session's: another test may save one)
            envelope=envelope if envelope is not None else Envelope(),
            audit_dir=tmp_path / "audit",
        )
        node.start()
        made.append(node)
        return node

    try:
        yield make
    finally:
        for node in made:
            node.stop()


class BrokerLink:
    """A TCP relay between the gateway and the broker that the test can cut and restore: the broker
    out of the gateway's reach while the subscriber, connected directly, sees everything."""

    def __init__(self, broker_port: int) -> None:
        self.broker_port = broker_port
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port: int = self._listener.getsockname()[1]
        self._cut = False
        self._open: list[socket.socket] = []
        self._lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while True:
            try:
                near, _ = self._listener.accept()
            except OSError:
                return  # closed
            with self._lock:
                if self._cut:
                    near.close()
                    continue
                far = socket.create_connection(("127.0.0.1", self.broker_port))
                self._open += [near, far]
            for a, b in ((near, far), (far, near)):
                threading.Thread(target=self._pipe, args=(a, b), daemon=True).start()

    @staticmethod
    def _pipe(source: socket.socket, sink: socket.socket) -> None:
        try:
            while data := source.recv(65536):
                sink.sendall(data)
        except OSError:
            pass  # the other side or cut() closed it
        finally:
            for s in (source, sink):
                s.close()

    def cut(self) -> None:
        with self._lock:
            self._cut = True
            for s in self._open:
                with contextlib.suppress(OSError):
                    s.shutdown(socket.SHUT_RDWR)
            self._open.clear()

    def restore(self) -> None:
        with self._lock:
            self._cut = False

    def close(self) -> None:
        self.cut()
        self._listener.close()


@pytest.fixture
def broker_link(broker: Broker) -> Iterator[BrokerLink]:
    link = BrokerLink(broker.port)
    try:
        yield link
    finally:
        link.close()

"""The Sparkplug B 3.0 edge node: the TeachPad host is the node, each controller of the cell a device.

Topics: ``spBv1.0/GROUP/{NBIRTH,NDEATH,NCMD}/NODE`` and
``spBv1.0/GROUP/{DBIRTH,DDATA,DDEATH,DCMD}/NODE/DEVICE``.
What the specification asks of an edge node, and how it is met here:

* **NDEATH is the MQTT will** (QoS 1, not retained) carrying ``bdSeq``; a new MQTT session (a
  reconnect after the broker went away) sets the will again with ``bdSeq + 1`` (0..255) before it
  connects. A graceful stop publishes NDEATH itself (a clean disconnect does not fire the will).
  With ``bdseq_file`` (the CLI's default: :func:`app.gateway.bdseq.default_bdseq_file`) the bdSeq
  in use is kept on disk before each CONNECT, and a restarted gateway goes on from it + 1.
* On every connect: subscribe to NCMD, then **NBIRTH** (``seq`` 0, the same ``bdSeq``, the
  ``Node Control/Rebirth`` metric), then a **DBIRTH** per answering controller (every metric, name and
  alias), then **DDATA** by exception: only the metrics that moved past their deadband, by alias only.
* ``seq`` counts every message of the node but NDEATH, 0..255 and round again; NBIRTH resets it to 0.
* A controller that stops answering gets a **DDEATH** once it has been silent
  ``GatewayTiming.death_after`` (0.2 s) since its last answer, not at a poll timeout: a late answer
  within that window is taken, and no consumer sees a busy PC's slow poll as a robot dying
  (:mod:`app.gateway.poller` says the rule); a **DBIRTH** when it answers again. **NCMD**
  ``Node Control/Rebirth`` = true: NBIRTH and every DBIRTH again (same bdSeq).
* **While the broker is away** the DDATA the controllers' changes would have been are kept, at most
  ``history_limit`` (the oldest dropped first), and published after the next session's births with
  every metric ``is_historical``; how many were dropped is the NBIRTH's ``Node Info/History dropped``
  (since the start) and a warning.
* **A primary host application** (``primary_host``, optional): its retained ``spBv1.0/STATE/ID``
  (JSON ``{"online": bool, "timestamp": ms}``, QoS 1) is subscribed to, and the node is born only
  while it says online; an offline STATE (not older than the last one) ends the session: NDEATH,
  disconnect, a new session (``bdSeq`` + 1) that waits for online again. Changes meanwhile are kept
  as while the broker is away.
* **DCMD** (``spBv1.0/GROUP/DCMD/NODE/+``, by name or alias): writes from the plant, off unless the
  cell file enables them per robot (``plant_writes``); each goes through the plant role, the one
  write guard, the safety envelope and the audit trail, and is refused while a pendant commands the
  robot (:mod:`app.gateway.plant`). What became of it is the device's ``Plant/Last command result``
  (a DDATA). The DBIRTH advertises the writable metrics a robot has.

Threads: paho's network thread (connect, NCMD, DCMD), one poller thread per controller and the
node's publisher thread. A poller puts its answers and silences in a queue (in order) and, when the
node's lock is free, publishes what waits there itself (DBIRTH / DDATA / DDEATH); when the lock is
held it does not wait for it: it wakes the publisher thread, which takes what waits once the lock
is free (another poller holding it may take it first). So 64 pollers never queue on that lock
(measured: 30 ms an answer on the 2-core machine when each took it blocking) and none is late for
its next poll because another's DDATA was being published, while an answer is mostly published by
the thread that has just run (no hand-over to a thread that must be scheduled first). One lock
orders everything the node publishes, so ``seq`` goes out in order. A DCMD's writes are made in its
robot's poller thread (its client's only thread), never in paho's.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import queue
import ssl
import threading
import time
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import paho.mqtt.client as mqtt
from google.protobuf.message import DecodeError
from paho.mqtt.enums import CallbackAPIVersion

from app import timing
from app.cell.cell_file import Cell, CellController
from app.cell.history import program_cycle
from app.gateway import payload as pb
from app.gateway.bdseq import BdSeqStore
from app.gateway.metrics import (
    ALL_METRICS,
    BDSEQ,
    COMMAND_WRITES,
    CYCLE_METRICS,
    HISTORY_DROPPED,
    PLANT_RESULT,
    REBIRTH,
    REBIRTH_ALIAS,
    MetricSpec,
    Reading,
    changed,
    clock_text,
    device_alias,
    device_metrics,
    device_values,
)
from app.gateway.plant import PlantCommand, PlantWriter, plant_audit_role
from app.gateway.poller import ControllerPoller, GatewayTiming
from app.safety.audit import AuditLog
from app.safety.envelope import Envelope

__all__ = ["NAMESPACE", "BrokerSettings", "EdgeNode"]

NAMESPACE = "spBv1.0"
_log = logging.getLogger(__name__)


@dataclass(frozen=True)
class BrokerSettings:
    """Where the MQTT broker is and how to log in."""

    host: str
    port: int = 1883
    tls: bool = False
    cafile: str | None = None  # None with tls: the system's trusted CAs
    certfile: str | None = None  # a client certificate (with keyfile)
    keyfile: str | None = None
    username: str | None = None
    password: str | None = None


def _kept() -> dict[str, pb.Value]:
    """What the node holds of a device beside its polls: the cycle counters and the plant's metrics."""
    kept: dict[str, pb.Value] = dict.fromkeys(CYCLE_METRICS.values(), 0)
    kept.update({PLANT_RESULT: "", "Plant/Program run": None, "Plant/Program stop": False})
    kept["Plant/Speed ratio"] = None
    return kept


@dataclass
class _Device:
    """What the node knows of one controller (guarded by the node's lock)."""

    name: str
    index: int
    metrics: tuple[int, ...]  # its metrics' indexes in ALL_METRICS (app.gateway.metrics.device_metrics)
    plan: tuple[tuple[MetricSpec, int], ...]  # those metrics and their aliases, in order
    kept: dict[str, pb.Value] = field(default_factory=_kept)
    commands: int = 0  # DCMD metrics received (their numbers)
    alive: bool = False  # answering (a DBIRTH went out, or will on the next session)
    values: dict[str, pb.Value] | None = None  # the last reading's values
    sent: dict[str, pb.Value] | None = None  # what the subscribers were last told
    clock: str | None = None
    never_said: bool = True  # a controller that never answered is said once (then each loss)


def _now_ms() -> int:
    return int(time.time() * 1000)


class EdgeNode:
    """Polls every controller of ``cell`` and publishes it as a Sparkplug B edge node."""

    def __init__(
        self,
        cell: Cell,
        broker: BrokerSettings,
        *,
        group: str,
        node: str,
        gateway: GatewayTiming | None = None,
        deadbands: Mapping[str, float] | None = None,
        history_limit: int | None = None,
        primary_host: str | None = None,
        bdseq_file: str | os.PathLike[str] | None = None,
        envelope: Envelope | None = None,
        audit_dir: Path | None = None,
        writes: bool = True,
        poll: bool = True,
    ) -> None:
        """``envelope``: the plant writes' safety envelope (None: the one in force, as the CLI's, read
        when a controller has plant writes); ``audit_dir``: their audit trail (None: TeachPad's);
        ``writes``: False leaves every robot monitor-only whatever the cell file enables;
        ``poll``: False, no pollers of its own (the caller feeds :meth:`answered` and :meth:`silent`:
        the GUI's cell view, whose pollers already read every controller) and so no plant writes."""
        self.group = group
        self.node = node
        self.timing = gateway or GatewayTiming()
        self._deadbands = dict(deadbands or {})
        self._broker = broker
        self._lock = threading.RLock()
        self._envelope = envelope
        self._audit_dir = audit_dir
        self._writes = writes and poll  # a plant write runs in its robot's poller
        self._pendant_robot: str | None = None
        self._writers: dict[str, PlantWriter] = {}
        self._read_envelope(cell.controllers)
        self._devices = {c.name: self._device(c, i) for i, c in enumerate(cell.controllers)}
        self._controllers = {c.name: c for c in cell.controllers}
        self._poll = poll
        self._pollers = {c.name: self._poller(c) for c in cell.controllers if poll}
        self._next_index = len(cell.controllers)  # a controller that joins later: aliases never reused
        # the last session's bdSeq + 1 when kept in a file (a restart is a new session too), else 0
        self._bdseq_store = None if bdseq_file is None else BdSeqStore(bdseq_file, group, node)
        self.bdseq = 0 if self._bdseq_store is None else self._bdseq_store.first()
        self._seq = 0
        self._online = False  # an MQTT session is up and NBIRTH went out
        self.sessions = 0  # MQTT sessions so far (NBIRTHs after a connect)
        self._running = False
        self.answers = 0  # answered polls of all controllers so far
        self.primary_host = primary_host
        self._primary_online = False
        self._primary_stamp = -1  # the newest STATE's timestamp (older ones are stale)
        self._connected = False  # an MQTT session is up (born or waiting for the primary host)
        self._disconnected = threading.Event()  # set by every on_disconnect
        self._unreachable_said = False  # "cannot reach the broker" said once per outage
        limit = timing.GATEWAY_HISTORY_LIMIT if history_limit is None else history_limit
        self._history: deque[tuple[str, Any]] = deque(maxlen=max(1, limit))
        self.history_dropped = 0  # DDATA the bound dropped while the broker was away, since the start
        self._client = self._make_client()
        # the pollers' answers (a Reading) and silences (the reason) for the publisher thread
        self._inbox: queue.SimpleQueue[tuple[str, Reading | str]] = queue.SimpleQueue()
        self._wake = threading.Event()  # something waits in the inbox that a poller did not publish
        self._publisher: threading.Thread | None = None
        self._publisher_done = False

    def _read_envelope(self, controllers: tuple[CellController, ...]) -> None:
        """The safety envelope in force (the GUI's and the CLI's), read once when a robot has plant
        writes (before anything changes: one that cannot be read raises, nothing is half made)."""
        if self._envelope is None and self._writes and any(c.plant_writes for c in controllers):
            from app.cli.guard import envelope_in_force

            self._envelope = envelope_in_force()

    def _allowed(self, controller: CellController) -> CellController:
        """``controller`` as this node serves it: without plant writes when ``writes`` is off."""
        return controller if self._writes else dataclasses.replace(controller, plant_writes=())

    def _device(self, controller: CellController, index: int) -> _Device:
        metrics = device_metrics(self._allowed(controller))
        plan = tuple((ALL_METRICS[i], device_alias(index, i)) for i in metrics)
        return _Device(controller.name, index, metrics, plan)

    def _poller(self, controller: CellController) -> ControllerPoller:
        """Its poller, and its plant writer (which refuses what is not enabled; the poller only
        makes a client that can write when something is)."""
        writer = self._writers[controller.name] = self._writer(controller)
        return ControllerPoller(controller, self, self.timing, writer)

    def _writer(self, controller: CellController) -> PlantWriter:
        name = controller.name
        controller = self._allowed(controller)
        audit = AuditLog(self._audit_dir, role=plant_audit_role(name))
        return PlantWriter(controller, self._envelope, audit, self, lambda: self._pendant_robot == name)

    def set_pendant_robot(self, name: str | None) -> None:
        """The robot this TeachPad's pendant commands now (the GUI's Take control; None: none): the
        plant's writes to it are refused meanwhile."""
        self._pendant_robot = name

    # -- topics ---------------------------------------------------------------------------
    def topic(self, kind: str, device: str | None = None) -> str:
        base = f"{NAMESPACE}/{self.group}/{kind}/{self.node}"
        return base if device is None else f"{base}/{device}"

    # -- lifecycle ------------------------------------------------------------------------
    def _make_client(self) -> mqtt.Client:
        client = mqtt.Client(
            callback_api_version=CallbackAPIVersion.VERSION2,
            client_id=f"teachpad-{self.group}-{self.node}",
            clean_session=True,
        )
        b = self._broker
        if b.username is not None:
            client.username_pw_set(b.username, b.password)
        if b.tls:
            client.tls_set(
                ca_certs=b.cafile, certfile=b.certfile, keyfile=b.keyfile, cert_reqs=ssl.CERT_REQUIRED
            )
        first, largest = self.timing.broker_retry
        client.reconnect_delay_set(min_delay=max(1, first), max_delay=max(1, first, largest))
        client.enable_logger(logging.getLogger("app.gateway.mqtt"))
        client.on_connect = self._on_connect
        client.on_connect_fail = self._on_connect_fail
        client.on_disconnect = self._on_disconnect
        client.on_message = self._on_message
        self._set_will(client)
        return client

    def _set_will(self, client: mqtt.Client) -> None:
        """The session's will (its bdSeq: kept in the file first, when there is one)."""
        if self._bdseq_store is not None:
            self._bdseq_store.save(self.bdseq)
        client.will_set(self.topic("NDEATH"), self._ndeath(), qos=1, retain=False)

    def _ndeath(self) -> bytes:
        death = pb.Payload(timestamp=_now_ms())
        metric = death.metrics.add(name=BDSEQ, timestamp=death.timestamp, datatype=pb.DataType.INT64)
        pb.set_value(metric, pb.DataType.INT64, self.bdseq)
        return pb.encode(death)

    def start(self) -> None:
        """Connect (in the background: a broker that is not up yet is tried again) and poll."""
        self._running = True
        self._client.connect_async(self._broker.host, self._broker.port, keepalive=self.timing.keepalive)
        self._client.loop_start()
        self._publisher_done = False
        self._publisher = threading.Thread(target=self._publish_loop, name="gateway-publish", daemon=True)
        self._publisher.start()
        for poller in self._pollers.values():
            poller.start()

    def stop(self) -> None:
        """Stop polling, publish NDEATH (a clean disconnect does not fire the will), disconnect."""
        if not self._running:
            return
        self._running = False
        for poller in list(self._pollers.values()):
            poller.stop()
        if self._publisher is not None:  # what the pollers told before they stopped goes out first
            self._publisher_done = True
            self._wake.set()
            self._publisher.join()
            self._publisher = None
        with self._lock:
            self._drain()
            online, self._online = self._online, False
            if online:
                info = self._client.publish(self.topic("NDEATH"), self._ndeath(), qos=1)
        if online:
            try:
                info.wait_for_publish(self.timing.stop_wait)
            except (RuntimeError, ValueError) as exc:  # not sent: the broker fires the will anyway
                _log.warning("NDEATH not sent on stop: %s", exc)
        self._client.disconnect()
        self._client.loop_stop()

    def set_cell(self, cell: Cell) -> None:
        """The cell file changed: a controller that left (or whose settings changed) gets its DDEATH
        and its poller stops; one that joined gets a poller (and its DBIRTH at its first answer, with
        aliases of its own: a device index is never used twice)."""
        self._read_envelope(cell.controllers)
        wanted = {c.name: c for c in cell.controllers}
        with self._lock:
            leaving = [n for n, c in self._controllers.items() if wanted.get(n) != c]
            stopped = [self._pollers.pop(name) for name in leaving if name in self._pollers]
            if leaving:  # their kept changes go with them (no DBIRTH will come before them)
                topics = {self.topic("DDATA", name) for name in leaving}
                kept = [(t, m) for t, m in self._history if t not in topics]
                self._history = deque(kept, maxlen=self._history.maxlen)
            for name in leaving:
                self._writers.pop(name, None)
                state = self._devices.pop(name)
                del self._controllers[name]
                if state.alive and self._online:
                    self._publish(self.topic("DDEATH", name), pb.Payload(timestamp=_now_ms()))
            joining = [c for n, c in wanted.items() if n not in self._controllers]
            for controller in joining:
                self._devices[controller.name] = self._device(controller, self._next_index)
                self._next_index += 1
                self._controllers[controller.name] = controller
                if self._poll:
                    self._pollers[controller.name] = self._poller(controller)
        for poller in stopped:  # outside the lock: its thread may be waiting for it
            poller.stop()
        if self._running:
            for controller in joining:
                if controller.name in self._pollers:
                    self._pollers[controller.name].start()
        _log.warning("cell changed: %d controller(s) left, %d joined", len(leaving), len(joining))

    # -- MQTT callbacks (paho's network thread) -------------------------------------------
    def _on_connect(self, client: mqtt.Client, _userdata: Any, _flags: Any, reason: Any, _props: Any) -> None:
        if reason.is_failure:
            _log.warning("broker refused the connection: %s", reason)
            return
        client.subscribe(self.topic("NCMD"), qos=1)
        client.subscribe(self.topic("DCMD", "+"), qos=1)
        if self.primary_host is not None:
            client.subscribe(self._state_topic(), qos=1)
        if self._unreachable_said:
            self._unreachable_said = False
            _log.warning("connected to the MQTT broker at %s:%d", self._broker.host, self._broker.port)
        with self._lock:
            self.sessions += 1
            self._connected = True
            self._primary_online = False  # its retained STATE comes with the subscription
            if self.primary_host is None:
                self._birth()

    def _on_connect_fail(self, _client: mqtt.Client, _userdata: Any) -> None:
        if not self._unreachable_said:
            self._unreachable_said = True
            b = self._broker
            first, largest = self.timing.broker_retry
            _log.warning(
                "cannot reach the MQTT broker at %s:%d; trying again (every %d to %d s)",
                b.host,
                b.port,
                first,
                largest,
            )

    def _on_disconnect(
        self, client: mqtt.Client, _userdata: Any, _flags: Any, reason: Any, _props: Any
    ) -> None:
        self._disconnected.set()
        with self._lock:
            self._connected = False
            if not self._online:
                return
            self._online = False
            self.bdseq = (self.bdseq + 1) % 256  # the next session's will and NBIRTH
            self._set_will(client)
        _log.warning("broker connection lost (%s); a new session will have bdSeq %d", reason, self.bdseq)

    def _state_topic(self) -> str:
        return f"{NAMESPACE}/STATE/{self.primary_host}"

    def _on_state(self, data: bytes) -> None:
        """The primary host's STATE: born while it is online, the session ended when it goes offline."""
        try:
            state = json.loads(data.decode("utf-8"))
            online, stamp = state["online"], state["timestamp"]
            if not isinstance(online, bool) or not isinstance(stamp, int):
                raise ValueError("online must be true or false, timestamp a whole number")
        except (ValueError, KeyError, TypeError) as exc:
            _log.warning("STATE of %s not understood: %s", self.primary_host, exc)
            return
        with self._lock:
            if stamp < self._primary_stamp:
                return  # stale
            self._primary_stamp = stamp
            self._primary_online = online
            if online and self._connected and not self._online:
                self._birth()
            elif not online and self._online:
                _log.warning(
                    "primary host %s offline: session ended, a new one waits for it", self.primary_host
                )
                self._online = False
                self._client.publish(self.topic("NDEATH"), self._ndeath(), qos=1)
                threading.Thread(target=self._new_session, name="gateway-new-session", daemon=True).start()

    def _new_session(self) -> None:
        """Disconnect, then connect again with bdSeq + 1 (not from paho's own thread: it is stopped here)."""
        self._disconnected.clear()
        self._client.disconnect()
        # paho closes the socket right after on_disconnect, in its thread: let it, then stop that thread
        self._disconnected.wait(self.timing.stop_wait)
        self._client.loop_stop()
        # paho 2.2's loop_start makes a new wake-up socket pair without closing the last one's: close
        # it here (its own method for that), or the next loop_start leaves two sockets to the GC
        reset = getattr(self._client, "_reset_sockets", None)
        if reset is not None:
            reset(sockpair_only=True)
        with self._lock:
            if not self._running:
                return
            self.bdseq = (self.bdseq + 1) % 256
            self._set_will(self._client)
            self._client.connect_async(self._broker.host, self._broker.port, keepalive=self.timing.keepalive)
            self._client.loop_start()

    def _on_message(self, _client: mqtt.Client, _userdata: Any, message: mqtt.MQTTMessage) -> None:
        if self.primary_host is not None and message.topic == self._state_topic():
            self._on_state(bytes(message.payload))
            return
        dcmd = self.topic("DCMD") + "/"
        if message.topic.startswith(dcmd):
            self._on_dcmd(message.topic[len(dcmd) :], bytes(message.payload))
            return
        if message.topic != self.topic("NCMD"):
            return
        try:
            command = pb.decode(message.payload)
        except DecodeError as exc:  # a malformed NCMD is the sender's problem: said, ignored
            _log.warning("NCMD not understood: %s", exc)
            return
        for metric in command.metrics:
            is_rebirth = metric.name == REBIRTH or (not metric.name and metric.alias == REBIRTH_ALIAS)
            if is_rebirth and pb.metric_value(metric) is True:
                _log.info("rebirth asked for by NCMD")
                with self._lock:
                    if self._online:
                        self._birth()

    def _on_dcmd(self, device: str, data: bytes) -> None:
        """A write from the plant: each metric to the robot's plant writer (refused there when not
        enabled; refused here when the robot does not answer)."""
        try:
            payload = pb.decode(data)
        except DecodeError as exc:
            _log.warning("DCMD for %s not understood: %s", device, exc)
            return
        with self._lock:
            state, writer = self._devices.get(device), self._writers.get(device)
            if state is None or writer is None:
                _log.warning("DCMD for %r, not a controller of the cell: ignored", device)
                return
            commands = []
            for metric in payload.metrics:
                state.commands += 1
                write = self._write_named(state, metric)
                commands.append(
                    PlantCommand(state.commands, write, pb.metric_value(metric), time.monotonic())
                )
            alive = state.alive
        for command in commands:
            _log.warning("plant command for %s: %s", device, command.text)
            if alive:
                writer.submit(command)
            else:
                writer.refuse(command, f"{device} does not answer")

    @staticmethod
    def _write_named(state: _Device, metric: Any) -> str:
        """The cell file's name of the write a DCMD metric asks for (by name, or by its alias)."""
        name = str(metric.name)
        if not name:
            found = [i for i in state.metrics if device_alias(state.index, i) == metric.alias]
            name = ALL_METRICS[found[0]].name if found else f"alias {metric.alias}"
        return COMMAND_WRITES.get(name, name)

    def plant_said(self, device: str, text: str, values: Mapping[str, pb.Value]) -> None:
        """What became of a plant command (:class:`~app.gateway.plant.PlantListener`): the device's
        ``Plant/Last command result`` and the written metrics' values, in a DDATA."""
        _log.warning("%s: %s", device, text)
        with self._lock:
            state = self._devices.get(device)
            if state is None:
                return
            state.kept[PLANT_RESULT] = text
            state.kept.update(values)
            if state.values is not None:
                state.values.update(state.kept)
                if state.alive and state.sent is not None:
                    self._ddata(state, _now_ms())

    # -- publishing (under the lock) ------------------------------------------------------
    def _publish(self, topic: str, message: Any) -> None:
        message.seq = self._seq
        self._seq = (self._seq + 1) % 256
        self._client.publish(topic, pb.encode(message), qos=0, retain=False)

    @property
    def online(self) -> bool:
        """An MQTT session is up and its NBIRTH went out."""
        return self._online

    def _birth(self) -> None:
        """NBIRTH (seq 0), then a DBIRTH for every answering controller, then the history."""
        self._seq = 0
        self._online = True
        birth = pb.Payload(timestamp=_now_ms())
        bdseq = birth.metrics.add(name=BDSEQ, timestamp=birth.timestamp, datatype=pb.DataType.INT64)
        pb.set_value(bdseq, pb.DataType.INT64, self.bdseq)
        rebirth = birth.metrics.add(
            name=REBIRTH, alias=REBIRTH_ALIAS, timestamp=birth.timestamp, datatype=pb.DataType.BOOLEAN
        )
        pb.set_value(rebirth, pb.DataType.BOOLEAN, False)
        dropped = birth.metrics.add(
            name=HISTORY_DROPPED, timestamp=birth.timestamp, datatype=pb.DataType.UINT64
        )
        pb.set_value(dropped, pb.DataType.UINT64, self.history_dropped)
        self._publish(self.topic("NBIRTH"), birth)
        for device in self._devices.values():
            if device.alive and device.values is not None:
                self._dbirth(device, birth.timestamp)
        self._send_history()

    def _send_history(self) -> None:
        if self._history:
            _log.warning(
                "broker back: %d change(s) kept while it was away sent as historical (%d dropped so far)",
                len(self._history),
                self.history_dropped,
            )
        while self._history:
            topic, message = self._history.popleft()
            for metric in message.metrics:
                metric.is_historical = True
            self._publish(topic, message)

    def _dbirth(self, device: _Device, stamp: int) -> None:
        assert device.values is not None
        message = pb.Payload(timestamp=stamp)
        for i in device.metrics:
            spec = ALL_METRICS[i]
            metric = message.metrics.add(
                name=spec.name, alias=device_alias(device.index, i), timestamp=stamp, datatype=spec.datatype
            )
            pb.set_value(metric, spec.datatype, device.values[spec.name])
        device.sent = dict(device.values)
        self._publish(self.topic("DBIRTH", device.name), message)

    def _ddata(self, device: _Device, stamp: int) -> None:
        """The metrics past their deadband: published, or kept while the broker is away."""
        message = self._changes(device, stamp)
        if message is None:
            return
        topic = self.topic("DDATA", device.name)
        if self._online:
            self._publish(topic, message)
            return
        if len(self._history) == self._history.maxlen:
            self.history_dropped += 1
        self._history.append((topic, message))

    def _changes(self, device: _Device, stamp: int) -> Any:
        """A DDATA payload of what moved past its deadband since the last one (None: nothing).

        Every poll of every controller passes here (640 a second at 64 controllers and 10 Hz): a
        value equal to the one sent is skipped before the deadband rule (most are: mode, alarms,
        a robot standing still), and the payload is made only when something is to be sent."""
        values, sent = device.values, device.sent
        assert values is not None and sent is not None
        moved = []
        deadbands = self._deadbands
        for spec, alias in device.plan:
            name = spec.name
            now, before = values[name], sent[name]
            if now == before and type(now) is type(before):  # (NaN != NaN: the rule decides)
                continue
            if changed(spec, before, now, deadbands):
                moved.append((spec.datatype, alias, now))
                sent[name] = now
        if not moved:
            return None
        message = pb.Payload(timestamp=stamp)
        add = message.metrics.add
        for datatype, alias, now in moved:
            pb.set_value(add(alias=alias, timestamp=stamp), datatype, now)
        return message

    # -- the pollers (their threads) hand over; whoever holds the lock publishes -------------
    def answered(self, device: str, reading: Reading) -> None:
        self._inbox.put((device, reading))
        self._hand_over()

    def silent(self, device: str, reason: str) -> None:
        self._inbox.put((device, reason))
        self._hand_over()

    def _hand_over(self) -> None:
        """Publish what is waiting when the lock is free; else, without waiting for it, wake the
        publisher thread, which takes what waits once the lock is free (a poller holding it may have
        taken it already)."""
        if self._lock.acquire(blocking=False):
            try:
                self._drain()
            finally:
                self._lock.release()
        else:
            self._wake.set()

    def _publish_loop(self) -> None:
        """The publisher thread: what a poller could not publish itself (the lock was held)."""
        while not self._publisher_done:
            self._wake.wait()
            self._wake.clear()
            with self._lock:
                self._drain()

    def _drain(self) -> None:
        """What the pollers told, in order (under the lock: one thread at a time takes from the queue)."""
        inbox = self._inbox
        while True:
            try:
                device, told = inbox.get_nowait()
            except queue.Empty:
                return
            try:
                if isinstance(told, str):
                    self._silent(device, told)
                else:
                    self._answered(device, told)
            except Exception:  # one device's bad answer must not end the publishing
                _log.exception("%s: its answer could not be published", device)

    def _answered(self, device: str, reading: Reading) -> None:
        """An answer (under the lock): the device's values, its DBIRTH or DDATA."""
        self.answers += 1
        state = self._devices.get(device)
        if state is None:  # it left the cell
            return
        if reading.clock is not None:
            state.clock = clock_text(reading.clock)
        freshness = int((time.monotonic() - reading.answered_at) * 1000)
        self._count_cycle(state, reading)
        state.values = device_values(reading, freshness, state.clock, state.kept)
        if not state.alive:
            state.alive = True
            if self._online:
                self._dbirth(state, reading.wall_ms)
        elif state.sent is not None:  # births told the subscribers its values once
            self._ddata(state, reading.wall_ms)

    @staticmethod
    def _count_cycle(state: _Device, reading: Reading) -> None:
        """The program cycle counters (app/cell/history.py's rule, from the program-state register)."""
        if state.values is None:
            return
        before, status = state.values["Status/Program state"], reading.status
        cycle = program_cycle(int(before or 0), int(status.program_state), int(status.alarms))
        if cycle is not None:
            name = CYCLE_METRICS[cycle]
            state.kept[name] = int(state.kept[name] or 0) + 1

    def _silent(self, device: str, reason: str) -> None:
        """A failed poll (under the lock): the device's DDEATH when it was alive."""
        state = self._devices.get(device)
        if state is None:
            return
        if not state.alive:
            if state.never_said and state.values is None:
                _log.warning("%s does not answer (trying again): %s", device, reason)
            state.never_said = False
            return
        state.alive = False
        _log.warning("%s stopped answering: %s", device, reason)
        if self._online:
            self._publish(self.topic("DDEATH", device), pb.Payload(timestamp=_now_ms()))

"""bdSeq across restarts of the gateway (Sparkplug 3.0: + 1 with every new MQTT session, a restart
of the edge node included): kept in a small file written atomically."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path
from typing import Any

from app.gateway import payload as pb
from app.gateway.bdseq import BdSeqStore, default_bdseq_file
from tests.waits import kill_child, wait_child

from .conftest import Subscriber, write_cell
from .test_gateway_cli import KEEPALIVE, _start


def _bdseq(message: Any) -> Any:
    return pb.metric_value(message.metric("bdSeq"))


def test_a_restarted_edge_node_is_born_with_the_last_bdseq_plus_one(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    kept = tmp_path / "state" / "plant.pad1.bdseq.json"
    sim = sim_factory()
    first = gateway_factory({"R1": sim}, bdseq_file=kept)
    birth = subscriber.kind("NBIRTH")
    assert _bdseq(birth) == 0  # no file yet: the first session ever
    first.stop()
    death = subscriber.kind("NDEATH")
    assert _bdseq(death) == 0
    start = subscriber.count()
    gateway_factory({"R1": sim}, bdseq_file=kept)
    again = subscriber.kind("NBIRTH", start=start)
    assert _bdseq(again) == 1
    assert json.loads(kept.read_text())["bdSeq"] == 1


def test_the_restarted_gateway_process_will_carries_the_previous_plus_one(
    sim_factory: Any, broker: Any, subscriber: Subscriber, tmp_path: Path
) -> None:
    """Two runs of teachpad-gateway: the second one's NBIRTH and the broker's NDEATH (its will, after
    kill -9) both carry the first one's bdSeq + 1."""
    cell = write_cell(tmp_path, {"R1": sim_factory()})
    kept = tmp_path / "bdseq.json"
    proc = _start(cell, broker.port, "--bdseq-file", str(kept))
    try:
        first = subscriber.kind("NBIRTH", timeout=30.0)
        proc.send_signal(signal.SIGTERM)
        assert wait_child(proc, "teachpad-gateway after SIGTERM") == 0
    finally:
        kill_child(proc)
    start = subscriber.count()
    proc = _start(cell, broker.port, "--bdseq-file", str(kept))
    try:
        second = subscriber.kind("NBIRTH", start=start, timeout=30.0)
        subscriber.kind("DBIRTH", "R1", start=subscriber.messages.index(second))
        start = subscriber.count()
        os.kill(proc.pid, signal.SIGKILL)
        will = subscriber.kind("NDEATH", start=start, timeout=1.5 * KEEPALIVE + 5.0)
    finally:
        kill_child(proc)
    assert _bdseq(second) == (_bdseq(first) + 1) % 256
    assert _bdseq(will) == _bdseq(second)
    assert (will.qos, will.retain) == (1, False)


def test_the_count_wraps_at_255_and_a_damaged_file_counts_from_0(tmp_path: Path) -> None:
    path = tmp_path / "g" / "b.json"
    store = BdSeqStore(path, "plant", "pad1")
    assert store.last() is None and store.first() == 0
    store.save(255)
    assert store.first() == 0
    store.save(41)
    assert BdSeqStore(path, "plant", "pad1").first() == 42
    assert list(path.parent.iterdir()) == [path]  # written atomically: no temp file left
    path.write_text("{not json")
    assert store.first() == 0
    path.write_text(json.dumps({"format": "teachpad-gateway-bdseq", "version": 1, "bdSeq": 300}))
    assert store.first() == 0


def test_the_default_file_is_per_group_and_node_in_the_data_folder(tmp_path: Path, monkeypatch: Any) -> None:
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path))
    assert default_bdseq_file("plant", "pad1") == tmp_path / "teachpad" / "gateway" / "plant.pad1.bdseq.json"
    assert default_bdseq_file("plant", "pad2") != default_bdseq_file("plant", "pad1")

"""The primary host application's STATE (Sparkplug 3.0, optional): born only while it is online."""

from __future__ import annotations

import json
import time
from typing import Any

from app.gateway import payload as pb

from .conftest import Subscriber
from .test_sparkplug import wait_until

STATE = "spBv1.0/STATE/scada"


def _state(subscriber: Subscriber, online: bool, stamp: int) -> None:
    subscriber.publish(STATE, json.dumps({"online": online, "timestamp": stamp}).encode(), retain=True)


def test_born_only_while_the_primary_host_is_online(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    node = gateway_factory({"R1": sim_factory()}, primary_host="scada")
    wait_until(lambda: node.sessions >= 1 and node.answers >= 10, "a session and ten polls")
    assert not [m for m in subscriber.snapshot() if m.kind in ("NBIRTH", "DBIRTH", "DDATA")]
    stamp = int(time.time() * 1000)
    start = subscriber.count()
    _state(subscriber, True, stamp)  # retained, as a host application publishes it
    birth = subscriber.kind("NBIRTH", start=start)
    assert pb.metric_value(birth.metric("bdSeq")) == 0
    subscriber.kind("DBIRTH", "R1", start=start)
    start = subscriber.count()
    _state(subscriber, False, stamp + 1)
    death = subscriber.kind("NDEATH", start=start)
    assert pb.metric_value(death.metric("bdSeq")) == 0
    start = subscriber.count()
    _state(subscriber, True, stamp + 2)
    again = subscriber.kind("NBIRTH", start=start)
    assert pb.metric_value(again.metric("bdSeq")) == 1  # a new session
    assert again.seq == 0


def test_a_stale_offline_state_is_ignored(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    node = gateway_factory({"R1": sim_factory()}, primary_host="scada")
    stamp = int(time.time() * 1000)
    _state(subscriber, True, stamp)
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    _state(subscriber, False, stamp - 1000)  # older than the online one
    # a rebirth asked for after it comes back on the same session: nothing ended it
    command = pb.Payload(timestamp=stamp)
    pb.set_value(
        command.metrics.add(name="Node Control/Rebirth", datatype=pb.DataType.BOOLEAN),
        pb.DataType.BOOLEAN,
        True,
    )
    subscriber.publish("spBv1.0/plant/NCMD/pad1", pb.encode(command))
    birth = subscriber.kind("NBIRTH", start=start)
    assert pb.metric_value(birth.metric("bdSeq")) == 0
    assert not [m for m in subscriber.snapshot()[start:] if m.kind == "NDEATH"]
    assert node.online

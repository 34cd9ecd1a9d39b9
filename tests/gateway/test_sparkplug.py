"""Sparkplug B 3.0 conformance of the edge node, one test per rule, against a real Mosquitto, read by
an independent subscriber that decodes the payloads (tests/gateway/conftest.py)."""

from __future__ import annotations

import itertools
import time
from typing import Any

from app.gateway import payload as pb
from app.gateway.metrics import DEVICE_METRICS, METRIC_INDEX, REBIRTH, REBIRTH_ALIAS, device_alias

from .conftest import BrokerLink, Received, Subscriber

NODE_KINDS = {"NBIRTH", "DBIRTH", "DDATA", "DDEATH"}


def _bdseq(message: Received) -> Any:
    return pb.metric_value(message.metric("bdSeq"))


def _aliases(message: Received) -> set[int]:
    return {int(m.alias) for m in message.payload.metrics}


def test_nbirth_seq0_bdseq_rebirth_then_a_dbirth_per_device(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sims = {"R1": sim_factory(), "R2": sim_factory()}
    gateway_factory(sims)
    nbirth = subscriber.kind("NBIRTH")
    assert nbirth.topic == "spBv1.0/plant/NBIRTH/pad1"
    assert nbirth.seq == 0
    assert _bdseq(nbirth) == 0
    rebirth = nbirth.metric(REBIRTH)
    assert rebirth.datatype == pb.DataType.BOOLEAN and pb.metric_value(rebirth) is False
    assert (nbirth.qos, nbirth.retain) == (0, False)
    start = subscriber.messages.index(nbirth)
    births = {name: subscriber.kind("DBIRTH", name, start=start) for name in sims}
    for index, (name, birth) in enumerate(births.items()):
        assert birth.topic == f"spBv1.0/plant/DBIRTH/pad1/{name}"
        assert [m.name for m in birth.payload.metrics] == [spec.name for spec in DEVICE_METRICS]
        assert [m.alias for m in birth.payload.metrics] == [
            device_alias(index, i) for i in range(len(DEVICE_METRICS))
        ]
        assert all(
            m.datatype == spec.datatype for m, spec in zip(birth.payload.metrics, DEVICE_METRICS, strict=True)
        )
    # the values are the controller's: its pose as the simulator holds it
    x = pb.metric_value(births["R1"].metric("Pose/X"))
    assert x == sims["R1"].robot.pose[0] or abs(float(x) - float(sims["R1"].robot.pose[0])) < 1e-3  # type: ignore[arg-type]
    # monitor-only: nothing was written to any controller
    assert all(sim.writes == [] for sim in sims.values())


def test_ddata_by_exception_with_deadband_and_aliases_only(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim}, deadbands={"Link/RTT": 1e9, "Link/Freshness": 1e9})
    birth = subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    j1, j2 = device_alias(0, METRIC_INDEX["Joints/J1"]), device_alias(0, METRIC_INDEX["Joints/J2"])
    joints = sim.robot.joints
    sim.set_joint(1, float(joints[0]) + 0.005)  # within J1's deadband (0.01 deg): never sent
    sim.set_joint(2, float(joints[1]) + 1.0)  # past J2's
    data = subscriber.wait_for(
        "DDATA with J2", lambda m: m.kind == "DDATA" and j2 in _aliases(m), start=start
    )
    for message in subscriber.snapshot()[start:]:
        if message.kind == "DDATA":
            assert all(not m.name for m in message.payload.metrics), "a DDATA metric carries its name"
            assert _aliases(message) <= _aliases(birth)
            assert j1 not in _aliases(message), "J1 moved less than its deadband but was sent"
    value = next(m for m in data.payload.metrics if m.alias == j2)
    assert abs(pb.metric_value(value) - (float(joints[1]) + 1.0)) < 1e-3  # type: ignore[operator]
    assert "Joints/J3" not in {
        spec.name for spec in DEVICE_METRICS if device_alias(0, METRIC_INDEX[spec.name]) in _aliases(data)
    }


def test_seq_counts_every_node_message_and_wraps_at_255(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sims = {"R1": sim_factory(), "R2": sim_factory()}
    # RTT without a deadband: nearly every poll is a DDATA, so 256 messages come quickly
    gateway_factory(sims, deadbands={"Link/RTT": 0.0}, poll_hz=100.0)
    nbirth = subscriber.kind("NBIRTH")
    start = subscriber.messages.index(nbirth)
    subscriber.wait_for(
        "300 node messages", lambda _m: subscriber_len(subscriber) - start > 300, timeout=30.0
    )
    ours = [m for m in subscriber.snapshot()[start:] if m.kind in NODE_KINDS]
    seqs = [m.seq for m in ours]
    assert seqs[0] == 0
    for before, after in itertools.pairwise(seqs):
        assert after == ((before or 0) + 1) % 256, f"seq {before} was followed by {after}"
    assert 255 in seqs and seqs[seqs.index(255) + 1] == 0


def subscriber_len(subscriber: Subscriber) -> int:
    return len(subscriber.messages)


def test_ddeath_within_250_ms_of_silence_and_dbirth_when_it_answers_again(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sims = {"R1": sim_factory(), "R2": sim_factory()}
    gateway_factory(sims)
    subscriber.kind("DBIRTH", "R2")
    start = subscriber.count()
    silent_at = time.monotonic()  # from here on no poll of R2 can be answered
    sims["R2"].set_silent(True)
    death = subscriber.kind("DDEATH", "R2", start=start)
    took = death.at - silent_at
    assert took <= 0.25, f"DDEATH {took * 1000:.0f} ms after the controller went silent"
    assert death.seq is not None
    sims["R2"].set_silent(False)
    after = subscriber.messages.index(death)
    again = subscriber.kind("DBIRTH", "R2", start=after)
    assert [m.name for m in again.payload.metrics] == [spec.name for spec in DEVICE_METRICS]
    # R1 kept answering: no DDEATH for it
    assert not [m for m in subscriber.snapshot() if m.kind == "DDEATH" and m.device == "R1"]
    # reconnecting to a controller writes nothing either (monitor-only)
    assert all(sim.writes == [] for sim in sims.values())


def test_rebirth_on_ncmd(sim_factory: Any, subscriber: Subscriber, gateway_factory: Any) -> None:
    gateway_factory({"R1": sim_factory()})
    first = subscriber.kind("NBIRTH")
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    _ask_rebirth(subscriber)
    again = subscriber.kind("NBIRTH", start=start)
    assert again.seq == 0 and _bdseq(again) == _bdseq(first)
    dbirth = subscriber.kind("DBIRTH", "R1", start=subscriber.messages.index(again))
    assert dbirth.seq == 1
    # by alias too (a host application that learned the alias from the NBIRTH)
    start = subscriber.count()
    command = pb.Payload(timestamp=int(time.time() * 1000))
    pb.set_value(command.metrics.add(alias=REBIRTH_ALIAS), pb.DataType.BOOLEAN, True)
    subscriber.publish("spBv1.0/plant/NCMD/pad1", pb.encode(command))
    subscriber.kind("NBIRTH", start=start)


def test_new_session_with_bdseq_plus_one_after_a_broker_restart(
    sim_factory: Any, broker: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    node = gateway_factory({"R1": sim_factory()})
    first = subscriber.kind("NBIRTH")
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    broker.restart()
    wait_until(lambda: subscriber.subscriptions >= 2 and node.online, "the subscriber and the gateway back")
    # which of the two came back first is chance: a NBIRTH the subscriber missed is asked for again,
    # as a host application does (a rebirth keeps the session's bdSeq)
    if not [m for m in subscriber.snapshot()[start:] if m.kind == "NBIRTH"]:
        _ask_rebirth(subscriber)
    again = subscriber.kind("NBIRTH", start=start)
    assert _bdseq(again) == _bdseq(first) + 1
    assert again.seq == 0
    subscriber.kind("DBIRTH", "R1", start=subscriber.messages.index(again))


def test_stop_publishes_ndeath_with_the_sessions_bdseq(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    node = gateway_factory({"R1": sim_factory()})
    first = subscriber.kind("NBIRTH")
    node.stop()
    death = subscriber.kind("NDEATH")
    assert _bdseq(death) == _bdseq(first)
    assert death.seq is None


def test_no_ddata_while_nothing_moves_past_its_deadband(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    node = gateway_factory({"R1": sim_factory()}, deadbands={"Link/RTT": 1e9, "Link/Freshness": 1e9})
    subscriber.kind("DBIRTH", "R1")
    start, answers = subscriber.count(), node.answers
    wait_until(lambda: node.answers >= answers + 20, "20 more answered polls")
    # a DDATA those polls caused comes before anything the node publishes after them (one
    # connection, in order): ask for a rebirth and look at what came before its NBIRTH
    _ask_rebirth(subscriber)
    end = subscriber.messages.index(subscriber.kind("NBIRTH", start=start))
    quiet = [m for m in subscriber.snapshot()[start:end] if m.kind == "DDATA"]
    assert quiet == [], f"{len(quiet)} DDATA while the robot stood still"


def wait_until(condition: Any, what: str, timeout: float = 10.0) -> None:
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"no {what} within {timeout:g} s"
        time.sleep(0.01)  # a counter in another thread: nothing to wait on


def _ask_rebirth(subscriber: Subscriber) -> None:
    command = pb.Payload(timestamp=int(time.time() * 1000))
    metric = command.metrics.add(name=REBIRTH, datatype=pb.DataType.BOOLEAN)
    pb.set_value(metric, pb.DataType.BOOLEAN, True)
    subscriber.publish("spBv1.0/plant/NCMD/pad1", pb.encode(command))


def _history_run(
    sim: Any, link: BrokerLink, node: Any, subscriber: Subscriber, changes: int
) -> tuple[int, list[float]]:
    """The broker goes out of the gateway's reach (the subscriber, connected directly, stays), J2
    changes ``changes`` times (each seen by a poll), the broker is back: where the subscriber's
    messages after the outage begin, and the J2 values polled meanwhile."""
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    link.cut()
    wait_until(lambda: not node.online, "the gateway seeing the broker gone")
    base = float(sim.robot.joints[1])
    values = [base + k + 1.0 for k in range(changes)]
    for value in values:
        answers = node.answers
        sim.set_joint(2, value)
        wait_until(lambda: node.answers >= answers + 2, "two polls after a change")  # noqa: B023
    link.restore()
    return start, values


#: RTT and freshness past any deadband, the clock read once (its seconds move): J2 is all that changes
QUIET = {"deadbands": {"Link/RTT": 1e9, "Link/Freshness": 1e9}, "clock_period": 3600.0}


def test_changes_while_the_broker_is_away_come_back_historical(
    sim_factory: Any, broker_link: BrokerLink, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sim = sim_factory()
    node = gateway_factory({"R1": sim}, port=broker_link.port, **QUIET)
    start, values = _history_run(sim, broker_link, node, subscriber, 5)
    birth = subscriber.kind("NBIRTH", start=start, timeout=15.0)
    assert pb.metric_value(birth.metric("Node Info/History dropped")) == 0
    dbirth = subscriber.kind("DBIRTH", "R1", start=subscriber.messages.index(birth))
    j2 = device_alias(0, METRIC_INDEX["Joints/J2"])
    subscriber.wait_for("5 historical DDATA", lambda _m: len(_historical(subscriber, j2)) >= 5)
    got = _historical(subscriber, j2)
    assert [round(v, 3) for v, _ in got] == [round(v, 3) for v in values]  # nothing lost, in order
    assert [t for _, t in got] == sorted(t for _, t in got)
    assert all(t <= dbirth.payload.timestamp for _, t in got)  # older than the births


def test_the_history_bound_drops_the_oldest_and_says_how_many(
    sim_factory: Any, broker_link: BrokerLink, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sim = sim_factory()
    node = gateway_factory({"R1": sim}, history_limit=2, port=broker_link.port, **QUIET)
    start, values = _history_run(sim, broker_link, node, subscriber, 5)
    birth = subscriber.kind("NBIRTH", start=start, timeout=15.0)
    assert pb.metric_value(birth.metric("Node Info/History dropped")) == 3
    j2 = device_alias(0, METRIC_INDEX["Joints/J2"])
    subscriber.wait_for("2 historical DDATA", lambda _m: len(_historical(subscriber, j2)) >= 2)
    assert [round(v, 3) for v, _ in _historical(subscriber, j2)] == [round(v, 3) for v in values[-2:]]


def _historical(watcher: Subscriber, alias: int) -> list[tuple[float, int]]:
    return [
        (float(pb.metric_value(m)), int(m.timestamp))  # type: ignore[arg-type]
        for message in watcher.snapshot()
        if message.kind == "DDATA"
        for m in message.payload.metrics
        if m.alias == alias and m.is_historical
    ]


def test_a_controller_that_leaves_the_cell_gets_its_ddeath_one_that_joins_its_dbirth(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    from app.cell.cell_file import Cell, CellController

    sims = {"R1": sim_factory(), "R2": sim_factory(), "R3": sim_factory()}
    # R1 must not die or be reborn by the cell's changes: a roomy death window, so that a loaded
    # machine's stall of the in-process simulator (> 0.2 s) is not read as R1's silence
    node = gateway_factory({"R1": sims["R1"], "R2": sims["R2"]}, death_after=2.0)
    subscriber.kind("DBIRTH", "R2")
    start = subscriber.count()
    r1 = CellController("R1", host="127.0.0.1", port=sims["R1"].port)
    node.set_cell(Cell("smaller", (r1,)))
    subscriber.kind("DDEATH", "R2", start=start)
    start = subscriber.count()
    node.set_cell(Cell("other", (r1, CellController("R3", host="127.0.0.1", port=sims["R3"].port))))
    joined = subscriber.kind("DBIRTH", "R3", start=start)
    # device index 2: R2's aliases (index 1) are never given to another controller
    assert joined.payload.metrics[0].alias == device_alias(2, 0)
    assert not [
        m for m in subscriber.snapshot()[start:] if m.device == "R1" and m.kind in ("DDEATH", "DBIRTH")
    ]

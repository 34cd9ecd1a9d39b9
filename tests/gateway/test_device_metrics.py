"""The metrics issue 23 asks for beyond the pose and the state: the external axes E1..E5 where the
robot has them, the program cycle counters, the controller's clock -- in the births and in DDATA,
read by an independent subscriber against a real Mosquitto and simulators."""

from __future__ import annotations

from typing import Any

from app.connection import ConnectionSettings
from app.gateway import payload as pb
from app.gateway.metrics import DEVICE_METRICS, EXTERNAL_METRICS, METRIC_INDEX, device_alias
from app.link.client import RobotClient
from app.protocol.enums import ProgramMotionMode

from .conftest import Received, Subscriber


def _value(message: Received, alias: int) -> Any:
    found = [m for m in message.payload.metrics if m.alias == alias]
    return None if not found else pb.metric_value(found[-1])


def test_external_axes_where_present_in_the_births_and_data(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sims = {"R1": sim_factory(), "R2": sim_factory()}
    sims["R2"].set_joint(8, 42.5)  # E2 = J8
    gateway_factory(sims, options={"R2": {"external_axes": 2}})
    plain = subscriber.kind("DBIRTH", "R1")
    assert not [m.name for m in plain.payload.metrics if m.name.startswith("External/")]
    birth = subscriber.kind("DBIRTH", "R2")
    names = [m.name for m in birth.payload.metrics]
    assert names == [s.name for s in DEVICE_METRICS] + ["External/E1", "External/E2"]
    e2 = birth.metric("External/E2")
    assert e2.datatype == EXTERNAL_METRICS[1].datatype
    assert abs(pb.metric_value(e2) - 42.5) < 1e-3  # type: ignore[operator]
    assert e2.alias == device_alias(1, METRIC_INDEX["External/E2"])
    start = subscriber.count()
    sims["R2"].set_joint(7, -120.25)  # E1 moves: a DDATA by alias
    e1 = device_alias(1, METRIC_INDEX["External/E1"])
    data = subscriber.wait_for(
        "E1 in a DDATA", lambda m: m.kind == "DDATA" and _value(m, e1) is not None, start=start
    )
    assert data.device == "R2" and abs(_value(data, e1) + 120.25) < 1e-3


def test_program_cycles_are_counted_from_the_program_state(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim})
    birth = subscriber.kind("DBIRTH", "R1")
    for name in ("Program/Cycles started", "Program/Cycles finished", "Program/Cycles stopped"):
        metric = birth.metric(name)
        assert metric.datatype == pb.DataType.UINT64 and pb.metric_value(metric) == 0
    assert pb.metric_value(birth.metric("Controller/Clock"))  # the controller's clock, as it reads
    alias = {
        word: device_alias(0, METRIC_INDEX[f"Program/Cycles {word}"])
        for word in ("started", "finished", "stopped")
    }
    state = device_alias(0, METRIC_INDEX["Status/Program state"])

    def seen(what: str, a: int, value: int) -> None:
        subscriber.wait_for(
            what, lambda m: m.kind == "DDATA" and _value(m, a) == value, start=start, timeout=20.0
        )

    start = subscriber.count()
    other = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, poll_timeout=2.0))
    other.connect()
    try:
        other.run_program(2, ProgramMotionMode.SINGLE_RUN, 1, 100)  # a run that ends by itself
        seen("a started cycle", alias["started"], 1)
        seen("a finished cycle", alias["finished"], 1)
        start = subscriber.count()
        other.run_program(3, ProgramMotionMode.SINGLE_RUN, 1, 5)
        seen("a second started cycle", alias["started"], 2)
        other.pause()
        seen("the program paused", state, 2)
        other.stop()  # stopped from paused: a stopped cycle
        seen("a stopped cycle", alias["stopped"], 1)
    finally:
        other.close()
    assert not [m for m in subscriber.snapshot()[start:] if _value(m, alias["finished"]) is not None]

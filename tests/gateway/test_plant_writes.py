"""Writes from the plant (DCMD), against a real Mosquitto and real simulators: off unless the cell
file enables them per robot, each through the write guard, the plant role, the envelope and the
audit trail, refused while a pendant commands the robot. What is written is read AT THE SIMULATOR
(its write log); what the plant is told is read by an independent subscriber (the DDATA)."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.gateway import payload as pb
from app.gateway.metrics import (
    COMMAND_METRICS,
    DEVICE_METRICS,
    METRIC_INDEX,
    PLANT_RESULT,
    device_alias,
)
from app.link.client import RobotClient
from app.protocol import registers
from app.protocol.enums import ProgramMotionMode, TeachFrame
from app.safety.audit_read import AuditRecord, read_records
from app.safety.envelope import Envelope

from .conftest import Received, Subscriber

ALL_WRITES = {"plant_writes": ["program/run", "program/stop", "speed_ratio"]}
RESULT = device_alias(0, METRIC_INDEX[PLANT_RESULT])


def _dcmd(subscriber: Subscriber, device: str, name: str, value: Any, *, by_alias: int | None = None) -> None:
    """A host application's DCMD: one metric, by name (or only by its alias, as hosts may)."""
    spec = next(s for s in (*DEVICE_METRICS, *COMMAND_METRICS) if s.name == name)
    command = pb.Payload(timestamp=int(time.time() * 1000))
    metric = (
        command.metrics.add(alias=by_alias, datatype=spec.datatype)
        if by_alias is not None
        else command.metrics.add(name=name, datatype=spec.datatype)
    )
    pb.set_value(metric, spec.datatype, value)
    subscriber.publish(f"spBv1.0/plant/DCMD/pad1/{device}", pb.encode(command))


def _said(message: Received, alias: int = RESULT) -> str | None:
    found = [m for m in message.payload.metrics if m.alias == alias]
    return None if not found else str(pb.metric_value(found[-1]))


def _result(subscriber: Subscriber, device: str, start: int, *words: str, timeout: float = 10.0) -> str:
    """The first Plant/Last command result of ``device`` from message ``start`` on that says ``words``."""

    def says(m: Received) -> bool:
        text = _said(m) if m.kind == "DDATA" and m.device == device else None
        return text is not None and all(w in text for w in words)

    found = subscriber.wait_for(f"a command result saying {words}", says, timeout, start)
    text = _said(found)
    assert text is not None
    return text


def _audit(tmp_path: Path) -> list[AuditRecord]:
    return list(read_records(tmp_path / "audit"))


def _writes_from(sim: Any, since: int) -> list[tuple[int, int, tuple[int, ...]]]:
    return [(w.function_code, w.address, tuple(w.values)) for w in sim.writes[since:]]


def test_a_dcmd_not_enabled_is_refused_said_audited_and_nothing_is_written(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim})  # no plant_writes: the plant only watches
    birth = subscriber.kind("DBIRTH", "R1")
    names = [m.name for m in birth.payload.metrics]
    assert not [n for n in names if n in {s.name for s in COMMAND_METRICS}], "a writable metric advertised"
    assert pb.metric_value(birth.metric(PLANT_RESULT)) == ""
    start = subscriber.count()
    _dcmd(subscriber, "R1", "Plant/Program run", 2)
    text = _result(subscriber, "R1", start, "refused")
    assert text.startswith("#1 program/run 2 refused: program/run is not enabled for this robot"), text
    # a metric that is not writable at all, by name: refused the same way
    _dcmd(subscriber, "R1", "Pose/X", 1.0)
    assert "Pose/X is not a write the plant may make" in _result(subscriber, "R1", start, "#2")
    assert sim.writes == []  # nothing reached the controller
    refused = [r for r in _audit(tmp_path) if r.kind == "refused"]
    assert [(r.command, r.role) for r in refused] == [
        ("plant program/run", "plant (R1)"),
        ("plant Pose/X", "plant (R1)"),
    ]


def test_enabled_writes_send_exactly_their_registers_audited_and_the_run_is_followed_to_its_end(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim}, options={"R1": ALL_WRITES})
    birth = subscriber.kind("DBIRTH", "R1")
    advertised = {m.name: m for m in birth.payload.metrics}
    for spec in COMMAND_METRICS:  # the DBIRTH advertises the writable metrics, name and alias
        assert advertised[spec.name].datatype == spec.datatype
        assert advertised[spec.name].alias == device_alias(0, METRIC_INDEX[spec.name])
    start = subscriber.count()
    _dcmd(subscriber, "R1", "Plant/Speed ratio", 90)
    assert _result(subscriber, "R1", start, "#1 speed_ratio 90: done")
    assert _writes_from(sim, 0) == [(0x06, registers.REG_PROGRAM_SPEED, (90,))]
    before = len(sim.writes)
    start = subscriber.count()
    run_alias = device_alias(0, METRIC_INDEX["Plant/Program run"])
    _dcmd(subscriber, "R1", "Plant/Program run", 2, by_alias=run_alias)  # by alias, as hosts may
    assert "run program 2 at 90 %" in _result(subscriber, "R1", start, "#2 program/run 2: sent")
    cycles_started = device_alias(0, METRIC_INDEX["Program/Cycles started"])
    subscriber.wait_for(
        "the cycle counter at 1",
        lambda m: m.kind == "DDATA" and _said(m, cycles_started) == "1",
        start=start,
    )
    done = _result(subscriber, "R1", start, "#2 program/run 2: ", "done", timeout=20.0)
    # 446..449 in one 0x10 (program 2, single run, 1 cycle, ratio 90), then 440 <- 0x01
    assert _writes_from(sim, before) == [
        (0x10, registers.REG_PROGRAM_ID, (2, int(ProgramMotionMode.SINGLE_RUN), 1, 90)),
        (0x06, registers.REG_RUN_COMMAND, (1,)),
    ], done
    finished = device_alias(0, METRIC_INDEX["Program/Cycles finished"])
    subscriber.wait_for(
        "a finished cycle", lambda m: m.kind == "DDATA" and _said(m, finished) == "1", start=start
    )
    writes = [r for r in _audit(tmp_path) if r.kind == "write"]
    assert {r.role for r in writes} == {"plant (R1)"}
    assert [r.args.get("address") for r in writes] == [
        registers.REG_PROGRAM_SPEED,
        registers.REG_PROGRAM_ID,
        registers.REG_RUN_COMMAND,
    ]
    assert writes[-1].result == "done"  # the run's outcome, judged and recorded against its write


def test_a_plant_stop_stops_the_plants_run(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim}, options={"R1": ALL_WRITES})
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    _dcmd(subscriber, "R1", "Plant/Speed ratio", 10)  # slow: the run is under way when the stop comes
    _dcmd(subscriber, "R1", "Plant/Program run", 3)
    _result(subscriber, "R1", start, "#2 program/run 3: sent")
    assert sim.wait_for(lambda snap: snap.program_state == 1, timeout=5.0)
    before = len(sim.writes)
    _dcmd(subscriber, "R1", "Plant/Program stop", True)
    _result(subscriber, "R1", start, "#3 program/stop true: ", "done")
    assert _writes_from(sim, before) == [(0x06, registers.REG_STOP, (1,))]
    assert sim.state().program_state == 0


def _pendant(sim: Any) -> RobotClient:
    client = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, poll_timeout=2.0))
    client.connect()
    return client


def test_refused_while_a_pendant_commands_the_robot(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory(watchdog=None)
    node = gateway_factory({"R1": sim}, options={"R1": ALL_WRITES})
    subscriber.kind("DBIRTH", "R1")
    pendant = _pendant(sim)
    try:
        # a pendant's jog session: the controller is in Modbus teach mode
        assert pendant.teach_enable(TeachFrame.JOINT, 0, 1).ok
        assert sim.wait_for(lambda snap: snap.mode == 2, timeout=5.0)
        ours = len(sim.writes)
        start = subscriber.count()
        _dcmd(subscriber, "R1", "Plant/Program run", 2)
        assert "Modbus teach mode" in _result(subscriber, "R1", start, "#1 program/run 2 refused: a pendant")
        _dcmd(subscriber, "R1", "Plant/Program stop", True)  # a stop too: the pendant holds the robot
        _result(subscriber, "R1", start, "#2 program/stop true refused: a pendant")
        assert pendant.teach_disable().ok
        # teach off again, but the pendant commanded the robot a moment ago (its GV291 results)
        assert sim.wait_for(lambda snap: snap.mode == 1, timeout=5.0)
        start = subscriber.count()
        _dcmd(subscriber, "R1", "Plant/Speed ratio", 50)
        _result(subscriber, "R1", start, "#3 speed_ratio 50 refused: another master (a pendant or a PLC)")
        # the pendant's own writes since (teach disable) are in the log too; the plant's would be these
        plant_kind = {registers.REG_PROGRAM_ID, registers.REG_PROGRAM_SPEED, registers.REG_STOP}
        plant = [w for w in _writes_from(sim, ours) if w[1] in plant_kind or w[1:] == (440, (1,))]
        assert plant == [], "the gateway wrote while a pendant commanded the robot"
    finally:
        pendant.close()
    refused = [r.command for r in _audit(tmp_path) if r.kind == "refused"]
    assert refused == ["plant program/run", "plant program/stop", "plant speed_ratio"]
    # this TeachPad's own pendant took control of the robot (the GUI's Take control)
    node.set_pendant_robot("R1")
    start = subscriber.count()
    _dcmd(subscriber, "R1", "Plant/Program run", 2)
    _result(
        subscriber, "R1", start, "#4 program/run 2 refused: a pendant commands R1 (TeachPad's Take control)"
    )


def test_refused_while_another_masters_program_runs(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from app import timing

    monkeypatch.setattr(timing, "GATEWAY_PLANT_PENDANT_WINDOW", 0.0)  # the program state alone
    sim = sim_factory(watchdog=None)
    gateway_factory({"R1": sim}, options={"R1": ALL_WRITES})
    subscriber.kind("DBIRTH", "R1")
    pendant = _pendant(sim)
    try:
        pendant.run_program(3, ProgramMotionMode.SINGLE_RUN, 1, 5)  # slow: it is still under way
        assert sim.wait_for(lambda snap: snap.program_state == 1, timeout=5.0)
        ours = len(sim.writes)
        start = subscriber.count()
        _dcmd(subscriber, "R1", "Plant/Program stop", True)
        _result(subscriber, "R1", start, "#1 program/stop true refused: R1 is moving under another master's")
        assert _writes_from(sim, ours) == []
        assert sim.state().program_state == 1  # the pendant's program runs on
    finally:
        pendant.stop()
        pendant.close()


def test_a_speed_ratio_above_the_envelopes_cap_is_refused(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory()
    envelope = Envelope(max_jog_ratio=50.0)
    gateway_factory({"R1": sim}, options={"R1": ALL_WRITES}, envelope=envelope)
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    _dcmd(subscriber, "R1", "Plant/Speed ratio", 80)
    text = _result(subscriber, "R1", start, "#1 speed_ratio 80 refused")
    assert "above the 50 % the safety envelope allows" in text
    _dcmd(subscriber, "R1", "Plant/Speed ratio", 0)
    assert "a whole number 1..100" in _result(subscriber, "R1", start, "#2 speed_ratio 0 refused")
    assert sim.writes == []
    assert [r.command for r in _audit(tmp_path) if r.kind == "refused"] == ["plant speed_ratio"] * 2


def test_a_controller_that_does_not_answer_refuses_at_once(
    sim_factory: Any, subscriber: Subscriber, gateway_factory: Any, tmp_path: Path
) -> None:
    sim = sim_factory()
    gateway_factory({"R1": sim}, options={"R1": ALL_WRITES})
    subscriber.kind("DBIRTH", "R1")
    start = subscriber.count()
    sim.set_silent(True)
    subscriber.kind("DDEATH", "R1", start=start)
    _dcmd(subscriber, "R1", "Plant/Program run", 2)
    deadline = time.monotonic() + 10.0
    while not [r for r in _audit(tmp_path) if r.kind == "refused"]:
        assert time.monotonic() < deadline, "the refusal was not audited"
        time.sleep(0.02)  # a file another thread writes: nothing to wait on
    sim.set_silent(False)
    # said with the next DBIRTH (a dead device has no DDATA)
    again = subscriber.kind("DBIRTH", "R1", start=start)
    assert pb.metric_value(again.metric(PLANT_RESULT)) == "#1 program/run 2 refused: R1 does not answer"
    assert sim.writes == []

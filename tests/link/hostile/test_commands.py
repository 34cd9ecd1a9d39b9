"""Every command, each misbehaviour aimed at each of its requests: success only when every write
was answered as itself, a clear error (unknown for an unconfirmed motion) otherwise, never a hang.

The relay (tests/link/hostile/relay.py) forwards each request to the simulator and misbehaves on the
one chosen; the judge (tests/link/hostile/commands.py) says what is wrong. Each test runs one command
over every request up to its trigger and the two reads after it (the reads that follow are the
same reads again), with every misbehaviour; silence (a whole request timeout) is aimed at the
first request and the trigger only. A test lists every wrong case at once.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from app import timing
from app.cli.exit_codes import ExitCode, exit_code_for
from app.connection import ConnectionSettings
from app.errors import (
    LinkError,
    MalformedResponse,
    ModbusExceptionError,
    OutcomeUnknown,
    ResponseTimeout,
    TeachPadError,
)
from app.link.client import RobotClient
from app.link.outcome import Outcome, outcome_of
from app.link.types import StepFrame
from app.models import CommandResult
from app.protocol import registers
from app.safety.audit import AuditLog
from app.safety.audit_read import Result, read_records
from tests.link.hostile.commands import (
    COMMANDS,
    MISBEHAVIOURS,
    POSE,
    SLOW,
    TRIGGERS,
    Command,
    exception_answer,
    judge,
    run_case,
)
from tests.link.hostile.relay import HostileRelay
from tests.link.hostile.server import HostileServer, Reply, bank_value

# The client's request timeout: silence waits it out. The simulator answers from this process:
# under load a good answer may come late, which fails a command (allowed), never makes one wrong.
TIMEOUT = 0.4
# Over RTU framing there is no transaction id: a late answer of the same shape, alone, cannot be
# told from the own one (a known limit of RTU, not checked); the exception codes are the same
# words as over TCP
RTU_SKIP = frozenset(
    {
        "transaction id +1",
        "late answer, then the own",
        "exception 0x0B (gateway target)",
        "exception 4 (device failure)",
    }
)
RTU_COMMANDS = ("read_registers", "write_gv", "stop", "go_zero")
# Frame-level faults the single-request tests (test_malformed.py) cover field by field, left to
# the random run (command_fuzz.py) here: the sweep stays under a minute
FRAME_ONLY = frozenset({"exception 0 (no code)", "bytes after it", "answered twice"})


@pytest.fixture(autouse=True)
def _quick(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "SENTINEL_PROBE_SETTLE", 0.01)


@pytest.fixture
def relay(request: pytest.FixtureRequest, sim_factory: Any) -> Iterator[tuple[Any, HostileRelay]]:
    framing = request.param
    sim = sim_factory(gv291="writable", framer="rtu" if framing == "rtu" else "socket")
    with HostileRelay(sim.port, framing) as r:
        yield sim, r


def _indices(command: Command, sim: Any, relay: HostileRelay) -> tuple[list[int], float]:
    """The requests to aim at (up to the trigger and two more) and the command's budget."""
    clean = run_case(sim, relay, command, {}, TIMEOUT)
    assert clean.error is None, f"{command.name} fails without any misbehaviour: {clean.error}"
    assert not judge(command, clean, 60.0, sim)
    writes = [ex.index for ex in clean.exchanges if ex.is_write]
    triggers = [ex.index for ex in clean.exchanges if ex.function == 0x06 and ex.address in TRIGGERS]
    last = max([*writes, *triggers, 0]) + (2 if triggers else 0)
    budget = clean.seconds + TIMEOUT + timing.OUTCOME_READ_BUDGET
    return list(range(min(last + 1, len(clean.exchanges)))), budget


def _sweep(command: Command, sim: Any, relay: HostileRelay, skip: frozenset[str] = frozenset()) -> None:
    indices, budget = _indices(command, sim, relay)
    triggers: set[int] = set()
    wrong: list[str] = []
    cases = 0
    for index in indices:
        for name, misbehaviour in MISBEHAVIOURS.items():
            if name in skip or name in FRAME_ONLY or (name in SLOW and index not in (0, *triggers)):
                continue
            run = run_case(sim, relay, command, {index: (name, misbehaviour)}, TIMEOUT)
            cases += 1
            if not run.delivered:
                continue  # the command ended before (a failure: allowed)
            aimed = run.exchanges[index]
            if aimed.function == 0x06 and aimed.address in TRIGGERS:
                triggers.add(index)
            wrong += [
                f"request #{index} ({aimed.function:#04x} @{aimed.address}), {name}: {w}"
                for w in judge(command, run, budget, sim)
            ]
    assert cases > 0
    assert not wrong, f"{command.name}: {len(wrong)} of {cases} cases wrong:\n" + "\n".join(wrong)


@pytest.mark.parametrize("relay", ["tcp"], indirect=True, ids=["tcp"])
@pytest.mark.parametrize("name", list(COMMANDS))
def test_each_misbehaviour_at_each_request_tcp(name: str, relay: tuple[Any, HostileRelay]) -> None:
    sim, r = relay
    _sweep(COMMANDS[name], sim, r)


@pytest.mark.parametrize("relay", ["rtu"], indirect=True, ids=["rtu"])
@pytest.mark.parametrize("name", RTU_COMMANDS)
def test_each_misbehaviour_at_each_request_rtu(name: str, relay: tuple[Any, HostileRelay]) -> None:
    sim, r = relay
    _sweep(COMMANDS[name], sim, r, RTU_SKIP)


# -- the paths the sweep found, one by one ------------------------------------------------------


OPEN_EXCEPTIONS = [
    "exception 4 (device failure)",
    "exception 5 (acknowledge)",
    "exception 0x0B (gateway target)",
    "exception 0x37 (unknown code)",
]
UNCONFIRMED = [*OPEN_EXCEPTIONS, "hang-up, no answer", "function code", "half an answer, hang-up", "silence"]


@pytest.mark.parametrize("relay", ["tcp"], indirect=True, ids=["tcp"])
@pytest.mark.parametrize("name", UNCONFIRMED)
def test_a_trigger_that_went_out_unconfirmed_is_unknown_in_the_audit(
    name: str, relay: tuple[Any, HostileRelay], tmp_path: Path
) -> None:
    """440 <- step went out and its answer was not its confirmation: the arm moves (the simulator
    took it). An exception that does not say "not carried out" ends the step *unknown*
    (OutcomeUnknown, exit 4; before: "refused"); a link failure stays a link error (its reason
    reads unknown in app/link/outcome.py's table); either way its write reads *unknown* in the
    audit trail (before: "failed")."""
    sim, r = relay
    clean = run_case(sim, r, COMMANDS["step"], {}, TIMEOUT)
    trigger = next(ex.index for ex in clean.exchanges if ex.address == registers.REG_RUN_COMMAND)
    sim.restart_controller()
    before = sim.state().pose
    r.arm({trigger: (name, MISBEHAVIOURS[name])})
    audit = AuditLog(tmp_path)
    client = RobotClient(ConnectionSettings(port=r.port, timeout=TIMEOUT))
    client.audit = audit
    with client, pytest.raises(TeachPadError) as info:
        client.step(StepFrame.BASE, [1.0, 0, 0, 0, 0, 0], speed=200.0)
    assert r.delivered
    if name in OPEN_EXCEPTIONS:
        assert isinstance(info.value, OutcomeUnknown)
        assert str(info.value) == (
            "incremental move (base): sent; the outcome is unknown \u2014 check the robot before sending "
            f"it again (the controller answered Modbus exception {int(name.split()[1], 0)} "
            f"{name.split(' ', 2)[2]}, which does not say it was not carried out)"
        ).replace("(unknown code)", "(a code the standard does not define)").replace(
            "(gateway target)", "(gateway target device failed to respond)"
        ).replace("(device failure)", "(server device failure)")
        assert exit_code_for(info.value) is ExitCode.UNKNOWN
    else:
        assert isinstance(info.value, LinkError | MalformedResponse | ResponseTimeout)
    reason = CommandResult(None, None, None, False, str(info.value), reason=info.value.as_reason())
    assert outcome_of(reason) is Outcome.UNKNOWN
    assert sim.wait_for(lambda s: abs(s.pose[0] - before[0] - 1.0) < 1e-3 and not s.moving, 5.0)
    audit.close()
    commands = [rec for rec in read_records(tmp_path) if rec.kind == "write" and rec.args.get("judged")]
    assert [rec.result for rec in commands] == [Result.UNKNOWN]


@pytest.mark.parametrize("relay", ["tcp"], indirect=True, ids=["tcp"])
@pytest.mark.parametrize("code", [4, 5, 6, 0x0B, 0x37])
def test_the_completion_probe_takes_only_a_refusal_for_read_only(
    code: int, relay: tuple[Any, HostileRelay]
) -> None:
    """The GV291 probe's write answered busy, device failure, acknowledge...: not "GV291 is
    read-only" (before: the command went on under the observe rule and succeeded): the command
    fails before its trigger, and the next command probes again."""
    sim, r = relay
    gv291 = registers.gv_reg(registers.GV_COMMAND_STATUS)
    clean = run_case(sim, r, COMMANDS["create_point"], {}, TIMEOUT)
    probe = next(ex.index for ex in clean.exchanges if ex.address == gv291)
    sim.restart_controller()
    triggers = len(sim.writes_to(registers.REG_RUN_COMMAND))
    r.arm({probe: (f"exception {code}", exception_answer(code))})
    with RobotClient(ConnectionSettings(port=r.port, timeout=TIMEOUT)) as client:
        with pytest.raises(ModbusExceptionError) as info:
            client.create_point(7, pose=POSE)
        assert info.value.exception_code == code
        assert client.completion_rule is None  # not decided: probed again next time
        assert len(sim.writes_to(registers.REG_RUN_COMMAND)) == triggers
        assert client.create_point(7, pose=POSE).ok
        assert client.completion_rule == "sentinel"


def test_a_late_answer_to_an_earlier_request_is_dropped_not_taken() -> None:
    """Modbus TCP: an answer carrying the transaction id of an earlier request of the connection
    (a duplicate, a slow gateway's) arrives before the request's own: dropped whole, counted, and
    the own answer is read after it (before: a malformed answer, the link dropped); alone, it is
    silence, never taken. Over RTU there is no transaction id to tell them apart."""
    with HostileServer("tcp") as server:
        client = RobotClient(ConnectionSettings(port=server.port, timeout=TIMEOUT))
        with client:
            assert client.read_registers(100, 4) == [bank_value(a) for a in range(100, 104)]
            assert server.last is not None
            late = server.last[0]  # the answer to transaction 1
            server.push(lambda a: Reply(late + a.correct))
            assert client.read_registers(560, 24) == [bank_value(a) for a in range(560, 584)]
            stats = client.stats
            assert (stats.answers, stats.malformed, stats.timeouts, stats.resyncs) == (2, 0, 0, 1)
            assert stats.last_error == "dropped a late answer to an earlier request (transaction id 1)"
            server.push(lambda a: Reply(late))
            with pytest.raises(ResponseTimeout):
                client.read_registers(100, 4)
            assert (client.stats.answers, client.stats.malformed) == (2, 0)

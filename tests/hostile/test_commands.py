"""Every command, each misbehaviour aimed at each of its requests: success only when every write
was answered as itself, a clear error (unknown for an unconfirmed motion) otherwise, never a hang.

The relay (tests/hostile/relay.py) forwards each request to the simulator and misbehaves on the
one chosen; the judge (tests/hostile/commands.py) says what is wrong. Each test runs one command
over every request up to its trigger and the two reads after it (the reads that follow are the
same reads again), with every misbehaviour; silence (a whole request timeout) is aimed at the
first request and the trigger only. A test lists every wrong case at once.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from app import timing
from tests.hostile.commands import COMMANDS, MISBEHAVIOURS, SLOW, TRIGGERS, Command, judge, run_case
from tests.hostile.relay import HostileRelay

# The client's request timeout: silence waits it out. The simulator answers from this process:
# under load a good answer may come late, which fails a command (allowed), never makes one wrong.
TIMEOUT = 0.4
# Over RTU framing there is no transaction id; the exception codes are the same words as over TCP
RTU_SKIP = frozenset({"transaction id +1", "exception 0x0B (gateway target)", "exception 4 (device failure)"})
RTU_COMMANDS = ("read_registers", "write_gv", "stop", "step", "go_zero")


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
            if name in skip or (name in SLOW and index not in (0, *triggers)):
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

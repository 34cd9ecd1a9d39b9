"""A long random run of every command against the hostile relay: false successes, wrong
outcomes and hangs counted (a report, not a test).

``python -m tests.link.hostile.command_fuzz [calls] [seed] [tcp|rtu]`` prints one JSON line.

Each call picks a command (tests/link/hostile/commands.py :data:`COMMANDS`), aims one to three
misbehaviours (:data:`MISBEHAVIOURS`, silence and "stale answer only" less often: each costs a
request timeout) at random requests among its first ones, runs it on a fresh client and judges it
(:func:`judge`): ``false_successes`` (a success although a write got no answer of its own, a
misbehaving answer taken as one, or a read that returned other values than the simulator's),
``wrong_outcomes`` (an unconfirmed motion said refused, a refused one said unknown, an error
without words), ``hangs`` (past twice the command's budget). All three must be 0.
"""

from __future__ import annotations

import json
import random
import sys
import time
from collections import Counter
from typing import Any

from app import timing
from app.sim.config import SimConfig
from app.sim.server import SimController
from tests.link.hostile.commands import COMMANDS, MISBEHAVIOURS, SLOW, judge, run_case
from tests.link.hostile.relay import HostileRelay
from tests.link.hostile.server import Framing

TIMEOUT = 0.3  # s, the client's request timeout
FAST = [name for name in MISBEHAVIOURS if name not in SLOW]


def _kind(problem: str) -> str:
    if problem.startswith("took "):
        return "hangs"
    if problem.startswith(("success although", "read ", "GV60")) or "answers taken" in problem:
        return "false_successes"
    return "wrong_outcomes"


def run(calls: int, seed: int, framing: Framing = "tcp") -> dict[str, Any]:
    rng = random.Random(seed)
    timing.SENTINEL_PROBE_SETTLE = 0.01
    timing.FOREIGN_MOVE_HOLD = 0.0
    figures: Counter[str] = Counter()
    examples: list[str] = []
    sim = SimController(
        SimConfig(host="127.0.0.1", port=0, gv291="writable", framer="rtu" if framing == "rtu" else "socket")
    )
    sim.start()
    t0 = time.monotonic()
    try:
        with HostileRelay(sim.port, framing) as relay:
            lengths, budgets = {}, {}
            for name, command in COMMANDS.items():
                clean = run_case(sim, relay, command, {}, TIMEOUT)
                lengths[name] = len(clean.exchanges)
                budgets[name] = clean.seconds + TIMEOUT + timing.OUTCOME_READ_BUDGET
            names = list(COMMANDS)
            for _ in range(calls):
                name = rng.choice(names)
                command = COMMANDS[name]
                aims = {}
                for _ in range(rng.randint(1, 3)):
                    index = rng.randrange(min(lengths[name] + 2, 24))
                    what = rng.choice(list(MISBEHAVIOURS)) if rng.random() < 0.05 else rng.choice(FAST)
                    aims[index] = (what, MISBEHAVIOURS[what])
                result = run_case(sim, relay, command, aims, TIMEOUT)
                figures["calls"] += 1
                figures["misbehaviours_met"] += sum(1 for ex in result.exchanges if ex.aimed)
                figures["succeeded"] += result.error is None
                kinds = {_kind(p) for p in judge(command, result, budgets[name], sim)}
                for kind in kinds:
                    figures[kind] += 1
                if kinds and len(examples) < 20:
                    aimed = ", ".join(f"#{ex.index} {ex.aimed}" for ex in result.exchanges if ex.aimed)
                    examples.append(f"{name} [{aimed}]: {sorted(kinds)} {result.error!r:.160}")
    finally:
        sim.stop()
    return {
        "framing": framing,
        "seed": seed,
        "calls": figures["calls"],
        "misbehaviours_met": figures["misbehaviours_met"],
        "succeeded": figures["succeeded"],
        "false_successes": figures["false_successes"],
        "wrong_outcomes": figures["wrong_outcomes"],
        "hangs": figures["hangs"],
        "seconds": round(time.monotonic() - t0, 1),
        "examples": examples,
    }


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    seed_ = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    framing_: Framing = "rtu" if len(sys.argv) > 3 and sys.argv[3] == "rtu" else "tcp"
    print(json.dumps(run(n, seed_, framing_)))

"""Many simulated controllers in one process: a cell for the gateway, the cell view and the benchmarks.

:class:`SimFleet` starts ``count`` :class:`~app.sim.server.SimController`, each on its own loopback
port (``port`` 0: free ports; otherwise ``port``, ``port + 1``, ...), each with its own arm (the
joints of the home pose turned by a few degrees per controller) and, with ``programs=True``, its own
built-in program running endlessly (programs 1, 2, 3 in turn at their own speed ratio), so every
controller's pose moves and no two move alike. :meth:`SimFleet.stop` stops them together.

One process serves them all: one asyncio loop per controller's server and one ticker thread each,
all under one interpreter lock. ``benchmarks.gateway`` measures what that costs against one process
per controller (CPU per controller, answer latency): a single process is fine for a handful of
controllers; for dozens at 10 Hz spread them over a few processes (``teachpad-sim --controllers N``
several times).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Sequence

from app.protocol.enums import ProgramMotionMode
from app.sim.config import SimConfig
from app.sim.robot import PROGRAMS
from app.sim.server import SimController

__all__ = ["SimFleet"]

J1_STEP = 7.0  # deg: controller i's arm starts with J1 turned by i x this (mod 90)
J4_STEP = 11.0  # deg: and J4 by i x this (mod 60)


class SimFleet:
    """``count`` simulators from one base configuration; started by :meth:`start`, stopped together."""

    def __init__(self, count: int, base: SimConfig | None = None, *, programs: bool = False) -> None:
        if not 1 <= count <= 1000:
            raise ValueError(f"the number of controllers must be 1..1000, got {count}")
        base = base or SimConfig(host="127.0.0.1", port=0)
        self.programs = programs
        self.controllers: tuple[SimController, ...] = tuple(
            SimController(
                dataclasses.replace(base, port=0 if base.port == 0 else base.port + i, seed=base.seed + i)
            )
            for i in range(count)
        )

    def __len__(self) -> int:
        return len(self.controllers)

    def __iter__(self) -> Iterator[SimController]:
        return iter(self.controllers)

    def __getitem__(self, index: int) -> SimController:
        return self.controllers[index]

    @property
    def ports(self) -> Sequence[int]:
        return [sim.port for sim in self.controllers]

    def start(self) -> None:
        """Bind every controller (all or none: one that cannot bind stops the ones started, OSError)."""
        started: list[SimController] = []
        try:
            for index, sim in enumerate(self.controllers):
                sim.start()
                started.append(sim)
                self._make_distinct(index, sim)
        except BaseException:
            for sim in started:
                sim.stop()
            raise

    def _make_distinct(self, index: int, sim: SimController) -> None:
        with sim.lock:
            joints = sim.robot.joints.copy()
            joints[0] += (index * J1_STEP) % 90.0
            joints[3] += (index * J4_STEP) % 60.0
            sim.robot.set_joints(joints)
            if self.programs:
                program = sorted(PROGRAMS)[index % len(PROGRAMS)]
                sim.robot.run_program(program, ProgramMotionMode.CYCLE, 0, 40 + (index * 13) % 60)

    def stop(self) -> None:
        for sim in self.controllers:
            sim.stop()

    def __enter__(self) -> SimFleet:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

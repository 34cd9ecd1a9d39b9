"""The simulated Bochuang controller: kinematics, motion, state machine, Modbus server.

``SimController(SimConfig(...))`` is the Modbus TCP slave (``start``/``stop``/``port``,
inspection and fault injection, see :mod:`app.sim.server`); ``SimRobot`` is the pure state
machine it drives (:mod:`app.sim.robot`); :mod:`app.sim.kinematics` holds the DH model;
``teachpad-sim`` is :func:`app.sim.cli.main`.
"""

from app.sim.robot import PROGRAMS, SimRobot, StoredPoint, TraceSample
from app.sim.server import SimConfig, SimController, SimSnapshot, WriteRecord

__all__ = ["PROGRAMS", "SimConfig", "SimController", "SimRobot", "SimSnapshot", "StoredPoint", "TraceSample",
           "WriteRecord"]

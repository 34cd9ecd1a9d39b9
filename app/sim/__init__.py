"""The simulated Bochuang controller: kinematics, motion, state machine, Modbus server.

``SimController(SimConfig(...))`` is the Modbus TCP slave, or RTU on a serial line
(``start``/``stop``/``port``, inspection and fault injection, see :mod:`app.sim.server`; bad
input and the communication watchdog in :mod:`app.sim.guard` and :mod:`app.sim.transport`);
``SimRobot`` is the pure state machine it drives (:mod:`app.sim.robot`, its commands in
:mod:`app.sim.commands`, its motion segments in :mod:`app.sim.motion`);
:mod:`app.sim.kinematics` holds the DH model; ``teachpad-sim`` is :func:`app.sim.cli.main`.
"""

"""Two TeachPads on one controller (issue 19 section 2): false restarts in a long run.

Two :class:`~app.link.robot_link.RobotLink` (restart canary on, GV99) poll one simulator for
SECONDS; with ``--fighter`` a third host writes its own canary token every second (the old rule,
which rewrote its token whenever it saw another). Prints the false restarts each link reported
(the done-when asks 0 in 10 minutes) and the signs of another master each one saw.

    .venv/bin/python -m benchmarks.two_teachpads 600 --fighter
"""

from __future__ import annotations

import argparse
import random
import time

from PySide6.QtCore import QCoreApplication, QTimer

from app import timing
from app.connection import ConnectionSettings
from app.link.client import RobotClient
from app.link.robot_link import RobotLink
from app.protocol.registers import CANARY_GV
from app.sim.config import SimConfig
from app.sim.server import SimController


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("seconds", type=float, nargs="?", default=600.0)
    parser.add_argument("--fighter", action="store_true", help="a third host rewrites its token every second")
    args = parser.parse_args()
    app = QCoreApplication([])
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    restarts = [0, 0]
    foreign = [0, 0]
    links: list[RobotLink] = []
    for i in range(2):
        link = RobotLink(poll_hz=timing.POLL_HZ_DEFAULT)
        link.controllerRestarted.connect(lambda i=i: restarts.__setitem__(i, restarts[i] + 1))
        link.foreignMaster.connect(lambda _what, _value, i=i: foreign.__setitem__(i, foreign[i] + 1))
        link.connect_to(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=1.0, poll_timeout=1.0))
        links.append(link)
    fighter = RobotClient(ConnectionSettings(host="127.0.0.1", port=sim.port, timeout=2.0))
    fighter.connect()
    writes = [0]

    def fight() -> None:
        fighter.write_gv(CANARY_GV, [float(random.randint(1, 1 << 23))])
        writes[0] += 1

    timer = QTimer()
    timer.timeout.connect(fight)
    if args.fighter:
        timer.start(1000)
    start = time.monotonic()
    QTimer.singleShot(round(args.seconds * 1000), app.quit)
    app.exec()
    timer.stop()
    print(
        f"{time.monotonic() - start:.0f} s: false restarts {restarts}, signs of another master {foreign}, "
        f"third host's token writes {writes[0]}",
        flush=True,
    )
    fighter.close()
    for link in links:
        link.shutdown()
    sim.stop()


if __name__ == "__main__":
    main()

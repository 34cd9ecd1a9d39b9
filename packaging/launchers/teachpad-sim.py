"""The bundle's ``teachpad-sim``: the same ``main`` as the console script of the wheel."""

import sys

from app.sim.cli import main

sys.exit(main())

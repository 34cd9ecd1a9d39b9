"""The bundle's ``teachpad-gateway``: the same ``main`` as the console script of the wheel."""

import sys

from app.gateway.cli import main

sys.exit(main())

"""The bundle's ``teachpad-cli``: the same ``main`` as the console script of the wheel."""

import sys

from app.cli.entry import main

sys.exit(main())

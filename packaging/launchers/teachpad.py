"""The bundle's ``teachpad`` (the GUI): the same ``main`` as the console script of the wheel."""

import sys

from ui.main import main

sys.exit(main())

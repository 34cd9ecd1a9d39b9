"""``python -m app.gateway``: the same as the ``teachpad-gateway`` console script."""

import sys

from app.gateway.cli import main

if __name__ == "__main__":
    sys.exit(main())

"""The ``teachpad-cli`` console script: a Ctrl-C while the CLI is still being imported ends it as
Ctrl-C does later (one line on stderr, exit code 130), not with a Python traceback.

Importing :mod:`app.cli.main` loads the protocol, link and point modules (and numpy) — a few hundred
milliseconds in which Ctrl-C would otherwise print a traceback. Nothing has been sent to the
controller by then, so there is nothing to stop. This module imports nothing heavy itself.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

PROG = "teachpad-cli"
INTERRUPTED = 130  # app.cli.exit_codes.ExitCode.INTERRUPTED (not imported: it is the heavy part)


def _load() -> Callable[[], int]:
    from app.cli.main import main as cli_main

    return cli_main


def main(load: Callable[[], Callable[[], int]] = _load) -> int:
    try:
        cli_main = load()
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted (before any request was sent)", file=sys.stderr, flush=True)
        return INTERRUPTED
    return cli_main()

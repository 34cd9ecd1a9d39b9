"""TeachPad's version: the installed distribution's (pyproject.toml's ``version``), the same in
the venv and in the bundle (packaging/teachpad.spec copies the distribution's metadata).

``--version`` of ``teachpad``, ``teachpad-cli`` and ``teachpad-sim`` (:class:`VersionAction`)
looks it up only when asked: importing importlib.metadata is not paid by every start.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any, Final

DISTRIBUTION: Final = "teachpad"
UNKNOWN: Final = "unknown (not installed)"


def version() -> str:
    """The installed version, or :data:`UNKNOWN` when run from a source tree not installed."""
    from importlib import metadata

    try:
        return metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return UNKNOWN


class VersionAction(argparse.Action):
    """``--version``: print ``PROG VERSION`` and exit 0 (argparse's own needs the text up front)."""

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS, **_kwargs: Any) -> None:
        super().__init__(
            option_strings=option_strings,
            dest=dest,
            default=argparse.SUPPRESS,
            nargs=0,
            help="print the version and exit",
        )

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        print(f"{parser.prog} {version()}", flush=True)  # on stdout, as argparse's own
        parser.exit()

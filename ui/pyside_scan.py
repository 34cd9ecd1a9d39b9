"""PySide6's source scan of every imported module, skipped for TeachPad's own modules.

Once ``PySide6.QtCore`` is imported, shiboken replaces ``builtins.__import__``: after each module
imported from then on it reads the module's whole source (``inspect.getsource``) to see whether
it says "PySide6", and notes the answer in a dict (module name -> 0 "uses PySide, no feature",
-1 "ignore") for its opt-in ``from __feature__ import snake_case`` syntax (PYSIDE-2029; napari
issue 8584 calls it "the __feature__ startup tax"). A name already in the dict is not read.

TeachPad never selects a feature, so 0 and -1 mean the same to it: :func:`skip_source_scan`
enters every module of ``app`` and ``ui`` as 0 before they are imported. Measured on the 2-core
machine: importing the window's ~140 modules after Qt took ~170 ms, of which ~25 ms was this
scan. The dict is PySide's internal (``shibokensupport.feature.pyside_feature_dict``, 6.11): when
it is not there, nothing is entered and nothing else changes (start-up is that much slower).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path

__all__ = ["OWN_PACKAGES", "own_module_names", "skip_source_scan"]

#: The packages whose modules are entered (their folders beside this one)
OWN_PACKAGES = ("app", "ui")

_FEATURE_MODULE = "shibokensupport.feature"


def own_module_names(root: Path | None = None) -> Iterator[str]:
    """Every module and package name under :data:`OWN_PACKAGES` in ``root`` (default: the folder
    that holds ``ui``), from the ``.py`` files there (none in a bundle, which has no sources)."""
    base = Path(__file__).resolve().parent.parent if root is None else root
    for package in OWN_PACKAGES:
        for folder, dirs, files in os.walk(base / package):
            dirs[:] = [d for d in dirs if d.isidentifier() and d != "__pycache__"]  # packages only
            parts = Path(folder).relative_to(base).parts
            for name in files:
                if not name.endswith(".py"):
                    continue
                stem = name[:-3]
                yield ".".join(parts if stem == "__init__" else (*parts, stem))


def skip_source_scan() -> int:
    """Enter TeachPad's own modules in PySide's feature dict (see the module docstring); returns
    how many were entered (0 when PySide is not imported yet or keeps no such dict)."""
    feature = sys.modules.get(_FEATURE_MODULE)
    table = getattr(feature, "pyside_feature_dict", None)
    if not isinstance(table, dict):
        return 0
    entered = 0
    for name in own_module_names():
        if name not in table:
            table[name] = 0
            entered += 1
    return entered

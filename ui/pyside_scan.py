"""PySide6's source scan of every imported module, skipped for TeachPad's own modules.

Once ``PySide6.QtCore`` is imported, shiboken replaces ``builtins.__import__``: after each module
imported from then on it reads the module's whole source (``inspect.getsource``) to see whether
it says "PySide6", and notes the answer in a dict (module name -> 0 "uses PySide, no feature",
-1 "ignore") for its opt-in ``from __feature__ import snake_case`` syntax (PYSIDE-2029; napari
issue 8584 calls it "the __feature__ startup tax"). A name already in the dict is not read.

TeachPad never selects a feature, so 0 and -1 mean the same to it: :func:`skip_source_scan`
enters every module of ``app`` and ``ui`` as 0 before they are imported, and every top-level module
of Python's standard library (``sys.stdlib_module_names``) as -1, the answer its scan gives (no
standard module says "PySide6"). Measured on the 2-core machine: importing the window's ~140
modules after Qt took ~170 ms, of which ~25 ms was reading our sources and ~12 ms reading the ~55
standard modules the window imports after Qt (``typing``, ``inspect``, ``argparse``, ...; their
submodules, such as ``json.decoder``, are still read: ~0.5 ms). The dict is PySide's internal
(``shibokensupport.feature.pyside_feature_dict``, 6.11): when it is not there, nothing is entered
and nothing else changes (start-up is that much slower).

This module imports only ``sys`` at its top (no ``from __future__``, no ``typing``: those, too,
are modules PySide would read before the standard library is entered) and ``os`` when it lists
TeachPad's own modules, after.
"""

import sys

__all__ = ["IGNORED", "OWN_PACKAGES", "USES_PYSIDE", "own_module_names", "skip_source_scan"]

#: The packages whose modules are entered (their folders beside this one)
OWN_PACKAGES = ("app", "ui")

_FEATURE_MODULE = "shibokensupport.feature"


def own_module_names(root: str | None = None) -> list[str]:
    """Every module and package name under :data:`OWN_PACKAGES` in ``root`` (default: the folder
    that holds ``ui``), from the ``.py`` files there (none in a bundle, which has no sources)."""
    import os

    base = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) if root is None else root
    names = []
    for package in OWN_PACKAGES:
        for folder, dirs, files in os.walk(os.path.join(base, package)):
            dirs[:] = [d for d in dirs if d.isidentifier() and d != "__pycache__"]  # packages only
            parts = os.path.relpath(folder, base).split(os.sep)
            for name in files:
                if name.endswith(".py"):
                    stem = name[:-3]
                    names.append(".".join(parts if stem == "__init__" else [*parts, stem]))
    return names


#: PySide's values: a module that uses PySide (no feature selected), a module it ignores
USES_PYSIDE, IGNORED = 0, -1


def skip_source_scan() -> int:
    """Enter TeachPad's own modules and the standard library's in PySide's feature dict (see the
    module docstring); returns how many were entered (0 when PySide is not imported yet or keeps
    no such dict). A name already there keeps its value."""
    feature = sys.modules.get(_FEATURE_MODULE)
    table = getattr(feature, "pyside_feature_dict", None)
    if not isinstance(table, dict):
        return 0
    before = len(table)
    for name in sys.stdlib_module_names:  # first: the next loop imports os
        table.setdefault(name, IGNORED)
    for name in own_module_names():
        table.setdefault(name, USES_PYSIDE)
    return len(table) - before

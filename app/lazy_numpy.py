"""numpy, imported by its first use instead of by the module that names it.

Importing numpy takes 0.1–0.3 s, and the modules that compute with it (the plan's geometry and
checks, the safety envelope, the robot model, the plots' ring buffers) are imported by the main
window long before anything is computed: the window's first paint does not need numpy. Those
modules write::

    if TYPE_CHECKING:
        import numpy as np
    else:
        from app.lazy_numpy import np
    from app.lazy_numpy import FloatArray, Matrix  # float64 arrays, for annotations

mypy sees numpy itself; at run time ``np`` is a stand-in that imports numpy the first time one
of its names is read and keeps each name it hands out as its own attribute, so a later
``np.asarray`` is one instance-dictionary lookup, like a module's. The link's worker imports
numpy itself when it is made (a jog guard's first check must not wait for the import).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any, TypeAlias

if TYPE_CHECKING:
    from numpy import float64
    from numpy.typing import NDArray

    FloatArray: TypeAlias = NDArray[float64]
    Matrix: TypeAlias = NDArray[float64]
else:  # the names, for importers: only annotations (strings) use them, so no numpy here
    FloatArray = object
    Matrix = object


class LazyModule:
    """A module imported at the first attribute read (thread-safe: the import system locks)."""

    def __init__(self, name: str) -> None:
        self.__dict__["_lazy_module_name"] = name

    def __getattr__(self, attr: str) -> Any:
        module = importlib.import_module(self.__dict__["_lazy_module_name"])
        value = getattr(module, attr)
        self.__dict__[attr] = value
        return value

    def __repr__(self) -> str:
        return f"<lazily imported module {self.__dict__['_lazy_module_name']!r}>"


np: Any = LazyModule("numpy")

__all__ = ["FloatArray", "LazyModule", "Matrix", "np"]

"""The methods ``dataclasses`` generates, compiled once and kept beside the bytecode, not at every start.

``@dataclass`` writes the source of each class's ``__init__``, ``__repr__``, ``__eq__``, ``__hash__``
and (frozen) ``__setattr__``/``__delattr__`` and runs it with ``exec``: Python 3.11 compiles each
text on every start, as it would a module with no ``__pycache__``. The window's ~85 dataclasses
are ~480 such texts: **~55 ms of compiling** before the first paint, a quarter of importing the
window's modules (measured on the 2-core machine, 6.11, Python 3.11.7).

:class:`DataclassCode` keeps those code objects in one file, ``__pycache__/dataclass-methods.<tag>.marshal``
beside this module (``<tag>``: ``sys.implementation.cache_tag``), written as Python writes a
``.pyc``: only where the folder is writable and ``sys.dont_write_bytecode`` is off, and atomically.
The key is the whole generated text, so a changed class is a new text: a stale entry can never
stand for new code (entries not used by a start are dropped at the next write). The file starts
with the interpreter's bytecode magic number; a file from another interpreter, or one that does
not read, is ignored and the texts are compiled as before. Compiled the way ``exec`` of a text in
``dataclasses`` compiles it (file ``"<string>"``, no ``__future__`` flags inherited). The file is
code, trusted as the ``.pyc`` files in the same folder are (whoever can write one can write both).

The hook is the name ``exec`` in the ``dataclasses`` module's globals, which its ``_create_fn``
(3.11, 3.12) and ``_FuncBuilder`` (3.13) look up before the builtin: :meth:`DataclassCode.install`
sets it, :meth:`DataclassCode.uninstall` removes it. Nothing else of ``dataclasses`` changes.
"""

from __future__ import annotations

import builtins
import dataclasses
import importlib.util
import marshal
import sys
import threading
from pathlib import Path
from types import CodeType
from typing import Any

from app.points.atomic import atomic_write_bytes

__all__ = ["DATACLASS_CODE", "DataclassCode", "default_cache_path"]

MAGIC = importlib.util.MAGIC_NUMBER


def default_cache_path() -> Path:
    """``__pycache__/dataclass-methods.<cache tag>.marshal`` beside this module."""
    tag = sys.implementation.cache_tag or "unknown"
    return Path(__file__).resolve().parent / "__pycache__" / f"dataclass-methods.{tag}.marshal"


class DataclassCode:
    """Code objects of generated dataclass methods, by their source text (see the module)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self._lock = threading.Lock()
        self._stored: dict[str, CodeType] = {}  # read from the file
        self._used: dict[str, CodeType] = {}  # asked for by this process
        self.compiled = 0  # texts compiled by this process (not in the file)
        self._written_with = 0  # `compiled` when the file was last written (or none compiled yet)

    def load(self) -> int:
        """Read the file; the number of code objects in it (0: none, or not one we can use)."""
        try:
            data = self.path.read_bytes()
        except OSError:
            return 0
        if not data.startswith(MAGIC):
            return 0
        try:
            table = marshal.loads(data[len(MAGIC) :])
        except (EOFError, ValueError, TypeError):
            return 0
        if isinstance(table, dict):
            self._stored = {k: v for k, v in table.items() if isinstance(k, str) and isinstance(v, CodeType)}
        return len(self._stored)

    def exec(self, source: Any, globals: Any = None, locals: Any = None) -> None:
        """``exec`` for ``dataclasses``: a text's code from the file, or compiled (and noted)."""
        if not isinstance(source, str):
            builtins.exec(source, globals, locals)
            return
        code = self._used.get(source) or self._stored.get(source)
        if code is None:
            code = compile(source, "<string>", "exec", dont_inherit=True)
            with self._lock:
                self.compiled += 1
        self._used[source] = code
        builtins.exec(code, globals, locals)

    def install(self) -> None:
        """Load the file and make ``dataclasses`` run its texts through :meth:`exec`."""
        self.load()
        dataclasses.exec = self.exec  # type: ignore[attr-defined]

    @staticmethod
    def uninstall() -> None:
        """``dataclasses`` uses the builtin ``exec`` again."""
        vars(dataclasses).pop("exec", None)

    def save(self, *, force: bool = False) -> bool:
        """Write the texts this process used, when one was compiled here since the last write and
        bytecode is written (``sys.dont_write_bytecode`` off, or ``force``). True when written; a
        folder that cannot be written is no error (False)."""
        with self._lock:
            if self.compiled == self._written_with or (sys.dont_write_bytecode and not force):
                return False
            table, self._written_with = dict(self._used), self.compiled
        try:
            self.path.parent.mkdir(exist_ok=True)
            atomic_write_bytes(self.path, MAGIC + marshal.dumps(table))
        except (OSError, ValueError):
            return False
        return True


#: The one the GUI installs at its start (ui/main.py)
DATACLASS_CODE = DataclassCode(default_cache_path())

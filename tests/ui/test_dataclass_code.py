"""ui/dataclass_code.py: the methods ``dataclasses`` generates, compiled once and read back."""

from __future__ import annotations

import dataclasses
import importlib.util
import marshal
import os
import sys
import textwrap
import types
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.ui.gui_child import ROOT, run_gui_child
from ui.dataclass_code import DataclassCode, default_cache_path

# a module's text with the shapes TeachPad uses: frozen, defaults, a factory, ordering, slots,
# and this file's own `from __future__ import annotations`
MODULE = textwrap.dedent("""
    from __future__ import annotations
    import dataclasses

    @dataclasses.dataclass(frozen=True)
    class Pose:
        x: float
        y: float = 0.0
        tags: tuple[str, ...] = ()

    @dataclasses.dataclass(order=True, slots=True)
    class Row:
        index: int
        names: list[str] = dataclasses.field(default_factory=list)
""")


def _classes(code: DataclassCode | None, text: str = MODULE) -> dict[str, Any]:
    """The module's classes, made through ``code`` (None: the plain ``dataclasses``)."""
    module = types.ModuleType("made_here")  # dataclasses reads string annotations in sys.modules
    sys.modules[module.__name__] = module
    if code is not None:
        code.install()
    try:
        exec(text, vars(module))
    finally:
        DataclassCode.uninstall()
        del sys.modules[module.__name__]
    return vars(module)


@pytest.fixture
def no_hook() -> Iterator[None]:
    """The test leaves ``dataclasses`` as it found it (ui.main may have installed the GUI's)."""
    before = vars(dataclasses).get("exec")
    yield
    if before is None:
        vars(dataclasses).pop("exec", None)
    else:
        vars(dataclasses)["exec"] = before


def _same_behaviour(made: dict[str, Any], plain: dict[str, Any]) -> None:
    for name in ("Pose", "Row"):
        assert made[name].__init__.__annotations__ == plain[name].__init__.__annotations__
    pose, plain_pose = made["Pose"](1.0, tags=("a",)), plain["Pose"](1.0, tags=("a",))
    assert repr(pose) == repr(plain_pose)
    assert pose == made["Pose"](1.0, 0.0, ("a",)) and hash(pose) == hash(made["Pose"](1.0, 0.0, ("a",)))
    with pytest.raises(dataclasses.FrozenInstanceError):
        pose.x = 2.0
    rows = [made["Row"](2), made["Row"](1, ["b"])]
    assert sorted(rows)[0].index == 1 and rows[0].names == [] and rows[0].names is not made["Row"](3).names
    assert not hasattr(rows[0], "__dict__")  # slots


def test_a_first_start_compiles_and_a_second_reads_what_the_first_wrote(
    tmp_path: Path, no_hook: None
) -> None:
    path = tmp_path / "__pycache__" / "dataclass-methods.test.marshal"
    first = DataclassCode(path)
    made = _classes(first)
    assert first.compiled > 0 and first.save(force=True)
    assert path.read_bytes().startswith(importlib.util.MAGIC_NUMBER)
    assert not first.save(force=True)  # nothing new since: no write

    second = DataclassCode(path)
    again = _classes(second)
    assert second.compiled == 0 and not second.save(force=True)
    plain = _classes(None)
    _same_behaviour(made, plain)
    _same_behaviour(again, plain)


def test_a_changed_class_is_compiled_anew_and_unused_texts_are_dropped(tmp_path: Path, no_hook: None) -> None:
    path = tmp_path / "dc.marshal"
    old = DataclassCode(path)
    _classes(old)
    old.save(force=True)
    stored = len(marshal.loads(path.read_bytes()[len(importlib.util.MAGIC_NUMBER) :]))
    changed = MODULE.replace("    y: float = 0.0\n", "    y: float = 0.0\n    z: float = 5.0\n")
    new = DataclassCode(path)
    made = _classes(new, changed)
    assert 0 < new.compiled < stored  # the Pose texts that name z; Row's came from the file
    assert made["Pose"](1.0).z == 5.0  # the new code, never the stale one
    assert new.save(force=True)
    back_to_old = DataclassCode(path)  # the old Pose's texts were not used by the last start: dropped
    _classes(back_to_old)
    assert back_to_old.compiled == new.compiled


@pytest.mark.parametrize(
    "content",
    [b"", b"\x00\x01\x02\x03garbage", importlib.util.MAGIC_NUMBER + b"\xff\xfe", b"XXXX" + marshal.dumps({})],
    ids=["empty", "garbage", "bad marshal", "another interpreter"],
)
def test_a_file_that_does_not_read_is_ignored(tmp_path: Path, content: bytes, no_hook: None) -> None:
    path = tmp_path / "dc.marshal"
    path.write_bytes(content)
    code = DataclassCode(path)
    assert code.load() == 0
    _same_behaviour(_classes(code), _classes(None))
    assert code.compiled > 0


def test_a_table_of_the_wrong_things_is_ignored(tmp_path: Path) -> None:
    path = tmp_path / "dc.marshal"
    path.write_bytes(importlib.util.MAGIC_NUMBER + marshal.dumps({"def f(): pass": "not code", 3: b""}))
    assert DataclassCode(path).load() == 0


def test_nothing_is_written_when_python_writes_no_bytecode_or_cannot(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, no_hook: None
) -> None:
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    path = tmp_path / "dc.marshal"
    code = DataclassCode(path)
    _classes(code)
    assert not code.save() and not path.exists()
    blocked = tmp_path / "a-file"
    blocked.write_text("")
    elsewhere = DataclassCode(blocked / "sub" / "dc.marshal")  # its folder cannot be made
    _classes(elsewhere)
    assert not elsewhere.save(force=True)


def test_the_gui_s_file_is_beside_the_bytecode_of_ui() -> None:
    path = default_cache_path()
    assert path.parent == ROOT / "ui" / "__pycache__" and sys.implementation.cache_tag in path.name


def test_a_second_start_of_the_window_compiles_no_dataclass_method_before_its_first_paint(
    tmp_path: Path,
) -> None:
    """The real start (ui.main.main) twice with the file in a temporary folder: the first start
    compiles the window's texts and writes them after its first paint, the second compiles none."""
    code = textwrap.dedent("""
        import json, sys
        from pathlib import Path
        from ui.dataclass_code import DATACLASS_CODE
        DATACLASS_CODE.path = Path(sys.argv[2])
        from PySide6.QtWidgets import QApplication
        import ui.main as teachpad

        class Probe(teachpad.MainWindow):
            def paintEvent(self, event):
                if not hasattr(self, "seen"):
                    self.seen = DATACLASS_CODE.compiled
                    print("FIRST_PAINT " + json.dumps(self.seen), flush=True)
                    teachpad.QTimer.singleShot(0, QApplication.instance().quit)
                super().paintEvent(event)

        teachpad.MainWindow = Probe
        sys.exit(teachpad.main(["--settings", sys.argv[1], "--host", "127.0.0.1", "--port", "9"]))
    """)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    cache = str(tmp_path / "dc.marshal")
    compiled = [
        run_gui_child(code, tmp_path, cache, env=env, expect="FIRST_PAINT")["FIRST_PAINT"] for _ in range(2)
    ]
    assert compiled[0] > 300  # the window's ~85 dataclasses, ~5 methods each
    assert compiled[1] == 0

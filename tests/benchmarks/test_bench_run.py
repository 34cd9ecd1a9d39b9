"""benchmarks/run.py: what `make bench` does before its figures."""

from __future__ import annotations

from pathlib import Path

from benchmarks.run import _warm_dataclass_code
from ui.dataclass_code import DataclassCode, default_cache_path

ROOT = Path(__file__).resolve().parents[2]


def test_the_warm_up_start_leaves_the_windows_dataclass_methods_compiled() -> None:
    """One real start (the simulator, a screenshot) with bytecode writing on, whatever this
    process's environment says: the file beside ui's bytecode then holds the window's texts."""
    default_cache_path().unlink(missing_ok=True)  # only the warm-up start can write it again
    assert _warm_dataclass_code(ROOT) == "warmed by one start before the run"
    assert DataclassCode(default_cache_path()).load() > 300

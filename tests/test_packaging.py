"""The bundle (`make dist`, packaging/teachpad.spec) and what the code needs to run frozen.

The bundle itself is built and run by `.ci/run` (tools/dist_smoke.py: minutes, not for every
`make test`); these are the fast checks of what it relies on.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.waits import kill_child, read_line, wait_child
from ui.main import SimProcess

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "packaging" / "teachpad.spec"


def _spec_list(name: str) -> list[str]:
    """A top-level list of strings assigned in the spec (a Python file PyInstaller executes)."""
    for node in ast.parse(SPEC.read_text("utf-8")).body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == name for t in node.targets
        ):
            value = ast.literal_eval(node.value)
            assert isinstance(value, list)
            return [str(v) for v in value]
    raise AssertionError(f"{name} not in {SPEC}")


def test_frozen_teachpad_starts_the_bundles_own_simulator(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """In the bundle sys.executable is the bundle's `teachpad`, which runs only the GUI (no
    `-c`, no `-m`): `teachpad --sim` must start `teachpad-sim` beside it, told to stop with its
    stdin, and must not point PYTHONPATH at a source tree."""
    monkeypatch.setattr(sys, "frozen", True, raising=False)
    monkeypatch.setattr(sys, "executable", str(tmp_path / "teachpad"))
    monkeypatch.delenv("PYTHONPATH", raising=False)
    command, env = SimProcess.command()
    suffix = ".exe" if sys.platform == "win32" else ""
    assert command[0] == str(tmp_path / f"teachpad-sim{suffix}")
    assert "-c" not in command and "-m" not in command
    assert {"--port", "0", "--no-stdin", "--stop-with-stdin"} <= set(command)
    assert "PYTHONPATH" not in env


def test_the_simulator_stops_by_itself_when_its_stdin_ends() -> None:
    """`--stop-with-stdin`: the parent's pipe closing stops the simulator (exit 0) with no signal
    sent to anybody -- the same on Windows, where a process cannot SIGTERM itself cleanly."""
    child = subprocess.Popen(
        [sys.executable, "-m", "app.sim.cli", "--port", "0", "--no-stdin", "--stop-with-stdin"],
        cwd=ROOT,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert child.stdin is not None and child.stdout is not None and child.stderr is not None
        assert "listening on" in read_line(child.stdout, "the simulator's port")
        child.stdin.close()
        code = wait_child(child, "the simulator after its stdin ended")
        errors = child.stderr.read()
    finally:
        kill_child(child)
    assert code == 0, errors
    assert "signal" not in errors, errors  # it stopped on its own, not by a signal handler


def test_nothing_the_spec_leaves_out_is_imported_by_the_product() -> None:
    """Every module of app/ and ui/ imported (what the bundle may run): none of the spec's
    EXCLUDES may be loaded, or the bundle would fail there with ModuleNotFoundError."""
    code = (
        "import importlib, json, pkgutil, sys\n"
        "import app, ui\n"
        "for pkg in (app, ui):\n"
        "    for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + '.'):\n"
        "        importlib.import_module(m.name)\n"
        "import pyqtgraph\n"
        "print(json.dumps(sorted(sys.modules)))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env={**os.environ, "QT_QPA_PLATFORM": "offscreen"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    loaded = set(json.loads(done.stdout.splitlines()[-1]))
    excluded = _spec_list("EXCLUDES")
    assert "tkinter" in excluded  # the list was read
    hit = sorted(e for e in excluded if any(m == e or m.startswith(e + ".") for m in loaded))
    assert not hit, f"imported by the product but left out of the bundle: {hit}"


def test_the_spec_collects_the_files_the_code_reads_at_their_package_paths() -> None:
    """The translations and robot profiles go where `ui.i18n` and `app.view3d.profile` look
    for them, relative to their packages (frozen: under sys._MEIPASS)."""
    from app.view3d.profile import DEFAULT_PROFILE_FILE
    from ui.i18n import I18N_DIR, qm_path

    tree = ast.parse(SPEC.read_text("utf-8"))
    datas = next(
        n.value
        for n in tree.body
        if isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "DATAS" for t in n.targets)
    )
    assert isinstance(datas, ast.List)
    targets = {ast.literal_eval(entry.elts[1]) for entry in datas.elts if isinstance(entry, ast.Tuple)}
    assert I18N_DIR.relative_to(ROOT).as_posix() in targets
    assert qm_path("zh_CN").is_file()
    assert "app/view3d/profiles" in targets
    assert (ROOT / "app" / "view3d" / "profiles" / DEFAULT_PROFILE_FILE).is_file()
    launchers = sorted(p.stem for p in (ROOT / "packaging" / "launchers").glob("*.py"))
    assert launchers == ["teachpad", "teachpad-cli", "teachpad-sim"]


def test_the_bench_says_why_when_the_bundle_is_not_built(tmp_path: Path) -> None:
    """`make bench` without `make dist`: the bundle's keys are there, null, with the reason."""
    from benchmarks import bundle
    from benchmarks.goals import goals

    out = bundle.run(True, tmp_path / "dist" / "teachpad")
    assert out["built"] is False and "make dist" in out["reason"]
    assert out["size_mb"] is None and out["cli_status_s"] is None and out["cli_help_s"] is None
    entry = next(e for e in goals({"bundle": out})["entries"] if e["key"] == "bundle.size_mb")
    assert entry["value"] is None and "make dist" in entry["reason"]  # the table says why too


@pytest.mark.parametrize(
    ("module", "prog"),
    [("ui.main", "teachpad"), ("app.cli.main", "teachpad-cli"), ("app.sim.cli", "teachpad-sim")],
)
def test_every_executable_says_its_version(module: str, prog: str) -> None:
    """`--version` (a bundle on a factory PC: which TeachPad is this?) prints the installed
    distribution's version, pyproject.toml's."""
    import tomllib

    from app.version import version

    with open(ROOT / "pyproject.toml", "rb") as f:
        expected = tomllib.load(f)["project"]["version"]
    assert version() == expected
    done = subprocess.run(
        [sys.executable, "-m", module, "--version"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
        env={**os.environ, "QT_QPA_PLATFORM": "offscreen"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == f"{prog} {expected}"

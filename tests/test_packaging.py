"""The bundle (`make dist`, packaging/teachpad.spec) and what the code needs to run frozen.

The bundle itself is built and run by `.ci/run` (tools/dist_smoke.py: minutes, not for every
`make test`); these are the fast checks of what it relies on.
"""

from __future__ import annotations

import ast
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

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
    assert launchers == ["teachpad", "teachpad-cli", "teachpad-gateway", "teachpad-sim"]


def _spec_data_targets() -> dict[str, str]:
    """The spec's DATAS as {source path relative to the repository: folder in the bundle}."""
    tree = ast.parse(SPEC.read_text("utf-8"))
    datas = next(
        n.value
        for n in tree.body
        if isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "DATAS" for t in n.targets)
    )
    assert isinstance(datas, ast.List)
    out: dict[str, str] = {}
    for entry in datas.elts:
        if isinstance(entry, ast.Tuple):
            source = entry.elts[0]
            assert isinstance(source, ast.Call)  # str(ROOT / "a" / "b" ...)
            parts = [ast.literal_eval(n.right) for n in ast.walk(source) if isinstance(n, ast.BinOp)]
            out["/".join(reversed(parts))] = ast.literal_eval(entry.elts[1])
    return out


def test_the_bundle_has_every_console_script_and_the_smoke_runs_each() -> None:
    """pyproject.toml's console scripts (teachpad-gateway among them: a plant PC without Python runs
    it) are the spec's executables, each with its launcher, and tools/dist_smoke.py runs each one."""
    import tomllib

    with open(ROOT / "pyproject.toml", "rb") as f:
        scripts = sorted(tomllib.load(f)["project"]["scripts"])
    assert "teachpad-gateway" in scripts
    assert sorted(_spec_list("NAMES")) == scripts
    assert sorted(p.stem for p in (ROOT / "packaging" / "launchers").glob("*.py")) == scripts
    assert sorted(_dist_smoke().EXECUTABLES) == scripts


def test_the_spec_collects_the_gateways_proto_where_the_payload_reads_it() -> None:
    """app.gateway.payload parses sparkplug_b.proto beside it when imported: without that file in
    the bundle's app/gateway/ the bundle's teachpad-gateway dies at start (even --version)."""
    from app.gateway.payload import PROTO_FILE

    assert PROTO_FILE.is_file()
    targets = _spec_data_targets()
    source = PROTO_FILE.relative_to(ROOT).as_posix()
    assert targets.get(source) == PROTO_FILE.parent.relative_to(ROOT).as_posix(), targets


def _dist_smoke() -> Any:
    """tools/dist_smoke.py (a script, not a package) as a module."""
    path = ROOT / "tools" / "dist_smoke.py"
    spec = importlib.util.spec_from_file_location("dist_smoke", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("dist_smoke", module)
    spec.loader.exec_module(module)
    return module


def test_the_bundle_smokes_gateway_step_passes_with_the_venvs_gateway(tmp_path: Path) -> None:
    """The smoke's gateway step (the bundle's is run by `.ci/run`), here with the venv's console
    script: `--version`, then a one-controller cell of a real simulator to a Mosquitto the step
    starts; an independent subscriber decodes NBIRTH and the DBIRTH with the simulator's pose;
    SIGTERM: exit 0 and the NDEATH with the NBIRTH's bdSeq."""
    from app.sim.config import SimConfig
    from app.sim.server import SimController

    smoke = _dist_smoke()
    exe = Path(sys.executable).parent / f"teachpad-gateway{smoke.EXE_SUFFIX}"
    assert exe.is_file(), f"{exe}: the venv's console script (make .venv/.installed-stamp)"
    sim = SimController(SimConfig(host="127.0.0.1", port=0))
    sim.start()
    try:
        steps: list[dict[str, Any]] = []
        facts = smoke.smoke_gateway(exe, sim.port, dict(os.environ), tmp_path, steps)
        x = sim.state().pose[0]
    finally:
        sim.stop()
    assert facts["pose_x"] == pytest.approx(x, abs=0.01)
    if sys.platform != "win32":  # terminate() there is TerminateProcess: no clean stop, no NDEATH
        assert facts["exit"] == 0 and facts["ndeath_bdSeq"] == facts["bdSeq"]
    assert [s["step"] for s in steps] == ["teachpad-gateway --version", "teachpad-gateway -> mosquitto"]


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

"""Smoke test of the bundle (`make dist`) from a clean environment: `make dist-smoke`, `.ci/run`.

    python tools/dist_smoke.py [dist/teachpad] [--keep DIR]

Every executable of the bundle runs with no virtual environment on PATH, no PYTHONPATH or
PYTHONHOME, a temporary HOME (and on Windows temporary APPDATA/LOCALAPPDATA) and a working
directory outside the repository, so nothing but the bundle can be imported:

1. the bundled simulator, ``teachpad-sim --port 0`` (a free loopback port, said on its stdout);
2. ``teachpad-cli --version`` (pyproject.toml's version: the metadata is in the bundle) and
   ``teachpad-cli status`` against the simulator (exit 0);
3. ``teachpad-cli run demo.teachpad.json --plan circle --check`` (exit 0: the plan is checked
   against the robot profile, which must be found inside the bundle);
4. ``teachpad --screenshot`` offscreen in zh_CN against it (exit 0, no traceback, the zh_CN
   translation found, a PNG that is not blank: its pixels vary);
5. ``teachpad --sim --screenshot`` (the GUI starts the bundle's own simulator as its child);
6. the simulator stopped by its PID (SIGTERM; on Windows TerminateProcess).

Prints one line per step with its time and a JSON summary at the end; exit 0 when all passed.
The screenshots stay in ``--keep DIR`` when given (look at them).
"""

from __future__ import annotations

import argparse
import json
import os
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXE_SUFFIX = ".exe" if sys.platform == "win32" else ""
SIM_START_TIMEOUT = 60.0  # s: a cold start of a bundle on a loaded 2-core machine
RUN_TIMEOUT = 120.0  # s for one command of the bundle
LISTENING = re.compile(r"teachpad-sim listening on (?P<host>[^\s:]+):(?P<port>\d+)")
MIN_GREY_STDDEV = 8.0  # a blank or one-colour window is ~0
MIN_COLOURS = 32
SIZE = ("--size", "1280x800")


class SmokeFailure(Exception):
    pass


def project_version() -> str:
    import tomllib

    with open(ROOT / "pyproject.toml", "rb") as f:
        return str(tomllib.load(f)["project"]["version"])


def clean_env(home: Path) -> dict[str, str]:
    """No venv, no PYTHONPATH: only what a user's session has (a locale, a HOME, a PATH)."""
    env = {"QT_QPA_PLATFORM": "offscreen", "HOME": str(home)}
    if sys.platform == "win32":
        system_root = os.environ.get("SYSTEMROOT", r"C:\Windows")
        env.update(
            SYSTEMROOT=system_root,
            PATH=rf"{system_root}\system32;{system_root}",
            USERPROFILE=str(home),
            APPDATA=str(home / "AppData" / "Roaming"),
            LOCALAPPDATA=str(home / "AppData" / "Local"),
            TEMP=str(home / "Temp"),
            TMP=str(home / "Temp"),
        )
        for key in ("APPDATA", "LOCALAPPDATA", "TEMP"):
            Path(env[key]).mkdir(parents=True, exist_ok=True)
    else:
        runtime = home / "run"
        runtime.mkdir(mode=0o700, exist_ok=True)
        env.update(PATH="/usr/bin:/bin", LANG="C.UTF-8", XDG_RUNTIME_DIR=str(runtime))
    return env


def run(
    label: str, command: list[str], env: dict[str, str], cwd: Path, steps: list[dict[str, Any]]
) -> subprocess.CompletedProcess[str]:
    t0 = time.perf_counter()
    done = subprocess.run(
        command, env=env, cwd=cwd, capture_output=True, text=True, timeout=RUN_TIMEOUT, check=False
    )
    seconds = time.perf_counter() - t0
    steps.append({"step": label, "seconds": round(seconds, 2), "exit": done.returncode})
    print(f"dist-smoke: {label}: exit {done.returncode} in {seconds:.2f} s", flush=True)
    problem = ""
    if done.returncode != 0:
        problem = f"exit code {done.returncode}"
    elif "Traceback (most recent call last)" in done.stderr + done.stdout:
        problem = "a traceback"
    if problem:
        raise SmokeFailure(f"{label}: {problem}\n{_head(done.stdout)}\n{_head(done.stderr)}")
    return done


def _head(text: str, lines: int = 40) -> str:
    kept = text.splitlines()[:lines]
    more = len(text.splitlines()) - len(kept)
    return "\n".join(kept) + (f"\n... ({more} more lines)" if more > 0 else "")


class Simulator:
    """The bundle's teachpad-sim on a free loopback port; stopped by its PID."""

    def __init__(self, exe: Path, env: dict[str, str], cwd: Path) -> None:
        self.process = subprocess.Popen(
            [str(exe), "--host", "127.0.0.1", "--port", "0", "--no-stdin"],
            env=env,
            cwd=cwd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        self.output: list[str] = []
        self._lines: queue.Queue[str] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.output.append(line)
            self._lines.put(line)
        self._lines.put("")

    def wait_port(self, timeout: float) -> int:
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self._lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise SmokeFailure(f"the simulator did not say its port within {timeout:g} s") from None
            if not line:
                raise SmokeFailure("the simulator ended at start:\n" + _head("".join(self.output)))
            found = LISTENING.search(line)
            if found:
                return int(found["port"])

    def stop(self) -> int:
        """SIGTERM by PID (the simulator stops cleanly, exit 0); kill after 10 s."""
        self.process.terminate()
        try:
            code = self.process.wait(10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            code = self.process.wait(10)
        self._reader.join(5)
        return code


def check_png(path: Path) -> dict[str, Any]:
    """The screenshot's size, grey-level spread and colour count (PySide6 of the caller's Python:
    only the bundle runs in the clean environment)."""
    from PySide6.QtGui import QImage

    if not path.is_file():
        raise SmokeFailure(f"no screenshot written at {path}")
    image = QImage(str(path))
    if image.isNull():
        raise SmokeFailure(f"{path} is not an image")
    width, height = image.width(), image.height()
    greys: list[int] = []
    colours: set[int] = set()
    step = 4
    for y in range(0, height, step):
        for x in range(0, width, step):
            rgb = image.pixel(x, y) & 0xFFFFFF
            colours.add(rgb)
            greys.append(((rgb >> 16) * 299 + ((rgb >> 8) & 0xFF) * 587 + (rgb & 0xFF) * 114) // 1000)
    mean = sum(greys) / len(greys)
    stddev = (sum((g - mean) ** 2 for g in greys) / len(greys)) ** 0.5
    facts = {"width": width, "height": height, "grey_stddev": round(stddev, 1), "colours": len(colours)}
    if stddev < MIN_GREY_STDDEV or len(colours) < MIN_COLOURS:
        raise SmokeFailure(f"{path} looks blank: {facts}")
    return facts


def smoke(bundle: Path, keep: Path | None) -> dict[str, Any]:
    exes = {name: bundle / f"{name}{EXE_SUFFIX}" for name in ("teachpad", "teachpad-cli", "teachpad-sim")}
    missing = [str(p) for p in exes.values() if not p.is_file()]
    if missing:
        raise SmokeFailure(f"not in the bundle: {', '.join(missing)} (run `make dist`)")
    summary: dict[str, Any] = {"bundle": str(bundle), "steps": []}
    steps: list[dict[str, Any]] = summary["steps"]
    with tempfile.TemporaryDirectory(prefix="teachpad-dist-smoke-") as tmp_name:
        tmp = Path(tmp_name)
        home = tmp / "home"
        home.mkdir()
        work = tmp / "work"
        work.mkdir()
        shots = keep or tmp / "shots"
        shots.mkdir(parents=True, exist_ok=True)
        env = clean_env(home)
        project = work / "demo.teachpad.json"
        shutil.copy(ROOT / "resources" / "samples" / "demo.teachpad.json", project)

        t0 = time.perf_counter()
        sim = Simulator(exes["teachpad-sim"], env, work)
        try:
            port = sim.wait_port(SIM_START_TIMEOUT)
            steps.append({"step": "teachpad-sim up", "seconds": round(time.perf_counter() - t0, 2)})
            print(f"dist-smoke: teachpad-sim listening on 127.0.0.1:{port} (pid {sim.process.pid})")
            link = ["--host", "127.0.0.1", "--port", str(port)]
            cli = str(exes["teachpad-cli"])
            said = run("teachpad-cli --version", [cli, "--version"], env, work, steps).stdout.strip()
            expected = f"teachpad-cli {project_version()}"
            if said != expected:
                raise SmokeFailure(f"teachpad-cli --version says {said!r}, not {expected!r}")
            status = run("teachpad-cli status", [cli, *link, "status"], env, work, steps)
            print(status.stdout.rstrip())
            run(
                "teachpad-cli run --check (robot profile)",
                [cli, *link, "run", str(project), "--plan", "circle", "--check"],
                env,
                work,
                steps,
            )
            shot_zh = shots / "bundle_zh_CN_1280x800.png"
            gui_args = [*link, "--monitor-only", "--lang", "zh_CN", *SIZE, "--screenshot", str(shot_zh)]
            gui = run(
                "teachpad --screenshot zh_CN",
                [str(exes["teachpad"]), *gui_args],
                env,
                work,
                steps,
            )
            if "no translation" in gui.stderr:
                raise SmokeFailure("the zh_CN translation was not found in the bundle:\n" + _head(gui.stderr))
            summary["screenshot_zh_CN"] = check_png(shot_zh)
        finally:
            code = sim.stop()
        steps.append({"step": "teachpad-sim stopped by PID", "exit": code})
        if sys.platform != "win32" and code != 0:  # SIGTERM is a clean stop on POSIX
            raise SmokeFailure(f"the simulator exited {code} on SIGTERM:\n" + _head("".join(sim.output)))
        print(f"dist-smoke: teachpad-sim stopped by PID, exit {code}")

        shot_sim = shots / "bundle_sim_en_1280x800.png"
        run(
            "teachpad --sim --screenshot",
            [str(exes["teachpad"]), "--sim", "--lang", "en", *SIZE, "--screenshot", str(shot_sim)],
            env,
            work,
            steps,
        )
        summary["screenshot_sim"] = check_png(shot_sim)
        summary["home_files"] = sorted(str(p.relative_to(home)) for p in home.rglob("*") if p.is_file())
    summary["total_s"] = round(sum(s.get("seconds", 0.0) for s in steps), 2)
    return summary


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument(
        "bundle", nargs="?", default=str(ROOT / "dist" / "teachpad"), help="the bundle's folder"
    )
    parser.add_argument("--keep", metavar="DIR", help="write the screenshots here (kept)")
    args = parser.parse_args(argv)
    os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")  # for reading the PNG here
    try:
        summary = smoke(Path(args.bundle).resolve(), Path(args.keep).resolve() if args.keep else None)
    except (SmokeFailure, subprocess.TimeoutExpired) as exc:
        print(f"dist-smoke: FAILED: {exc}", file=sys.stderr)
        return 1
    print("dist-smoke: passed " + json.dumps(summary, sort_keys=True))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

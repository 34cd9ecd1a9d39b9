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
5. ``teachpad-gateway --version``, then ``teachpad-gateway CELL --broker mqtt://127.0.0.1:PORT``
   for a one-controller cell of that simulator, publishing to a Mosquitto this script starts on a
   free loopback port (its own config file; stopped by its PID): an independent subscriber (paho,
   the caller's Python) decodes NBIRTH and the robot's DBIRTH -- Sparkplug B payloads the bundle
   built from ``sparkplug_b.proto``, which it parses at import -- with the pose read from the
   simulator; SIGTERM on the gateway: exit 0 and its NDEATH with the NBIRTH's ``bdSeq``;
6. ``teachpad --sim --screenshot`` (the GUI starts the bundle's own simulator as its child);
7. the simulator stopped by its PID (SIGTERM; on Windows TerminateProcess).

Prints one line per step with its time and a JSON summary at the end; exit 0 when all passed.
The screenshots stay in ``--keep DIR`` when given (look at them).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import queue
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXE_SUFFIX = ".exe" if sys.platform == "win32" else ""
#: every executable of the bundle (packaging/teachpad.spec's NAMES, pyproject.toml's console scripts)
EXECUTABLES = ("teachpad", "teachpad-cli", "teachpad-sim", "teachpad-gateway")
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


# --- the gateway: a real Mosquitto, an independent subscriber ------------------------------------
MOSQUITTO_PATHS = ("/usr/sbin/mosquitto", "/usr/bin/mosquitto", r"C:\Program Files\mosquitto\mosquitto.exe")
BROKER_START_TIMEOUT = 10.0  # s for mosquitto to accept connections
GATEWAY_TIMEOUT = 60.0  # s for the bundle's gateway to start and publish its births (cold, loaded)
GROUP, NODE, DEVICE = "smoke", "bundle", "R1"


def mosquitto_binary() -> str:
    found = shutil.which("mosquitto") or next((p for p in MOSQUITTO_PATHS if Path(p).exists()), None)
    if found is None:
        raise SmokeFailure(
            "mosquitto is not installed: the gateway's smoke needs a real MQTT broker "
            "(Debian: apt-get install -y mosquitto, .ci/run installs it; Windows: choco install mosquitto)"
        )
    return found


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


class Mosquitto:
    """``mosquitto -c FILE`` on a free loopback port, anonymous, no persistence; stopped by its PID."""

    def __init__(self, folder: Path) -> None:
        self.port = free_port()
        config = folder / "mosquitto.conf"
        config.write_text(
            f"listener {self.port} 127.0.0.1\nallow_anonymous true\npersistence false\nlog_dest stderr\n"
            "log_type error\nlog_type warning\n",
            encoding="utf-8",
        )
        self.log = folder / "mosquitto.log"
        with self.log.open("wb") as log:
            self.process = subprocess.Popen([mosquitto_binary(), "-c", str(config)], stdout=log, stderr=log)
        deadline = time.monotonic() + BROKER_START_TIMEOUT
        while not self._accepts():
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.stop()
                raise SmokeFailure(f"mosquitto did not listen on {self.port}: {self.log.read_text()[-400:]}")
            time.sleep(0.05)  # a port that is not open yet: nothing to wait on

    def _accepts(self) -> bool:
        try:
            socket.create_connection(("127.0.0.1", self.port), timeout=0.2).close()
        except OSError:
            return False
        return True

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(5)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait(5)


class Subscriber:
    """A second MQTT client (paho, the caller's Python) on ``spBv1.0/GROUP/#``: every message's
    kind (NBIRTH, DBIRTH, NDEATH...) with its payload decoded by app.gateway.payload."""

    def __init__(self, port: int) -> None:
        import paho.mqtt.client as mqtt
        from paho.mqtt.enums import CallbackAPIVersion

        self.messages: list[tuple[str, Any]] = []
        self._cond = threading.Condition()
        self._client = mqtt.Client(callback_api_version=CallbackAPIVersion.VERSION2, client_id="dist-smoke")
        subscribed = threading.Event()
        self._client.on_connect = lambda client, *_: client.subscribe(f"spBv1.0/{GROUP}/#", qos=1)
        self._client.on_subscribe = lambda *_: subscribed.set()
        self._client.on_message = self._on_message
        self._client.connect("127.0.0.1", port, keepalive=10)
        self._client.loop_start()
        if not subscribed.wait(BROKER_START_TIMEOUT):
            self.close()
            raise SmokeFailure("the smoke's subscriber got no subscription from mosquitto")

    def _on_message(self, _client: Any, _userdata: Any, message: Any) -> None:
        from app.gateway.payload import decode

        kind = message.topic.split("/")[2]
        with self._cond:
            self.messages.append((kind, decode(message.payload)))
            self._cond.notify_all()

    def wait_for(self, kind: str, timeout: float) -> Any:
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                found = next((payload for k, payload in self.messages if k == kind), None)
                if found is not None:
                    return found
                left = deadline - time.monotonic()
                if left <= 0:
                    seen = [k for k, _ in self.messages]
                    raise SmokeFailure(f"no {kind} from the gateway within {timeout:g} s (seen: {seen})")
                self._cond.wait(left)

    def close(self) -> None:
        self._client.loop_stop()
        self._client.disconnect()


def _metric(payload: Any, name: str) -> Any:
    from app.gateway.payload import metric_value

    found = [metric_value(m) for m in payload.metrics if m.name == name]
    if not found:
        raise SmokeFailure(f"no metric {name!r} in the payload")
    return found[0]


def _write_cell(folder: Path, sim_port: int) -> Path:
    cell = folder / "smoke.cell.json"
    document = {
        "format": "teachpad-cell",
        "version": 1,
        "name": "bundle smoke",
        "controllers": [{"name": DEVICE, "host": "127.0.0.1", "port": sim_port, "unit": 1}],
    }
    cell.write_text(json.dumps(document), encoding="utf-8")
    return cell


def _births(sub: Subscriber, gateway: subprocess.Popen[str]) -> dict[str, Any]:
    try:
        nbirth = sub.wait_for("NBIRTH", GATEWAY_TIMEOUT)
        dbirth = sub.wait_for("DBIRTH", GATEWAY_TIMEOUT)
    except SmokeFailure as exc:
        if gateway.poll() is not None:
            ended = f"the gateway ended (exit {gateway.returncode}) before its births"
            raise SmokeFailure(f"{ended}: {exc}") from exc
        raise
    pose_x = _metric(dbirth, "Pose/X")
    if not isinstance(pose_x, float) or math.isnan(pose_x):
        raise SmokeFailure(f"DBIRTH's Pose/X is {pose_x!r}, not a pose read from the simulator")
    return {"bdSeq": _metric(nbirth, "bdSeq"), "dbirth_metrics": len(dbirth.metrics), "pose_x": pose_x}


def _stop_gateway(gateway: subprocess.Popen[str], sub: Subscriber) -> dict[str, Any]:
    """SIGTERM by PID (on Windows TerminateProcess, no clean stop): exit 0 and an NDEATH."""
    gateway.terminate()
    try:
        _out, err = gateway.communicate(timeout=RUN_TIMEOUT)
    except subprocess.TimeoutExpired:
        gateway.kill()
        gateway.communicate()
        raise SmokeFailure("the gateway did not stop within its timeout after SIGTERM") from None
    if "Traceback (most recent call last)" in err:
        raise SmokeFailure("the gateway printed a traceback:\n" + _head(err))
    if sys.platform == "win32":
        return {"exit": gateway.returncode}
    if gateway.returncode != 0:
        raise SmokeFailure(f"the gateway exited {gateway.returncode} on SIGTERM:\n{_head(err)}")
    return {"exit": 0, "ndeath_bdSeq": _metric(sub.wait_for("NDEATH", 10.0), "bdSeq")}


def _run_gateway(
    exe: Path, cell: Path, port: int, env: dict[str, str], work: Path, sub: Subscriber
) -> dict[str, Any]:
    gateway = subprocess.Popen(
        [str(exe), str(cell), "--broker", f"mqtt://127.0.0.1:{port}", "--group", GROUP, "--node", NODE],
        env=env,
        cwd=work,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        facts = _births(sub, gateway)
    except BaseException:
        gateway.kill()
        gateway.communicate()
        raise
    return {**facts, **_stop_gateway(gateway, sub)}


def smoke_gateway(
    exe: Path, sim_port: int, env: dict[str, str], work: Path, steps: list[dict[str, Any]]
) -> dict[str, Any]:
    """The bundle's teachpad-gateway: ``--version``, then one simulator's cell to a real Mosquitto,
    read by an independent subscriber (module docstring, step 5)."""
    said = run("teachpad-gateway --version", [str(exe), "--version"], env, work, steps).stdout.strip()
    if said != f"teachpad-gateway {project_version()}":
        raise SmokeFailure(f"teachpad-gateway --version says {said!r}")
    cell = _write_cell(work, sim_port)
    t0 = time.perf_counter()
    broker = Mosquitto(work)
    try:
        sub = Subscriber(broker.port)
        try:
            facts = _run_gateway(exe, cell, broker.port, env, work, sub)
        finally:
            sub.close()
    finally:
        broker.stop()
    seconds = round(time.perf_counter() - t0, 2)
    steps.append({"step": "teachpad-gateway -> mosquitto", "seconds": seconds, "exit": facts["exit"]})
    print(f"dist-smoke: teachpad-gateway -> mosquitto: births, NDEATH, exit {facts['exit']} in {seconds} s")
    if "ndeath_bdSeq" in facts and facts["ndeath_bdSeq"] != facts["bdSeq"]:
        raise SmokeFailure(f"NDEATH's bdSeq {facts['ndeath_bdSeq']} is not the NBIRTH's {facts['bdSeq']}")
    return facts


def smoke(bundle: Path, keep: Path | None) -> dict[str, Any]:
    exes = {name: bundle / f"{name}{EXE_SUFFIX}" for name in EXECUTABLES}
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
            summary["gateway"] = smoke_gateway(exes["teachpad-gateway"], port, env, work, steps)
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

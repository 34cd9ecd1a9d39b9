"""The support bundle always carries the recent Modbus traffic (issue 21: empty unless the
traffic dock had been opened) and the event log of the last days; its manifest says what was
left out and why."""

from __future__ import annotations

import datetime as dt
import json
import zipfile
from pathlib import Path
from typing import Any

import pytest

from app.cli.main import main
from app.event_store import EventStore, StoredEvent
from app.safety.bundle import build_support_bundle
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    connect,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)

pytestmark = [pytest.mark.timeout(60), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


def bundle(out: Path) -> tuple[list[str], dict[str, Any], zipfile.ZipFile]:
    zf = zipfile.ZipFile(out)
    return zf.namelist(), json.loads(zf.read("manifest.json")), zf


def test_the_bundle_has_the_traffic_the_dock_never_showed(
    qtbot: Any, sim: Any, window: Any, tmp_path: Path
) -> None:
    menu = window.safety_menu
    assert not window.traffic_dock.isVisible() or window.event_dock.isVisible()  # tabbed behind
    connect(qtbot, window.link, sim, poll_timeout=1.0)
    with qtbot.waitSignal(window.link.trafficObserved, timeout=10_000):  # a poll's frames (or more)
        pass
    qtbot.waitUntil(lambda: window.link.state.pose is not None, timeout=10_000)
    out = tmp_path / "bundle.zip"
    menu.save_path = lambda _t, _s: str(out)
    assert menu.write_bundle() == out
    names, manifest, zf = bundle(out)
    with zf:
        traffic = zf.read("traffic.txt").decode("utf-8")
    assert "traffic.txt" in names
    assert "read pose" in traffic and "Tx" in traffic and "Rx" in traffic
    assert not any("traffic" in note for note in manifest["left_out"])


def test_the_manifest_says_what_was_left_out(tmp_path: Path) -> None:
    data, manifest = build_support_bundle(events=[], traffic=None, days=3)
    assert manifest.left_out == [
        "event log: no events in the last 3 days",
        "Modbus traffic: none given (TeachPad records it; teachpad-cli takes a file with --traffic)",
    ]
    _data, manifest = build_support_bundle(events=None, traffic=[])
    assert manifest.left_out == [
        "event log: none given",
        "Modbus traffic: no frames recorded (no connection to a controller since TeachPad started)",
    ]
    out = tmp_path / "b.zip"
    out.write_bytes(data)
    names, doc, zf = bundle(out)
    zf.close()
    assert "traffic.txt" not in names and "events.txt" not in names
    assert doc["left_out"] == list(build_support_bundle(events=[], traffic=None, days=3)[1].left_out)


def test_the_cli_bundle_has_the_saved_event_log(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    events = tmp_path / "events"
    store = EventStore(events)
    now = dt.datetime.now()
    store.append(StoredEvent(now - dt.timedelta(days=1), "error", "link", "link lost yesterday"))
    store.append(StoredEvent(now - dt.timedelta(days=20), "info", "link", "long ago"))
    out = tmp_path / "out.zip"
    argv = ["support-bundle", str(out), "--audit-dir", str(tmp_path / "audit"), "--events-dir", str(events)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "left out: Modbus traffic: none given" in printed
    with zipfile.ZipFile(out) as zf:
        lines = zf.read("events.txt").decode("utf-8").splitlines()
    assert len(lines) == 1 and lines[0].endswith("\tERROR\tlink\tlink lost yesterday")

"""Issue 23, "the GUI's cell view can publish too (a setting, off by default)": the Cell tab of the
real window, real simulators, a real Mosquitto started by the test (stopped by PID) and an
independent subscriber that decodes every Sparkplug payload. Enabling the setting: NBIRTH, then a
DBIRTH per controller; disabling it: one NDEATH (the NBIRTH's bdSeq), a clean disconnect (the broker
fires no will after it); the setting remembered; nothing of it on the GUI thread."""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication

from app.cell.publish import PublishSettings
from app.gateway.poller import GatewayTiming
from tests.gateway.conftest import Broker, Received, Subscriber, mosquitto_binary
from tests.ui.layout_audit import clipped_texts
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    app_settings_fixture,
    fast_reconnect_fixture,
    link_fixture,
    project_dialogs_fixture,
    translator_fixture,
    window_fixture,
)
from tests.ui.test_cell_view import STALE_AFTER, TIMING, WAIT_MS, _cell
from ui.panels.cell_panel import CellPanel
from ui.window_cell import PUBLISH_KEYS

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]

NAMES = ("R1", "R2", "R3")
BDSEQ = "bdSeq"
# the edge node's clocks: a short keepalive (a will would come soon), a quick broker retry
PUBLISH_TIMING = GatewayTiming(keepalive=5, broker_retry=(1, 1), stop_wait=5.0)
FAST_ENOUGH = 0.25  # s: what the GUI thread may spend in enabling or disabling (no network wait)


@pytest.fixture(name="broker")
def broker_fixture(tmp_path: Path) -> Iterator[Broker]:
    folder = tmp_path / "broker"
    folder.mkdir()
    b = Broker(mosquitto_binary(), folder)
    b.start_fresh()
    try:
        yield b
    finally:
        b.stop()


@pytest.fixture(name="subscriber")
def subscriber_fixture(broker: Broker) -> Iterator[Subscriber]:
    sub = Subscriber(broker.port)
    try:
        yield sub
    finally:
        sub.close()


@pytest.fixture(name="panel")
def panel_fixture(window: Any, sim_factory: Any, tmp_path: Path) -> Iterator[CellPanel]:
    from app.cell.cell_file import load_cell

    sims = [sim_factory() for _ in NAMES]
    host = window.cell
    host.publish_timing = PUBLISH_TIMING
    panel = host.show_cell(load_cell(_cell(sims, tmp_path)), timing=TIMING, stale_after=STALE_AFTER)
    yield panel
    host.close_cell()
    assert host.wait_unpublished(10.0)


def _bdseq(message: Received) -> int:
    return int(message.metric(BDSEQ).long_value)


def _timed(action: Any) -> float:
    start = time.perf_counter()
    action()
    return time.perf_counter() - start


def test_publishing_is_off_by_default(qtbot: Any, window: Any, panel: CellPanel) -> None:
    enabled, settings = window.cell.publish_settings()
    assert not enabled and settings == PublishSettings()
    assert panel.publisher is None and panel.listener.publisher is None
    assert panel.publish_label.text() == ""
    assert not [t for t in threading.enumerate() if t.name.startswith("paho")]


def test_enabling_births_the_cell_disabling_sends_ndeath_and_disconnects_cleanly(
    qtbot: Any, window: Any, panel: CellPanel, broker: Broker, subscriber: Subscriber
) -> None:
    qtbot.waitUntil(lambda: all(t.reading is not None for t in panel.tiles.values()), timeout=WAIT_MS)
    settings = PublishSettings(f"mqtt://127.0.0.1:{broker.port}", "plant", "pad-gui")
    host = window.cell
    took = _timed(lambda: host.set_publishing(True, settings))
    assert took < FAST_ENOUGH, f"enabling took {took:.3f} s on the GUI thread"
    # remembered in the window's settings
    store = window.settings.store
    assert [store.value(k) for k in PUBLISH_KEYS[1:]] == [settings.broker, "plant", "pad-gui"]
    assert host.publish_settings() == (True, settings)
    # NBIRTH, then a DBIRTH per controller (seq continuing from the NBIRTH's 0), then DDATA
    nbirth = subscriber.kind("NBIRTH")
    assert nbirth.topic == "spBv1.0/plant/NBIRTH/pad-gui" and nbirth.seq == 0
    births = {name: subscriber.kind("DBIRTH", name) for name in NAMES}
    messages = subscriber.snapshot()
    first = messages.index(nbirth)
    assert all(messages.index(b) > first for b in births.values())
    assert sorted(b.seq or 0 for b in births.values()) == [1, 2, 3]
    reading = panel.tiles["R1"].reading
    assert reading is not None
    pose_x = births["R1"].metric("Pose/X")
    assert pose_x.alias and pose_x.double_value == pytest.approx(reading.pose.x, abs=50)
    # the Cell tab says so
    qtbot.waitUntil(lambda: panel.publish_label.text() == "MQTT: published", timeout=WAIT_MS)
    assert "pad-gui" in panel.publish_label.toolTip()
    # one poller per controller still: the edge node has none of its own
    assert panel.publisher is not None and panel.publisher.edge._pollers == {}
    # disabling: NDEATH with the NBIRTH's bdSeq, then a clean disconnect
    before = subscriber.count()
    publisher = panel.publisher
    took = _timed(lambda: host.set_publishing(False, settings))
    assert took < FAST_ENOUGH, f"disabling took {took:.3f} s on the GUI thread"
    assert panel.publisher is None and panel.publish_label.text() == ""
    ndeath = subscriber.kind("NDEATH", start=before)
    assert _bdseq(ndeath) == _bdseq(nbirth)
    assert host.wait_unpublished(10.0)
    assert not publisher.edge._client.is_connected()
    # a marker after the disconnect: an unclean one would have made the broker publish the will, a
    # second NDEATH, before it (the broker handles the closed connection before the marker)
    subscriber.publish("spBv1.0/plant/NCMD/marker", b"")
    subscriber.wait_for("the marker", lambda m: m.topic.endswith("/marker"), start=before)
    after = subscriber.snapshot()[before:]
    assert [m.kind for m in after if m.kind == "NDEATH"] == ["NDEATH"]
    assert not any(m.kind in ("NBIRTH", "DBIRTH", "DDATA") for m in after[after.index(ndeath) + 1 :])
    assert host.publish_settings()[0] is False


def test_a_remembered_setting_publishes_the_next_cell_opened(
    qtbot: Any, window: Any, broker: Broker, subscriber: Subscriber, sim_factory: Any, tmp_path: Path
) -> None:
    from app.cell.cell_file import load_cell

    host = window.cell
    host.publish_timing = PUBLISH_TIMING
    host.set_publishing(True, PublishSettings(f"mqtt://127.0.0.1:{broker.port}", "plant", "pad-next"))
    assert host.panel is None  # no cell open: nothing to publish yet
    sims = [sim_factory() for _ in NAMES]
    panel = host.show_cell(load_cell(_cell(sims, tmp_path)), timing=TIMING, stale_after=STALE_AFTER)
    try:
        assert subscriber.kind("NBIRTH").topic == "spBv1.0/plant/NBIRTH/pad-next"
        for name in NAMES:
            subscriber.kind("DBIRTH", name)
    finally:
        before = subscriber.count()
        host.close_cell()  # closing the cell ends its publishing: NDEATH
        subscriber.kind("NDEATH", start=before)
        assert host.wait_unpublished(10.0)
    assert panel.publisher is None


def test_an_unreachable_broker_costs_the_gui_thread_nothing(
    qtbot: Any, window: Any, panel: CellPanel
) -> None:
    # TEST-NET-1: nothing answers, a connect there hangs until its timeout (in paho's thread)
    settings = PublishSettings("mqtt://192.0.2.1:1883", "plant", "pad-gui")
    took = _timed(lambda: window.cell.set_publishing(True, settings))
    assert took < FAST_ENOUGH
    assert panel.publish_label.text() == "MQTT: connecting…"
    assert "192.0.2.1:1883" in panel.publish_label.toolTip()
    # the Cell tab's title row still has room for it at 1280×800
    window.resize(1280, 800)
    qtbot.waitUntil(lambda: window.size().toTuple() == (1280, 800), timeout=WAIT_MS)
    for _ in range(3):
        QCoreApplication.sendPostedEvents()
        QCoreApplication.processEvents()
    assert clipped_texts(panel) == []
    # the tiles keep updating meanwhile
    since = time.monotonic()
    qtbot.waitUntil(
        lambda: all(t.reading is not None and t.reading.answered_at > since for t in panel.tiles.values()),
        timeout=WAIT_MS,
    )
    took = _timed(lambda: window.cell.set_publishing(False, settings))
    assert took < FAST_ENOUGH


def test_the_plant_link_dialog_says_a_bad_value_in_words(qtbot: Any, window: Any, panel: CellPanel) -> None:
    from ui.dialogs.cell_publish_dialog import CellPublishDialog

    seen: list[CellPublishDialog] = []

    def answer(dialog: Any) -> bool:
        seen.append(dialog)
        dialog.enabled_box.setChecked(True)
        dialog.broker_edit.setText("http://example")
        dialog.accept()
        assert dialog.result() != dialog.DialogCode.Accepted and dialog.error_label.isVisibleTo(dialog)
        assert "mqtt://HOST" in dialog.error_label.text()
        dialog.broker_edit.setText("mqtt://127.0.0.1:1")
        dialog.group_edit.setText("a/b")
        dialog.accept()
        assert "'/'" in dialog.error_label.text()
        dialog.group_edit.setText("plant")
        dialog.node_edit.setText("pad9")
        dialog.enabled_box.setChecked(False)  # filled in, left off
        dialog.accept()
        return bool(dialog.result() == dialog.DialogCode.Accepted)

    window.cell.run_dialog = answer
    panel.publish_button.click()
    assert len(seen) == 1
    enabled, settings = window.cell.publish_settings()
    assert not enabled and settings == PublishSettings("mqtt://127.0.0.1:1", "plant", "pad9")
    assert panel.publisher is None

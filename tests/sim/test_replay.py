"""Traffic replay (issue 24): a capture of a real session -- connect, polls, a jog, a create point,
recorded by the link's traffic capture against the normal simulator and exported as the traffic
inspector exports it (CSV and text) and as a support bundle holds it -- drives
``teachpad-sim --replay``; a fresh TeachPad link sending the same requests receives byte-identical
answers, and what cannot be matched is reported (and answered with a Modbus exception)."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path
from typing import Any

import pytest

from app.connection import ConnectionSettings
from app.errors import ModbusExceptionError
from app.link.frames import Request
from app.link.ops import CreatePoint, JogPress, JogRelease
from app.link.robot_link import RobotLink
from app.link.transport import TrafficRecord, Transport
from app.link.types import JogRequest, LinkState
from app.protocol.enums import TeachFrame
from app.safety.bundle import build_support_bundle
from app.sim.replay import (
    EXCEPTION_UNMATCHED,
    ReplayBook,
    ReplayError,
    ReplayServer,
    parse_capture_text,
    read_capture,
)
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    QT_LOG_IGNORE,
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    is_state,
)

pytestmark = [pytest.mark.timeout(120), pytest.mark.qt_log_ignore(*QT_LOG_IGNORE)]


@pytest.fixture(name="recorded")
def recorded_fixture(qtbot: Any, sim: Any, fast_reconnect: None) -> list[TrafficRecord]:
    """The frames of a real session against the simulator: connect, polls, a jog, a create point."""
    link = RobotLink(poll_hz=20.0)  # the restart canary on, as the GUI's
    records: list[TrafficRecord] = []
    link.trafficObserved.connect(records.extend)
    link.set_traffic_capture(True)
    try:
        connect(qtbot, link, sim)
        qtbot.waitUntil(lambda: link.state.pose is not None, timeout=SIGNAL_TIMEOUT_MS)
        link.submit(JogPress(JogRequest(TeachFrame.BASE, 0, 1, 20.0)))
        assert sim.wait_for(lambda s: s.teach_ratio > 0, timeout=5.0)
        link.submit(JogRelease())
        assert sim.wait_for(lambda s: s.teach_ratio == 0, timeout=5.0)
        with qtbot.waitSignal(link.commandFinished, timeout=SIGNAL_TIMEOUT_MS * 2) as done:
            link.submit(CreatePoint(7))
        assert done.args[0].ok, done.args[0]
        with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED)):
            link.disconnect()
    finally:
        link.shutdown()
    assert len(records) > 20
    return records


def export(records: list[TrafficRecord], path: Path, qtbot: Any) -> Path:
    """The traffic inspector's own export (ui/panels/traffic_panel.py)."""
    from ui.panels.traffic_panel import TrafficPanel

    panel = TrafficPanel()
    qtbot.addWidget(panel)
    panel.on_traffic(tuple(records))
    assert panel.export_to(path, visible_only=False) == len(records)
    return path


def requests_and_answers(records: list[TrafficRecord]) -> list[tuple[bytes, bytes | None]]:
    """The captured requests in order, each with the answer frame of the same transaction id."""
    out: list[tuple[bytes, bytes | None]] = []
    open_: dict[bytes, int] = {}
    for r in records:
        if r.direction == "tx":
            open_[r.frame[:2]] = len(out)
            out.append((r.frame, None))
        elif (i := open_.pop(r.frame[:2], None)) is not None:
            out[i] = (out[i][0], r.frame)
    return out


def as_request(frame: bytes) -> Request:
    pdu = frame[7:]
    fc, address, second = pdu[0], int.from_bytes(pdu[1:3]), int.from_bytes(pdu[3:5])
    count = 1 if fc == 0x06 else second
    return Request(fc, address, count, second if fc == 0x06 else 0, pdu)


def replay_to_a_fresh_link(server: ReplayServer, requests: list[bytes]) -> list[TrafficRecord]:
    """Send each captured request through a fresh TeachPad transport; every frame it saw."""
    seen: list[TrafficRecord] = []
    transport = Transport(ConnectionSettings(host="127.0.0.1", port=server.port, timeout=2.0, retries=0))
    transport.add_observer(seen.append)
    try:
        for frame in requests:
            transport.execute("replayed request", as_request(frame))
    finally:
        transport.close()
    return seen


@pytest.mark.parametrize("kind", ["csv", "txt", "bundle"])
def test_a_replayed_capture_answers_a_fresh_link_byte_for_byte(
    qtbot: Any, recorded: list[TrafficRecord], tmp_path: Path, kind: str
) -> None:
    text_path = export(recorded, tmp_path / ("traffic.csv" if kind == "csv" else "traffic.txt"), qtbot)
    path = text_path
    if kind == "bundle":  # the support bundle holds the text export's lines (app/safety/bundle.py)
        lines = text_path.read_text(encoding="utf-8-sig").splitlines()
        data, _manifest = build_support_bundle(traffic=lines)
        path = tmp_path / "teachpad-support.zip"
        path.write_bytes(data)
        assert "traffic.txt" in zipfile.ZipFile(path).namelist()
    pairs = requests_and_answers(recorded)
    functions = {req[7] for req, _ in pairs}
    assert {0x03, 0x06, 0x10} <= functions  # reads, the jog's and the create point's writes
    book = ReplayBook(read_capture(path))
    with ReplayServer(book) as server:
        seen = replay_to_a_fresh_link(server, [req for req, _ in pairs])
    sent = [r.frame for r in seen if r.direction == "tx"]
    got = [r.frame for r in seen if r.direction == "rx"]
    assert len(got) == len(pairs) == len(sent)
    for (captured_req, captured_answer), request, answer in zip(pairs, sent, got, strict=True):
        assert request[2:] == captured_req[2:]  # the same request (its own transaction id)
        assert captured_answer is not None
        # the captured controller's answer, byte for byte, under the fresh request's transaction id
        assert answer == request[:2] + captured_answer[2:]
    assert book.unmatched == [] and book.differing == [] and book.repeated == 0


def test_unmatched_requests_are_reported_and_answered_with_an_exception(
    qtbot: Any, recorded: list[TrafficRecord], tmp_path: Path
) -> None:
    book = ReplayBook(read_capture(export(recorded, tmp_path / "traffic.csv", qtbot)))
    with ReplayServer(book) as server:
        transport = Transport(ConnectionSettings(host="127.0.0.1", port=server.port, timeout=2.0, retries=0))
        try:
            with pytest.raises(ModbusExceptionError) as refused:
                transport.read("a read the capture never had", 900, 4)
            assert refused.value.exception_code == EXCEPTION_UNMATCHED
            # a read asked more often than captured gets its last captured answer again
            pose_reads = sum(1 for r in recorded if r.direction == "tx" and r.frame[7:10] == b"\x03\x01\x9c")
            for _ in range(pose_reads + 2):
                transport.read("pose", 412, 100)
        finally:
            transport.close()
    assert [u.text for u in book.unmatched] == ["read 900..903 (unit 1): not in the capture"]
    assert book.repeated == 2
    assert "1 unmatched" in book.summary()


def test_a_fresh_teachpad_link_connects_to_the_replay_and_sees_the_captured_pose(
    qtbot: Any, recorded: list[TrafficRecord], tmp_path: Path, fast_reconnect: None
) -> None:
    from app.link.decode import decode_pose
    from app.protocol.codec import WordOrder

    book = ReplayBook(read_capture(export(recorded, tmp_path / "traffic.txt", qtbot)))
    first_pose = next(
        answer for req, answer in requests_and_answers(recorded) if req[7:12] == b"\x03\x01\x9c\x00\x64"
    )
    assert first_pose is not None
    expected = decode_pose(
        [int.from_bytes(first_pose[9 + 2 * i : 11 + 2 * i]) for i in range(100)], WordOrder.LOW_FIRST
    )
    link = RobotLink(poll_hz=20.0)
    try:
        with ReplayServer(book) as server:
            with qtbot.waitSignal(link.state.poseChanged, timeout=SIGNAL_TIMEOUT_MS) as pose:
                link.connect_to(
                    ConnectionSettings(host="127.0.0.1", port=server.port, timeout=1.0, poll_timeout=1.0)
                )
            assert pose.args[0].xyzabc == expected.xyzabc
            with qtbot.waitSignal(link.connectionChanged, check_params_cb=is_state(LinkState.DISCONNECTED)):
                link.disconnect()
    finally:
        link.shutdown()
    assert book.answered > 0


def test_bad_captures_are_said_in_words(tmp_path: Path) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("time,direction,bytes,meaning\n12:00:00.000,Sideways,00 01,x\n", encoding="utf-8")
    with pytest.raises(ReplayError, match=r"line 2: the direction must be Tx or Rx"):
        read_capture(bad)
    with pytest.raises(ReplayError, match="cannot read the capture"):
        read_capture(tmp_path / "missing.csv")
    with pytest.raises(ReplayError, match="not hex"):
        parse_capture_text("t\tTx\tzz zz\tx\n")
    empty_zip = tmp_path / "bundle.zip"
    with zipfile.ZipFile(empty_zip, "w") as z:
        z.writestr("manifest.json", "{}")
    with pytest.raises(ReplayError, match=r"without traffic\.txt"):
        read_capture(empty_zip)


def test_teachpad_sim_replay_command_line(recorded: list[TrafficRecord], tmp_path: Path, qtbot: Any) -> None:
    """``teachpad-sim --replay CAPTURE`` listens, answers, and reports the unmatched at the end."""
    capture = export(recorded, tmp_path / "traffic.csv", qtbot)
    proc = subprocess.Popen(
        [sys.executable, "-m", "app.sim.cli", "--port", "0", "--replay", str(capture)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None and proc.stdin is not None
        first = proc.stdout.readline()
        assert "replaying traffic.csv" in first, first
        port = int(first.rsplit(":", 1)[1].split(";")[0])
        transport = Transport(ConnectionSettings(host="127.0.0.1", port=port, timeout=2.0, retries=0))
        try:
            transport.read("status", 560, 24)
            with pytest.raises(ModbusExceptionError):
                transport.read("unknown", 700, 2)
        finally:
            transport.close()
        out, _err = proc.communicate("quit\n", timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0
    assert "1 unmatched" in out and "unmatched: read 700..701 (unit 1): not in the capture" in out
    bad = subprocess.run(
        [sys.executable, "-m", "app.sim.cli", "--replay", str(tmp_path / "none.csv")],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert bad.returncode == 2 and "cannot read the capture" in bad.stderr and "Traceback" not in bad.stderr

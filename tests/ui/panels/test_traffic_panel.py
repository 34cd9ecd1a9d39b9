"""TrafficPanel: bounded model, lazy decoding with request pairing, filters, capture, export."""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import QCoreApplication, QModelIndex, Qt, QTranslator

from app.protocol.codec import WordOrder, encode_floats
from app.protocol.framing import encode_request, encode_response, encode_write_gv
from app.protocol.registers import POSE_BLOCK_COUNT, POSE_BLOCK_START, STATUS_BLOCK_COUNT, STATUS_BLOCK_START
from ui.models.traffic_model import COL_BYTES, COL_DIRECTION, COL_MEANING, COL_TIME, TrafficModel
from ui.models.traffic_row import is_poll_read
from ui.panels.traffic_panel import TrafficPanel

pytestmark = pytest.mark.qt_log_ignore("This plugin does not support propagateSizeHints")

SEED_TX = "00 01 00 00 00 0B 01 10 01 90 00 02 04 00 00 41 F0"  # GV200 = 30.0, from the seed
SEED_RX = "00 01 00 00 00 06 01 10 01 90 00 02"
T0 = 1_750_000_000.0


@dataclass(frozen=True)
class Rec:
    """Shaped like app.link.client.TrafficRecord."""

    t: float
    direction: str
    frame: bytes
    transport: str = "tcp"


class Wire:
    """Builds request/response record pairs with increasing transaction ids and times."""

    def __init__(self, transport: str = "tcp") -> None:
        self.transport = transport
        self.tid = 0
        self.t = T0

    def pair(self, request: bytes, response: bytes) -> list[Rec]:
        self.t += 0.01
        return [
            Rec(self.t, "tx", request, self.transport),
            Rec(self.t + 0.0004, "rx", response, self.transport),
        ]

    def poll_pose(self) -> list[Rec]:
        self.tid += 1
        values = encode_floats([400.0, -12.5, 300.0, 180.0, 0.0, 90.0]) + [0] * (POSE_BLOCK_COUNT - 12)
        return self.pair(
            encode_request(
                3, POSE_BLOCK_START, count=POSE_BLOCK_COUNT, transaction_id=self.tid, transport=self.tp
            ),
            encode_response(3, values=values, transaction_id=self.tid, transport=self.tp),
        )

    def poll_status(self, gv291: float = 255.0) -> list[Rec]:
        self.tid += 1
        values = [2, 1, 0] + [0] * (STATUS_BLOCK_COUNT - 5) + encode_floats([gv291])
        return self.pair(
            encode_request(
                3, STATUS_BLOCK_START, count=STATUS_BLOCK_COUNT, transaction_id=self.tid, transport=self.tp
            ),
            encode_response(3, values=values, transaction_id=self.tid, transport=self.tp),
        )

    def write(self, address: int, value: int) -> list[Rec]:
        self.tid += 1
        return self.pair(
            encode_request(6, address, [value], transaction_id=self.tid, transport=self.tp),
            encode_response(6, address, [value], transaction_id=self.tid, transport=self.tp),
        )

    def bad_read(self) -> list[Rec]:
        self.tid += 1
        return self.pair(
            encode_request(3, 900, count=2, transaction_id=self.tid, transport=self.tp),
            encode_response(3, exception=2, transaction_id=self.tid, transport=self.tp),
        )

    @property
    def tp(self) -> Any:
        return self.transport


def seed_pair() -> list[Rec]:
    return [
        Rec(T0, "tx", encode_write_gv(200, 30.0, transaction_id=1)),
        Rec(T0 + 0.001, "rx", encode_response(16, 400, count=2, transaction_id=1)),
    ]


def cell(model: Any, row: int, column: int, role: int = Qt.ItemDataRole.DisplayRole) -> Any:
    return model.data(model.index(row, column), role)


@pytest.fixture
def panel(qtbot: Any) -> Iterator[TrafficPanel]:
    widget = TrafficPanel()
    qtbot.addWidget(widget)
    yield widget


def test_is_poll_read() -> None:
    assert is_poll_read(412, 100)
    assert is_poll_read(412, 12)
    assert is_poll_read(560, 24)
    assert is_poll_read(576, 4)  # the clock, inside the status block
    assert not is_poll_read(400, 2)
    assert not is_poll_read(500, 20)  # runs past the pose block
    assert not is_poll_read(412, 0)


def test_rows_show_time_direction_seed_hex_and_meaning(panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair())
    model = panel.model
    assert model.rowCount() == 2
    assert cell(model, 0, COL_DIRECTION) == "→ Tx"
    assert cell(model, 1, COL_DIRECTION) == "← Rx"
    assert cell(model, 0, COL_BYTES) == SEED_TX
    assert cell(model, 1, COL_BYTES) == SEED_RX
    assert cell(model, 0, COL_MEANING) == "write GV200 = 30.0"
    assert cell(model, 1, COL_MEANING) == "ack write GV200 (400–401)"
    assert cell(model, 0, COL_TIME).count(":") == 2 and cell(model, 0, COL_TIME).endswith(".000")
    assert cell(model, 1, COL_TIME).endswith(".001")


def test_decoding_is_lazy_and_cached(panel: TrafficPanel, monkeypatch: pytest.MonkeyPatch) -> None:
    import app.protocol.frames as frames
    import ui.models.traffic_row as traffic

    calls: list[bytes] = []
    real = frames.decode_frame  # the function the model module imported

    def counting(data: bytes, **kwargs: Any) -> Any:
        calls.append(bytes(data))
        return real(data, **kwargs)

    monkeypatch.setattr(traffic, "decode_frame", counting)
    wire = Wire()
    panel.on_traffic([r for _ in range(50) for r in wire.poll_pose()])
    assert calls == []  # inserting decodes nothing
    text = cell(panel.model, 99, COL_MEANING)
    assert "X=400.0" in text and "Y=-12.5" in text  # the response was paired with its request
    n = len(calls)
    assert n == 2  # the response and the request it answers
    cell(panel.model, 99, COL_MEANING)
    assert len(calls) == n
    # The other 49 answers carry the same bytes (another transaction id): decoded once for all.
    assert cell(panel.model, 1, COL_MEANING) == text
    assert len(calls) == n
    panel.set_word_order(WordOrder.HIGH_FIRST)  # a new word order decodes afresh
    assert cell(panel.model, 3, COL_MEANING) != text


def test_one_insert_notification_per_batch(panel: TrafficPanel) -> None:
    inserted: list[tuple[int, int]] = []
    panel.model.rowsInserted.connect(lambda _parent, first, last: inserted.append((first, last)))
    wire = Wire()
    panel.on_traffic(wire.poll_pose() + wire.poll_status() + wire.write(444, 1))
    panel.on_traffic(wire.poll_pose())
    assert inserted == [(0, 5), (6, 7)]


def test_status_is_decoded_with_the_last_command(panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(wire.write(440, 0xE0) + wire.poll_status(gv291=1.0))
    assert cell(panel.model, 0, COL_MEANING) == "create temp point (440 ← 0xE0)"
    assert "GV291=bad point id" in cell(panel.model, 3, COL_MEANING)
    panel.on_traffic(wire.write(440, 0x40) + wire.poll_status(gv291=1.0))
    assert "GV291=work mode error" in cell(panel.model, 7, COL_MEANING)


def test_rtu_responses_pair_by_order(panel: TrafficPanel) -> None:
    wire = Wire("rtu")
    panel.on_traffic(wire.poll_pose() + wire.write(444, 1))
    assert "X=400.0" in cell(panel.model, 1, COL_MEANING)
    assert cell(panel.model, 3, COL_MEANING) == "ack work mode auto (444 ← 1)"
    assert cell(panel.model, 0, COL_BYTES).startswith("01 03 01 9C 00 64")


def test_exception_rows_are_red(panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(wire.bad_read())
    brush = cell(panel.model, 1, COL_MEANING, Qt.ItemDataRole.ForegroundRole)
    assert brush is not None and brush.color().name() == "#c62828"
    assert "illegal data address" in cell(panel.model, 1, COL_MEANING)


def test_hide_polls_hides_reads_of_the_pose_and_status_blocks(panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(
        wire.poll_pose() + wire.poll_status() + wire.write(444, 1) + wire.poll_pose() + wire.bad_read()
    )
    assert panel.proxy.rowCount() == 10
    panel.hide_polls_check.setChecked(True)
    assert panel.proxy.rowCount() == 4
    shown = [cell(panel.proxy, r, COL_MEANING) for r in range(4)]
    assert shown[0] == "work mode auto (444 ← 1)"
    assert "illegal data address" in shown[3]
    assert panel.count_label.text() == "4 of 10 frames shown"
    panel.on_traffic(wire.poll_status() + wire.write(445, 0x0B))  # new rows are filtered too
    assert panel.proxy.rowCount() == 6
    panel.set_hide_polls(False)
    assert not panel.hide_polls_check.isChecked()
    assert panel.proxy.rowCount() == 14


def test_text_filter_matches_meaning_or_bytes(panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(seed_pair() + wire.poll_pose() + wire.write(444, 1))
    panel.set_filter_text("gv200")
    assert panel.proxy.rowCount() == 2
    panel.set_filter_text("01 BC")  # register 444 in hex
    assert panel.proxy.rowCount() == 2
    assert cell(panel.proxy, 0, COL_MEANING) == "work mode auto (444 ← 1)"
    panel.set_filter_text("")
    assert panel.proxy.rowCount() == 6


def test_typing_in_the_filter_box_applies_after_a_pause(qtbot: Any, panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair() + Wire().poll_pose())
    panel.show()
    qtbot.waitExposed(panel)
    qtbot.keyClicks(panel.filter_edit, "GV200")
    qtbot.waitUntil(lambda: panel.proxy.rowCount() == 2, timeout=2000)
    assert panel.filter_edit.text() == "GV200"


def test_hiding_with_a_pending_filter_applies_it_and_stops_the_timer(qtbot: Any, panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair() + Wire().poll_pose())
    panel.show()
    qtbot.waitExposed(panel)
    panel.filter_edit.setText("write")
    assert panel._filter_timer.isActive()
    panel.hide()
    assert not panel._filter_timer.isActive()
    assert panel.proxy.rowCount() == 2


def test_model_is_bounded_and_drops_the_oldest(qtbot: Any) -> None:
    panel = TrafficPanel(max_rows=100)
    qtbot.addWidget(panel)
    wire = Wire()
    for _ in range(30):
        panel.on_traffic([r for _ in range(5) for r in wire.poll_status()])  # 10 rows a batch
        assert panel.model.rowCount() <= 100
    last = panel.model.row_at(panel.model.rowCount() - 1)
    assert last.t == pytest.approx(wire.t + 0.0004)
    huge = [r for _ in range(80) for r in wire.poll_pose()]  # 160 rows > max_rows
    panel.on_traffic(huge)
    assert panel.model.rowCount() == 100
    assert panel.model.row_at(0).frame == huge[60].frame
    assert panel.model.row_at(99).frame == huge[-1].frame


def test_pause_capture_signals_and_ignores_records(qtbot: Any, panel: TrafficPanel) -> None:
    with qtbot.waitSignal(panel.captureEnabledChanged, check_params_cb=lambda on: on is False):
        panel.pause_button.click()
    assert not panel.capture_enabled()
    panel.on_traffic(seed_pair())
    assert panel.model.rowCount() == 0
    assert "capture paused" in panel.count_label.text()
    with qtbot.assertNotEmitted(panel.captureEnabledChanged):
        panel.set_capture_enabled(False)  # no change, no signal
    with qtbot.waitSignal(panel.captureEnabledChanged, check_params_cb=lambda on: on is True):
        panel.set_capture_enabled(True)
    assert not panel.pause_button.isChecked()
    panel.on_traffic(seed_pair())
    assert panel.model.rowCount() == 2


def test_clear(panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair())
    panel.clear_button.click()
    assert panel.model.rowCount() == 0
    assert panel.count_label.text() == "0 frames"


def test_export_csv_is_atomic_and_follows_the_filter(tmp_path: Path, panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(seed_pair() + wire.poll_pose())
    target = tmp_path / "traffic.csv"
    target.write_text("old contents")
    panel.set_hide_polls(True)
    assert panel.export_to(target) == 2
    assert [p.name for p in tmp_path.iterdir()] == ["traffic.csv"]  # no temp file left
    assert target.read_bytes().startswith(b"\xef\xbb\xbf")  # UTF-8 with a BOM, for Excel
    rows = list(csv.reader(io.StringIO(target.read_text(encoding="utf-8-sig"))))
    assert rows[0] == ["time", "direction", "bytes", "meaning"]
    assert rows[1][1:] == ["Tx", SEED_TX, "write GV200 = 30.0"]
    assert rows[2][1:] == ["Rx", SEED_RX, "ack write GV200 (400–401)"]
    assert rows[1][0].startswith("2025-06-1") and len(rows) == 3
    assert panel.export_to(target, visible_only=False) == 4


def test_export_text_is_tab_separated(tmp_path: Path, panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair())
    target = tmp_path / "traffic.txt"
    panel.export_to(target)
    lines = target.read_text(encoding="utf-8-sig").splitlines()
    assert len(lines) == 2
    assert lines[0].split("\t")[1:] == ["Tx", SEED_TX, "write GV200 = 30.0"]


def test_failed_export_leaves_nothing_behind(tmp_path: Path, panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair())
    with pytest.raises(OSError):
        panel.export_to(tmp_path / "missing-dir" / "traffic.csv")
    target = tmp_path / "is-a-dir.csv"
    target.mkdir()
    with pytest.raises(OSError):
        panel.export_to(target)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["is-a-dir.csv"]


def test_traffic_model_passes_the_model_tester(qtmodeltester: Any) -> None:
    model = TrafficModel()
    wire = Wire()
    model.append_records(seed_pair() + wire.poll_pose() + wire.bad_read() + wire.write(440, 0x80))
    qtmodeltester.check(model)
    assert model.rowCount(model.index(0, 0)) == 0
    assert model.data(QModelIndex()) is None


def test_filter_proxy_passes_the_model_tester(qtmodeltester: Any, panel: TrafficPanel) -> None:
    wire = Wire()
    panel.on_traffic(seed_pair() + wire.poll_pose() + wire.poll_status())
    panel.set_hide_polls(True)
    qtmodeltester.check(panel.proxy)


class _Prefix(QTranslator):
    def translate(self, context: str, source: str, disambiguation: str | None = None, n: int = -1) -> str:
        return f"中 {source}"

    def isEmpty(self) -> bool:
        return False


def test_language_change_retranslates_headers_and_directions(qtbot: Any, panel: TrafficPanel) -> None:
    panel.on_traffic(seed_pair())
    changed: list[int] = []
    panel.model.headerDataChanged.connect(lambda _o, first, last: changed.append(last - first + 1))
    translator = _Prefix()
    app = QCoreApplication.instance()
    assert app is not None
    app.installTranslator(translator)
    try:
        qtbot.waitUntil(lambda: cell(panel.model, 0, COL_DIRECTION) == "中 → Tx", timeout=2000)
        assert panel.model.headerData(COL_BYTES, Qt.Orientation.Horizontal) == "中 Bytes"
        assert panel.pause_button.text() == "中 Pause capture"
        assert changed and changed[-1] == 4
    finally:
        app.removeTranslator(translator)
    qtbot.waitUntil(lambda: cell(panel.model, 0, COL_DIRECTION) == "→ Tx", timeout=2000)


def test_visible_panel_gathers_batches_into_one_insert(qtbot: Any, panel: TrafficPanel) -> None:
    panel.show()
    qtbot.waitExposed(panel)
    inserted: list[tuple[int, int]] = []
    panel.model.rowsInserted.connect(lambda _parent, first, last: inserted.append((first, last)))
    wire = Wire()
    for _ in range(5):  # five polls arriving faster than the table repaints
        panel.on_traffic(wire.poll_status())
    assert panel.model.rowCount() == 0
    qtbot.waitUntil(lambda: panel.model.rowCount() == 10, timeout=2000)
    assert inserted == [(0, 9)]
    assert panel.count_label.text() == "10 frames"


def test_hiding_flushes_and_stops_the_flush_timer(qtbot: Any, panel: TrafficPanel) -> None:
    panel.show()
    qtbot.waitExposed(panel)
    panel.on_traffic(seed_pair())
    assert panel._flush_timer.isActive()
    panel.hide()
    assert not panel._flush_timer.isActive()
    assert panel.model.rowCount() == 2


def test_export_includes_gathered_records(qtbot: Any, tmp_path: Path, panel: TrafficPanel) -> None:
    panel.show()
    qtbot.waitExposed(panel)
    panel.on_traffic(seed_pair())
    assert panel.export_to(tmp_path / "t.txt") == 2


def test_malformed_frames_do_not_break_the_table(panel: TrafficPanel) -> None:
    panel.on_traffic([Rec(T0, "tx", b"\x00\x07"), Rec(T0, "rx", b"\x00\x07\x00"), Rec(T0, "rx", b"")])
    assert panel.model.rowCount() == 3
    assert cell(panel.model, 0, COL_MEANING).startswith("truncated frame [truncated: 2 bytes")
    assert cell(panel.model, 2, COL_BYTES) == ""
    brush = cell(panel.model, 1, COL_MEANING, Qt.ItemDataRole.ForegroundRole)
    assert brush is not None  # shown in red


def test_long_frames_are_cut_in_the_cell_but_complete_in_tooltip_and_export(
    tmp_path: Path, panel: TrafficPanel
) -> None:
    panel.on_traffic(Wire().poll_pose())
    shown = cell(panel.model, 1, COL_BYTES)
    assert shown.endswith(" …") and len(shown) < 130
    full = panel.model.row_at(1).hex
    assert len(full.split()) == 209
    tip = cell(panel.model, 1, COL_BYTES, Qt.ItemDataRole.ToolTipRole)
    assert tip.startswith("209 bytes") and tip.replace("\n", " ").endswith(full[-20:])
    panel.export_to(tmp_path / "t.txt")
    assert full in (tmp_path / "t.txt").read_text(encoding="utf-8-sig")


def test_a_100hz_stream_updates_the_visible_table_at_most_at_the_flush_rate(
    qtbot: Any, panel: TrafficPanel
) -> None:
    from PySide6.QtCore import QTimer

    from ui.panels.traffic_panel import FLUSH_INTERVAL_MS

    panel.show()
    qtbot.waitExposed(panel)
    inserts: list[float] = []
    panel.model.rowsInserted.connect(lambda *_: inserts.append(time.monotonic()))
    wire = Wire()
    fed = [0]

    def poll() -> None:
        panel.on_traffic(wire.poll_pose() + wire.poll_status())
        fed[0] += 1

    timer = QTimer()
    timer.setInterval(10)  # 100 Hz, one batch per poll as the worker sends it
    timer.timeout.connect(poll)
    t0 = time.monotonic()
    timer.start()
    try:
        qtbot.waitUntil(lambda: fed[0] >= 40 and len(inserts) >= 2, timeout=10_000)
    finally:
        timer.stop()
    elapsed_ms = 1000.0 * (time.monotonic() - t0)
    # a coarse timer may fire 5 % early: each insert is >= 0.95 x the interval after the last
    assert len(inserts) <= elapsed_ms / (0.95 * FLUSH_INTERVAL_MS) + 1
    assert len(inserts) < fed[0]  # batched, not one insert per poll
    panel.flush()
    assert panel.model.rowCount() == 4 * fed[0]  # nothing lost


def test_the_meaning_column_reads_in_chinese(qtbot: Any, panel: TrafficPanel) -> None:
    """(issue 21) 含义 was the English decoding inside the Chinese table; the stored meaning, the
    filter and the export keep the English."""
    import re

    from tests.ui.pendant_support import translator_fixture  # noqa: F401 - (the fixture's module)
    from ui.i18n import Translator
    from ui.traffic_words import meaning_words

    wire = Wire()
    panel.on_traffic(seed_pair() + wire.poll_status() + wire.write(440, 0x80) + wire.bad_read())
    english = [cell(panel.model, row, COL_MEANING) for row in range(panel.model.rowCount())]
    translator = Translator()
    assert translator.set_language("zh_CN")
    try:
        qtbot.waitUntil(lambda: cell(panel.model, 0, COL_MEANING) != english[0], timeout=2000)
        words = [cell(panel.model, row, COL_MEANING) for row in range(panel.model.rowCount())]
        raw = [meaning_words("read regs 107–109"), meaning_words("3 regs = 0x0001, 0x0002, 0x0003")]
    finally:
        translator.uninstall()
    assert words[0] == "写入 GV200 = 30.0" and words[1] == "写入已应答：GV200 (400–401)"
    assert words[2].startswith("读取 状态 (560–583)") and words[3].startswith("状态 (560–583)：模式=")
    assert words[5].startswith("已应答：示教使能 (440 ← 0x80)"), words[5]
    assert "异常 02：非法数据地址" in words[7], words[7]
    assert raw == ["读取 寄存器 107–109", "3 个寄存器 = 0x0001, 0x0002, 0x0003"]
    kept = re.compile(r"Modbus|GV\d+|0x[0-9A-Fa-f]+|\bX\b|\d+")
    for text in words:
        assert not re.search(r"[A-Za-z]{3,}", kept.sub("", text)), f"English left in {text!r}"
    qtbot.waitUntil(lambda: cell(panel.model, 0, COL_MEANING) == english[0], timeout=2000)
    assert panel.model.summary(panel.model._make_view(0)) == english[0]  # the stored meaning

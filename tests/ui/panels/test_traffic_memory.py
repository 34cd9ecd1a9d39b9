"""The traffic table's memory: every buffer that grows with the traffic has a bound, and a stored
row costs its frame's bytes plus a fixed few (the 10-minute soak of ``benchmarks.gui_memory``)."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtCore import QModelIndex

import ui.models.traffic_model as traffic
from tests.ui.panels.test_traffic_panel import Rec, Wire, cell
from ui.models.traffic_model import COL_MEANING, VIEW_CACHE_SIZE, TrafficModel
from ui.models.traffic_store import FIXED_BYTES_PER_ROW, FRAME_BYTES_PER_ROW, MAX_FRAME_BYTES, TrafficStore


def streaming(wire: Wire, n: int) -> list[Rec]:
    """``n`` poll pairs whose answers all differ, as while the arm moves."""
    out: list[Rec] = []
    for i in range(n):
        pair = wire.poll_pose() if i % 2 else wire.poll_status()
        answer = bytearray(pair[1].frame)
        answer[-2:] = (i % 65536).to_bytes(2, "big")
        out += [pair[0], Rec(pair[1].t, "rx", bytes(answer))]
    return out


def show_all(model: TrafficModel) -> None:
    for r in range(model.rowCount()):
        for column in range(model.columnCount()):
            model.data(model.index(r, column))


def test_every_buffer_stays_bounded_when_filled_far_past_the_cap(qapp: Any) -> None:
    model = TrafficModel(max_rows=500)
    wire = Wire()
    for _ in range(12):  # 3,000 rows a round: six times the cap
        for start in range(0, 300, 30):
            model.append_records(streaming(wire, 150)[start : start + 30])
        show_all(model)  # every row decoded and formatted once
        assert model.rowCount() <= 500
        assert model.view_count() <= VIEW_CACHE_SIZE
        assert len(model._summary_cache) <= traffic._SUMMARY_CACHE_SIZE
        assert len(model._pending) <= traffic._MAX_PENDING
        assert model.stored_bytes() == 500 * (FRAME_BYTES_PER_ROW + FIXED_BYTES_PER_ROW)


def test_unanswered_requests_do_not_pile_up(qapp: Any) -> None:
    model = TrafficModel(max_rows=100)
    wire = Wire()
    for _ in range(1000):  # requests whose answers never come (a silent controller)
        model.append_records([wire.poll_status()[0]])
    assert len(model._pending) == traffic._MAX_PENDING
    assert model.rowCount() <= 100


def test_the_store_is_allocated_once_and_rolls_in_place() -> None:
    store = TrafficStore(1000)
    assert store.nbytes() == 0  # nothing before the first row
    store.append(0.0, bytes(10), 0, -1, -1)
    allocated = store.nbytes()
    assert allocated == 1000 * (FRAME_BYTES_PER_ROW + FIXED_BYTES_PER_ROW)
    buffers = [id(b) for b in (store._data, store._times, store._offsets, store._meanings)]
    for i in range(1, 5000):
        size = 1 + i % 120
        store.append(float(i), bytes([i % 256]) * size, 0, -1, -1)
        assert len(store) <= 1000 and store.frame_bytes() <= store.frame_capacity
    assert store.nbytes() == allocated
    assert [id(b) for b in (store._data, store._times, store._offsets, store._meanings)] == buffers
    newest = len(store) - 1
    assert store.time(newest) == 4999.0 and store.frame(newest) == bytes([4999 % 256]) * (1 + 4999 % 120)
    assert store.base == 5000 - len(store)


def test_big_frames_give_way_to_the_byte_ring_first() -> None:
    store = TrafficStore(100)
    for i in range(300):
        store.append(float(i), bytes([i % 256]) * MAX_FRAME_BYTES, 0, -1, -1)
    assert store.frame_bytes() <= store.frame_capacity
    assert len(store) == store.frame_capacity // MAX_FRAME_BYTES  # fewer, longer rows
    assert store.frame(len(store) - 1) == bytes([299 % 256]) * MAX_FRAME_BYTES
    assert store.room_for([MAX_FRAME_BYTES]) >= 1
    store.drop_oldest(len(store))
    assert len(store) == 0 and store.room_for([12] * 100) == 0


def test_rows_are_the_same_after_their_views_were_dropped(qapp: Any) -> None:
    model = TrafficModel(max_rows=4 * VIEW_CACHE_SIZE)
    wire = Wire()
    model.append_records(wire.bad_read() + streaming(wire, VIEW_CACHE_SIZE))
    first = model.row_at(1)
    meaning = cell(model, 1, COL_MEANING)
    assert "illegal data address" in meaning and first.bad
    show_all(model)  # views of every other row push the first ones out
    assert model.view_count() <= VIEW_CACHE_SIZE
    again = model.row_at(1)
    assert again is not first
    assert (again.t, again.direction, again.frame, again.bad) == (first.t, first.direction, first.frame, True)
    assert again._summary == meaning  # kept with the row: not decoded again
    assert again.request is not None and again.request.frame == first.request.frame  # type: ignore[union-attr]


def test_the_table_never_keeps_an_answer_without_its_request(qapp: Any) -> None:
    model = TrafficModel(max_rows=61)  # drops 3 rows at a time: pairs would be cut in half
    wire = Wire()
    for _ in range(60):
        model.append_records(wire.poll_pose())
        first = model.row_at(0)
        assert first.direction == "tx" or first.request is not None
    assert "X=400.0" in cell(model, 0, COL_MEANING) or "X=400.0" in cell(model, 1, COL_MEANING)


def test_clear_forgets_rows_views_and_pairing(qapp: Any) -> None:
    model = TrafficModel(max_rows=100)
    wire = Wire()
    model.append_records([*streaming(wire, 20), wire.poll_status()[0]])
    show_all(model)
    model.clear()
    assert (model.rowCount(), model.view_count(), len(model._pending)) == (0, 0, 0)
    with pytest.raises(IndexError):
        model.row_at(0)
    assert model.rowCount(QModelIndex()) == 0


def test_records_gathered_while_shown_stay_within_the_table_bound(qtbot: Any) -> None:
    from ui.display_clock import DisplayClock
    from ui.panels.traffic_panel import TrafficPanel

    clock = DisplayClock()  # never given a turn of the event loop here: nothing is flushed
    panel = TrafficPanel(max_rows=50, clock=clock)
    qtbot.addWidget(panel)
    panel.show()
    qtbot.waitExposed(panel)
    wire = Wire()
    for _ in range(100):
        panel.on_traffic(streaming(wire, 5))
        assert len(panel._pending) <= 50
    newest = panel._pending[-1]
    panel.flush()
    assert panel.model.rowCount() == 50
    assert panel.model.row_at(49).frame == newest.frame

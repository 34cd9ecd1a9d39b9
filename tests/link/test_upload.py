"""The chunked upload run (no Qt): checks, grouping, chunks, cancel."""

from __future__ import annotations

from typing import Any

import pytest

from app import timing
from app.errors import InvalidInput
from app.link.upload import UPLOAD_STAGE_GV, check_upload_items, group_by_tool, stage_gv_for
from tests.link.harness import PartsHost

POSE = (100.0, 0.0, 300.0, 180.0, 0.0, 0.0)


def test_grouping_keeps_tools_in_first_seen_order() -> None:
    items = [(1, POSE, 5), (2, POSE, 3), (3, POSE, 5)]
    assert [pid for pid, _, _ in group_by_tool(items)] == [1, 3, 2]


def test_every_item_is_checked_and_bad_values_are_quoted_short(sim: Any, make_client: Any) -> None:
    client = make_client(sim)
    with pytest.raises(InvalidInput, match="finite float32"):
        check_upload_items(client, [(100, (float("nan"),) * 6, 0)])
    with pytest.raises(InvalidInput) as info:
        check_upload_items(client, [("x" * 500, POSE, 0)])
    assert len(str(info.value)) < 120


def test_chunks_until_done_with_one_final_result(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "UPLOAD_CHUNK_POINTS", 2)
    host.connect(sim)
    host.request_id = 9
    assert host.uploader.start([(100 + i, POSE, 200) for i in range(5)])
    host.request_id = None
    steps = 1
    while host.uploader.step():
        steps += 1
    assert steps >= 3  # 5 points in chunks of at most 2
    assert [p[0] for p in host.of("pointUploaded")] == [100, 101, 102, 103, 104]
    result = host.of("commandFinished")[-1]
    assert result.ok and result.request_id == 9 and result.message == "uploaded 5 of 5 points"
    assert host.of("uploadProgress")[-1] == (5, 5)


def test_cancel_between_chunks_ends_it_at_once(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(timing, "UPLOAD_CHUNK_POINTS", 1)
    host.connect(sim)
    assert host.uploader.start([(100 + i, POSE, 200) for i in range(4)])
    assert host.uploader.step()
    host.uploader.end("cancelled")
    assert host.uploader.run is None
    result = host.of("commandFinished")[-1]
    assert not result.ok and result.message == "uploaded 1 of 4 points (cancelled)"


def test_the_second_pose_block_steps_aside_for_the_restart_canary(sim: Any) -> None:
    assert stage_gv_for(None) == UPLOAD_STAGE_GV == 6
    assert stage_gv_for(99) == 6 and stage_gv_for(5) == 6
    assert stage_gv_for(8) == 12  # the canary in GV6..GV11: the poses alternate with GV12..GV17
    host = PartsHost(canary_gv=8)
    try:
        host.connect(sim)
        assert host.uploader.start([(100 + i, (100.0 + i, 0.0, 300.0, 0.0, 0.0, 0.0), 200) for i in range(6)])
        while host.uploader.step():
            pass
        assert host.of("commandFinished")[-1].ok
    finally:
        host.close()
    pose_blocks = {w.address for w in sim.writes if w.address < 400 and len(w.values) == 12}
    assert pose_blocks == {0, 24}  # GV0..GV5 and GV12..GV17
    assert sim.state().points[105] == (105.0, 0.0, 300.0, 0.0, 0.0, 0.0)

"""*Done, unconfirmed* travels from the worker's upload to the points table: a point the
controller took without any visible change of its status is UNCONFIRMED, never ON_CONTROLLER."""

from __future__ import annotations

import dataclasses
from typing import Any

import pytest

from app.link.ops import UploadPoints
from app.link.robot_link import RobotLink
from app.models import CommandResult
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.points.upload import UploadOutcome, UploadReport, apply_upload
from tests.link.progress_log import ProgressLog
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)

pytestmark = pytest.mark.timeout(60)

POSES = {5: (400.0, 10.0, 300.0, 180.0, 0.0, 0.0), 6: (410.0, 10.0, 300.0, 180.0, 0.0, 0.0)}


@pytest.mark.parametrize(("gv291", "unconfirmed"), [("read-only", True), ("writable", False)])
def test_upload_carries_unconfirmed(
    qtbot: Any, sim_factory: Any, link: RobotLink, gv291: str, unconfirmed: bool
) -> None:
    # "fast": the controller finishes within one scan, GV291 shows 0xFF before and after. With a
    # read-only GV291 nothing tells this point's create from the last one: done, unconfirmed.
    sim = sim_factory(timing="fast", gv291=gv291)
    connect(qtbot, link, sim, unconfirmed_after=0.05)
    log = ProgressLog(link)
    with qtbot.waitSignal(
        link.commandFinished,
        check_params_cb=lambda r: isinstance(r, CommandResult) and r.message.startswith("uploaded"),
        timeout=SIGNAL_TIMEOUT_MS,
    ) as done:
        link.submit(UploadPoints.of([(pid, pose, 0) for pid, pose in POSES.items()]))
    assert done.args[0].ok
    seen = [dataclasses.astuple(p) for p in log.points()]
    assert [(pid, ok) for pid, ok, _, _ in seen] == [(5, True), (6, True)]
    # The first create may still see GV291 change from its power-on value; the second cannot.
    assert seen[-1][3] is unconfirmed and (unconfirmed or not seen[0][3])
    assert sim.state().points[5] == pytest.approx(POSES[5])

    ledger = PointLedger([make_point(pid, pose=pose) for pid, pose in POSES.items()])
    report = UploadReport(
        [UploadOutcome(pid, ok, sent=ledger.point(pid), unconfirmed=unc) for pid, ok, _, unc in seen]
    )
    apply_upload(ledger, report)
    assert [p.sync for p in ledger] == [
        SyncState.UNCONFIRMED if unc else SyncState.ON_CONTROLLER for *_, unc in seen
    ]
    assert ledger.point(6).needs_upload is unconfirmed  # not proven: upload again before relying on it
    ledger.mark_all_unknown()  # a reconnect: not known any more
    assert [p.sync for p in ledger] == [SyncState.UNKNOWN] * 2


def test_every_sync_state_has_a_colour_text_and_tooltip(qapp: Any) -> None:
    from ui.models.point_columns import SYNC_COLOURS, sync_text
    from ui.panels.view3d_scene import SYNC_COLORS

    assert set(SYNC_COLOURS) == set(SyncState) == set(SYNC_COLORS)
    assert sync_text(SyncState.UNCONFIRMED) == "on controller, unconfirmed"

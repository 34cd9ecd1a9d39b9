"""The CLI's upload (:func:`app.cli.points_upload.staged_upload`, the one upload driver's CLI side)
against a scripted client: a refusal is recorded and the upload goes on, a lost link ends it, the
progress callback can stop it, and the report updates the ledger. Moved here from
tests/points/test_points.py, where they drove ``app.points.upload.upload_points`` (a third upload
path used only by tests, gone, issue 22); point 7 is in point 5's tool frame so that the upload's
order (grouped by tool, as the GUI's and the CLI's) is the one the test was written for."""

from __future__ import annotations

from app.cli.points_upload import staged_upload
from app.errors import CommandRefused, LinkError
from app.points.ledger import PointLedger
from app.points.point import SyncState, make_point
from app.points.upload import apply_upload
from app.protocol.enums import CommandKind, CommandStatus
from tests.fakes import FakeClient

ON = SyncState.ON_CONTROLLER


def ledger3() -> PointLedger:
    return PointLedger(
        [
            make_point(1, "原点", (400, 0, 450, 180, 0, 0), sync=ON),
            make_point(2, "Pick A", (450, -150, 250, 180, 0, 0), sync=ON),
            make_point(5, "pick B", (450, 150, 250, 180, 0, 0), tool=0, sync=SyncState.CHANGED),
        ]
    )


def test_upload_records_refusals_and_stops_on_lost_link() -> None:
    ledger = ledger3()
    refused = CommandRefused(CommandStatus(CommandKind.CREATE_POINT, 1))
    client = FakeClient(create_script={1: refused, 2: LinkError("connection lost")})
    report = staged_upload(client, [*ledger.snapshot(), make_point(7, tool=0)])
    assert [c["id"] for c in client.creates] == [1, 2, 5]
    assert client.creates[0]["pose"] == (400, 0, 450, 180, 0, 0) and client.creates[2]["tool"] == 0
    assert report.ok_count == 1 and [o.point_id for o in report.failed] == [2]
    assert "bad point id" in report.failed[0].reason
    assert report.aborted == "connection lost" and report.not_attempted == [5, 7]
    assert not report.all_ok

    ledger.set_field(0, "x", 1)  # edited while uploading: becomes CHANGED, upload must not hide that
    ledger.set_sync(2, ON)  # by id
    rows = apply_upload(ledger, report)
    assert rows == [1]
    assert ledger[0].sync is SyncState.CHANGED
    assert ledger[1].sync is SyncState.FAILED and "bad point id" in ledger[1].sync_error
    assert ledger[2].sync is SyncState.CHANGED


def test_upload_progress_can_stop_and_all_ok() -> None:
    ledger = ledger3()
    seen: list[tuple[int, int]] = []

    def progress(done: int, total: int) -> bool:
        seen.append((done, total))
        return done < 2

    report = staged_upload(FakeClient(), ledger.snapshot(), progress=progress)
    assert seen == [(0, 3), (1, 3), (2, 3)] and report.ok_count == 2 and report.not_attempted == [5]
    report = staged_upload(FakeClient(), ledger.snapshot())
    assert report.all_ok
    apply_upload(ledger, report)
    assert all(p.sync is ON for p in ledger)

"""The one upload driver (app/link/upload_driver.py, issue 22): the GUI's worker and the CLI send an
upload's points through it, and ``app.points.upload.upload_points`` (a third path, used only by
tests) is gone. The drivers' behaviour over the wire is in test_upload*.py, tests/cli/
test_cli_points_upload.py, test_cli_upload_restart.py and tests/link/test_completion_profiles.py."""

from __future__ import annotations

import app.cli.points_upload
import app.link.upload
import app.points.upload
from app.errors import LinkError, ModbusExceptionError, Reason
from app.link import upload_driver
from app.link.upload_driver import UploadCounts, Verdict, batch_end, send_batch
from app.models import CommandResult
from app.protocol.enums import CommandKind, RunCommand


def test_the_gui_and_the_cli_send_through_the_one_driver() -> None:
    assert not hasattr(app.points.upload, "upload_points")  # the test-only third driver
    for module in (app.link.upload, app.cli.points_upload):
        assert module.send_batch is upload_driver.send_batch, module.__name__
        assert module.group_by_tool is upload_driver.group_by_tool, module.__name__


def _failed(code: str) -> CommandResult:
    return CommandResult(
        RunCommand.CREATE_POINT, CommandKind.CREATE_POINT, None, False, code, reason=Reason(code)
    )


def test_each_result_reads_one_way_and_is_tallied() -> None:
    done = CommandResult(RunCommand.CREATE_POINT, CommandKind.CREATE_POINT, None, True, "done")
    tally = UploadCounts()
    seen = [
        tally.count(r)
        for r in (
            done,
            _failed("command_refused"),
            _failed("modbus_exception"),
            _failed("no_acknowledgement"),
            _failed("stopped_by_operator"),
            _failed("link_lost"),
        )
    ]
    assert seen[:5] == [Verdict.CREATED, Verdict.REFUSED, Verdict.REFUSED, Verdict.FAILED, Verdict.STOPPED]
    assert seen[5] is Verdict.LINK_FAILED
    assert (tally.good, tally.refused, tally.failed, tally.first_failure) == (1, 2, 1, "command_refused")


def test_batches_are_one_tool_and_bounded() -> None:
    tools = [3, 3, 3, 0, 0, 3]
    assert batch_end(tools, 0) == 3 and batch_end(tools, 0, 2) == 2 and batch_end(tools, 3) == 5
    assert batch_end(tools, 5) == 6


class _Refusing:
    """A client whose ``upload_points`` fails before its first point."""

    def __init__(self, exc: Exception) -> None:
        self.exc = exc
        self.calls: list[dict[str, object]] = []

    def upload_points(self, points: object, tool: int, progress: object, **kw: object) -> list[CommandResult]:
        self.calls.append(kw)
        raise self.exc


def test_a_batch_refused_or_cut_before_its_first_point() -> None:
    busy = _Refusing(ModbusExceptionError(0x10, 6, "busy"))
    batch = send_batch(busy, [(1, (0.0,) * 6), (2, (0.0,) * 6)], 3, None, canary_gv=99)
    assert [r.ok or r.link_failed for r in batch.results] == [False, False] and batch.link_error is None
    assert busy.calls[0]["gv_start"] == 0 and busy.calls[0]["stage_gv"] == 6
    lost = _Refusing(LinkError("connection lost"))
    batch = send_batch(lost, [(1, (0.0,) * 6)], 3, None, canary_gv=6)  # the canary in the spare block
    assert batch.results == [] and batch.link_error == "connection lost" and lost.calls[0]["stage_gv"] == 12

"""An upload's progress is keyed by its ticket (issue 22, "one result/progress signal keyed by the
ticket"): two uploads one after the other -- the second submitted while the first one's reports
are still on their way to the GUI thread -- and a create point between them, on the real link and
simulator. Each request's Pending hears its own points and counts and nothing else; the link's
``progressed`` carries each report under the ticket of the upload it belongs to."""

from __future__ import annotations

from typing import Any

import pytest

from app.link.ops import CreatePoint, UploadPoints
from app.link.progress import PointUploaded, Progress, UploadProgress
from app.link.robot_link import RobotLink
from tests.link.progress_log import ProgressLog, WorkerEnded
from tests.ui.pendant_support import (  # noqa: F401 - fixtures
    SIGNAL_TIMEOUT_MS,
    connect,
    fast_reconnect_fixture,
    link_fixture,
)

pytestmark = pytest.mark.timeout(120)


def _items(sim: Any, ids: range, tool: int) -> list[tuple[int, tuple[float, ...], int]]:
    x, y, z, a, b, c = sim.state().pose
    return [(pid, (x + pid * 0.01, y, z, a, b, c), tool) for pid in ids]


def _heard(link: RobotLink, ticket: int) -> tuple[Any, list[Progress]]:
    """The ticket's Pending (tracked at once) and the progress it hears."""
    pending = link.track(ticket)
    heard: list[Progress] = []
    pending.progressed.connect(heard.append)
    return pending, heard


def test_two_uploads_and_a_create_report_their_progress_under_their_own_tickets(
    qtbot: Any, sim: Any, link: RobotLink
) -> None:
    connect(qtbot, link, sim, timeout=1.0)  # roomy: a loaded machine's late answer is not the subject
    ended = WorkerEnded(link)
    log = ProgressLog(link)
    first_id = link.submit(UploadPoints.of(_items(sim, range(1, 4), 200)))
    first, first_heard = _heard(link, first_id)
    ended.wait(first_id)  # the first upload is over on the worker; its reports are not delivered yet
    create_id = link.submit(CreatePoint(50))  # another op between: no progress of its own
    create, create_heard = _heard(link, create_id)
    second_id = link.submit(UploadPoints.of(_items(sim, range(11, 15), 3)))
    second, second_heard = _heard(link, second_id)
    qtbot.waitUntil(lambda: first.done and create.done and second.done, timeout=SIGNAL_TIMEOUT_MS)

    assert first.result is not None and first.result.ok, first.result
    assert second.result is not None and second.result.ok, second.result
    assert len({first_id, create_id, second_id}) == 3
    # each Pending heard its own upload's points, in order, and its own counts
    assert [p.point_id for p in first_heard if isinstance(p, PointUploaded)] == [1, 2, 3]
    assert [p.point_id for p in second_heard if isinstance(p, PointUploaded)] == [11, 12, 13, 14]
    first_counts = [(p.done, p.total) for p in first_heard if isinstance(p, UploadProgress)]
    second_counts = [(p.done, p.total) for p in second_heard if isinstance(p, UploadProgress)]
    assert first_counts[0] == (0, 3) and first_counts[-1] == (3, 3)
    assert second_counts[0] == (0, 4) and second_counts[-1] == (4, 4)
    assert create_heard == []
    # the link's one progress signal: every report under the ticket of its request
    assert log.tickets() == [first_id, second_id]
    assert [p for t, p in log.reports if t == first_id] == first_heard
    assert [p for t, p in log.reports if t == second_id] == second_heard
    # and the simulator holds what each one sent
    held = sim.state().points
    assert {1, 2, 3, 11, 12, 13, 14, 50} <= set(held)

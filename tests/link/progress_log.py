"""What a link reported of its requests' progress (``progressed(ticket, Progress)``), for tests:
every report with its ticket, in order, and views by kind (the points, the counts); and
:class:`WorkerEnded`, a request's end heard on the worker thread."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from PySide6.QtCore import Qt

from app.link.progress import PointUploaded, Progress, UploadProgress
from app.link.robot_link import RobotLink
from app.models import CommandResult
from tests.waits import THREAD_TIMEOUT


class ProgressLog:
    """Connects to ``link.progressed`` (a RobotLink, a worker); ``on_point`` is called with each
    :class:`PointUploaded` as it comes (a test acting half way: cancel, silence the simulator)."""

    def __init__(self, link: Any, on_point: Callable[[PointUploaded], object] | None = None) -> None:
        self.reports: list[tuple[int, Progress]] = []
        self._on_point = on_point
        # a lambda, held by the connection: the log lives as long as the link (a test need not keep it)
        link.progressed.connect(lambda ticket, progress: self._on_progress(ticket, progress))

    def _on_progress(self, ticket: int, progress: Progress) -> None:
        self.reports.append((ticket, progress))
        if self._on_point is not None and isinstance(progress, PointUploaded):
            self._on_point(progress)

    def points(self, ticket: int | None = None) -> list[PointUploaded]:
        """The points reported (of ``ticket`` only, when given), in order."""
        return [p for t, p in self.reports if isinstance(p, PointUploaded) and ticket in (None, t)]

    def counts(self, ticket: int | None = None) -> list[tuple[int, int]]:
        """The (done, total) counts reported (of ``ticket`` only, when given), in order."""
        reports = [p for t, p in self.reports if isinstance(p, UploadProgress) and ticket in (None, t)]
        return [(p.done, p.total) for p in reports]

    def tickets(self) -> list[int]:
        """The tickets the reports came under, each once, in order of first appearance."""
        return list(dict.fromkeys(t for t, _ in self.reports))


class WorkerEnded:
    """The worker's own results, heard on the worker thread: :meth:`wait` returns once a request
    has ended there while the GUI thread does not run meanwhile -- whatever the worker reported of
    it (its progress, its result) is still queued for the GUI thread."""

    def __init__(self, link: RobotLink) -> None:
        self._ids: set[int] = set()
        self._changed = threading.Condition()
        worker = link._worker  # made now: its own signal, heard where it is emitted
        worker.commandFinished.connect(self._on_result, Qt.ConnectionType.DirectConnection)

    def _on_result(self, result: CommandResult) -> None:
        with self._changed:
            if result.request_id is not None:
                self._ids.add(result.request_id)
            self._changed.notify_all()

    def wait(self, request_id: int) -> None:
        with self._changed:
            ended = self._changed.wait_for(lambda: request_id in self._ids, THREAD_TIMEOUT)
        assert ended, f"request {request_id} did not end on the worker within {THREAD_TIMEOUT:g} s"

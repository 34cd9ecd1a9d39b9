"""The worker's job queue: the only state shared between the GUI thread and the worker thread.

Operations submitted from any thread (:mod:`app.link.ops`) become :class:`Job` s; the worker
pops them on its own thread. Urgent jobs (stop, pause, resume, jog release, cancel upload) come
out before every other job; a newer job with the same ``coalesce`` key takes the place of a
queued one (the jog press and the jog speed), and an urgent job can drop queued jobs by key (a
release drops a press not yet started). Each op's class says which it is.
``halts`` counts the queued jobs that end a running upload (stop, cancel upload): an upload sees
one queued after it began before that job runs, and writes nothing more that it would not need.
"""

from __future__ import annotations

import itertools
import threading
from collections import deque
from collections.abc import Callable, Collection
from dataclasses import dataclass
from typing import TYPE_CHECKING

from app.link.ops import JobKind, LinkOp

if TYPE_CHECKING:  # the stop line needs pymodbus; the queue is imported by the GUI before any worker
    from app.link.stop_line import StopSent

__all__ = ["Job", "JobQueue"]


@dataclass
class Job:
    """One submitted operation in the queue; what the queue needs comes from the op's class."""

    op: LinkOp
    seq: int = 0
    request_id: int = 0
    sent: threading.Event | None = None  # set by the worker once the job's first write is out (stop)
    on_line: StopSent | None = None  # a Stop already written on the stop line (its answer to read)

    @property
    def operation(self) -> str:
        return self.op.operation

    @property
    def kind(self) -> JobKind:
        return self.op.kind

    @property
    def coalesce(self) -> str | None:
        """A newer job with the same key replaces a queued one."""
        return self.op.coalesce

    @property
    def cancels(self) -> tuple[str, ...]:
        """An urgent job drops the queued jobs with these coalesce keys."""
        return self.op.cancels

    @property
    def needs_link(self) -> bool:
        return self.op.needs_link


class JobQueue:
    """Two deques under one lock; urgent jobs first. Safe to call from any thread."""

    def __init__(self, halting: Collection[str] = ()) -> None:
        self._halting = frozenset(halting)  # operations that end a running upload (stop, cancel)
        self.halts = 0  # how many of those were queued so far (read from any thread)
        self._lock = threading.Lock()
        self._urgent: deque[Job] = deque()
        self._normal: deque[Job] = deque()
        self._seq = itertools.count(1)
        self._ids = itertools.count(1)

    def put(self, job: Job) -> int:
        """Queue ``job``; returns its request id (unique, increasing, never 0). A coalesced job
        takes the place of the queued one it replaces, which then never runs (and has no result)."""
        with self._lock:
            job.seq = next(self._seq)
            job.request_id = next(self._ids)
            if job.operation in self._halting:
                self.halts += 1
            if job.kind is JobKind.URGENT:
                if job.cancels:  # e.g. a release drops a press still waiting: it must never start
                    self._normal = deque(q for q in self._normal if q.coalesce not in job.cancels)
                self._urgent.append(job)
                return job.request_id
            if job.coalesce is not None:
                for i, queued in enumerate(self._normal):
                    if queued.coalesce == job.coalesce:
                        job.seq = queued.seq  # keep its place in the queue
                        self._normal[i] = job
                        return job.request_id
            self._normal.append(job)
            return job.request_id

    def pop_urgent(self) -> Job | None:
        with self._lock:
            return self._urgent.popleft() if self._urgent else None

    def pop(self) -> Job | None:
        with self._lock:
            if self._urgent:
                return self._urgent.popleft()
            return self._normal.popleft() if self._normal else None

    def cancel(self, predicate: Callable[[Job], bool]) -> list[Job]:
        """Remove and return the queued normal jobs matching ``predicate``."""
        with self._lock:
            cancelled = [job for job in self._normal if predicate(job)]
            if cancelled:
                self._normal = deque(job for job in self._normal if not predicate(job))
            return cancelled

    def clear(self) -> list[Job]:
        with self._lock:
            jobs = [*self._urgent, *self._normal]
            self._urgent.clear()
            self._normal.clear()
            return jobs

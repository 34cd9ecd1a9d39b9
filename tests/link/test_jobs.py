"""The job queue: urgent first, coalescing, cancelling by key, ids."""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import ClassVar

from app.link.jobs import Job, JobQueue
from app.link.ops import JOG_PRESS, JOG_RATIO, JobKind, LinkOp
from tests.waits import join


@dataclass(frozen=True)
class _Plain(LinkOp):
    name: str


@dataclass(frozen=True)
class _Motion(_Plain):
    kind: ClassVar[JobKind] = JobKind.MOTION


@dataclass(frozen=True)
class _Urgent(_Plain):
    kind: ClassVar[JobKind] = JobKind.URGENT


@dataclass(frozen=True)
class _Press(_Motion):
    coalesce: ClassVar[str | None] = JOG_PRESS


@dataclass(frozen=True)
class _Speed(_Motion):
    coalesce: ClassVar[str | None] = JOG_RATIO


@dataclass(frozen=True)
class _Release(_Urgent):
    cancels: ClassVar[tuple[str, ...]] = (JOG_PRESS, JOG_RATIO)


_KINDS: dict[JobKind, type[_Plain]] = {
    JobKind.PLAIN: _Plain,
    JobKind.MOTION: _Motion,
    JobKind.URGENT: _Urgent,
}


def _job(name: str, kind: JobKind = JobKind.PLAIN, *, op: type[_Plain] | None = None) -> Job:
    """A job whose op carries ``name`` (the op's class: its priority class, coalesce key, cancels)."""
    return Job((op or _KINDS[kind])(name))


def _name(job: Job) -> str:
    assert isinstance(job.op, _Plain)
    return job.op.name


def test_urgent_jobs_come_first_and_ids_increase() -> None:
    q = JobQueue()
    ids = [q.put(_job("a")), q.put(_job("b", JobKind.MOTION)), q.put(_job("stop", JobKind.URGENT))]
    assert ids == sorted(ids) and 0 not in ids
    order = [_name(job) for job in iter(q.pop, None)]
    assert order == ["stop", "a", "b"]


def test_a_newer_coalesced_job_takes_the_place_of_the_queued_one() -> None:
    q = JobQueue()
    q.put(_job("first"))
    q.put(_job("press 1", op=_Press))
    q.put(_job("second"))
    q.put(_job("press 2", op=_Press))
    assert [_name(job) for job in iter(q.pop, None)] == ["first", "press 2", "second"]


def test_a_release_drops_the_press_and_speed_not_yet_started() -> None:
    q = JobQueue()
    q.put(_job("press", op=_Press))
    q.put(_job("speed", op=_Speed))
    q.put(_job("other"))
    q.put(_job("release", op=_Release))
    assert [_name(job) for job in iter(q.pop, None)] == ["release", "other"]


def test_pop_urgent_leaves_normal_jobs_and_cancel_and_clear() -> None:
    q = JobQueue()
    q.put(_job("move", JobKind.MOTION))
    q.put(_job("mode"))
    assert q.pop_urgent() is None
    cancelled = q.cancel(lambda job: job.kind is JobKind.MOTION)
    assert [_name(job) for job in cancelled] == ["move"]
    q.put(_job("stop", JobKind.URGENT))
    assert [_name(job) for job in q.clear()] == ["stop", "mode"]
    assert q.pop() is None


def test_ids_are_unique_across_threads() -> None:
    q = JobQueue()
    ids: list[int] = []
    lock = threading.Lock()

    def put_many() -> None:
        for _ in range(500):
            rid = q.put(_job("x"))
            with lock:
                ids.append(rid)

    threads = [threading.Thread(target=put_many) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        join(t, "a thread putting jobs")
    assert len(set(ids)) == 2000

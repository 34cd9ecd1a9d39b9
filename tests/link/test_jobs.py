"""The job queue: urgent first, coalescing, cancelling by key, ids."""

from __future__ import annotations

import threading

from app.link.jobs import JOG_PRESS, JOG_RATIO, Job, JobKind, JobQueue
from tests.waits import join


def _job(name: str, kind: JobKind = JobKind.PLAIN, **kw: object) -> Job:
    return Job(name, lambda: None, kind, **kw)  # type: ignore[arg-type]


def test_urgent_jobs_come_first_and_ids_increase() -> None:
    q = JobQueue()
    ids = [q.put(_job("a")), q.put(_job("b", JobKind.MOTION)), q.put(_job("stop", JobKind.URGENT))]
    assert ids == sorted(ids) and 0 not in ids
    order = [job.operation for job in iter(q.pop, None)]
    assert order == ["stop", "a", "b"]


def test_a_newer_coalesced_job_takes_the_place_of_the_queued_one() -> None:
    q = JobQueue()
    q.put(_job("first"))
    q.put(_job("press 1", JobKind.MOTION, coalesce=JOG_PRESS))
    q.put(_job("second"))
    q.put(_job("press 2", JobKind.MOTION, coalesce=JOG_PRESS))
    assert [job.operation for job in iter(q.pop, None)] == ["first", "press 2", "second"]


def test_a_release_drops_the_press_and_speed_not_yet_started() -> None:
    q = JobQueue()
    q.put(_job("press", JobKind.MOTION, coalesce=JOG_PRESS))
    q.put(_job("speed", JobKind.MOTION, coalesce=JOG_RATIO))
    q.put(_job("other"))
    q.put(_job("release", JobKind.URGENT, cancels=(JOG_PRESS, JOG_RATIO)))
    assert [job.operation for job in iter(q.pop, None)] == ["release", "other"]


def test_pop_urgent_leaves_normal_jobs_and_cancel_and_clear() -> None:
    q = JobQueue()
    q.put(_job("move", JobKind.MOTION))
    q.put(_job("mode"))
    assert q.pop_urgent() is None
    cancelled = q.cancel(lambda job: job.kind is JobKind.MOTION)
    assert [job.operation for job in cancelled] == ["move"]
    q.put(_job("stop", JobKind.URGENT))
    assert [job.operation for job in q.clear()] == ["stop", "mode"]
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

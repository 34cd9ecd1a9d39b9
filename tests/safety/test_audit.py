"""The audit trail: records, rotation, a truncated last line, filters, CSV, and kill -9."""

from __future__ import annotations

import csv
import datetime as dt
import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from app.errors import LinkError, WriteBlocked
from app.safety import audit, audit_read
from app.safety.audit import AuditLog, FsyncPolicy
from app.safety.audit_read import AuditFilter, ReadStats, Result, audit_files, export_csv, query, read_records
from tests.waits import wait_child

ROOT = Path(__file__).resolve().parents[2]


class Clock:
    def __init__(self, start: dt.datetime) -> None:
        self.t = start

    def __call__(self) -> dt.datetime:
        return self.t


def test_writes_and_refusals_are_recorded_with_role_result_and_both_clocks(tmp_path: Path) -> None:
    role = ["engineer"]
    log = AuditLog(tmp_path, role=lambda: role[0])
    log.note_controller_clock(dt.datetime(2026, 1, 2, 3, 4, 5))
    log.record_write(440, [0x80], single=True)
    with pytest.raises(LinkError), log.writing(400, [0, 0x41F0], single=False):
        raise LinkError("no answer from 10.0.0.5:502")
    role[0] = "operator"
    with pytest.raises(WriteBlocked), log.writing(441, [1], single=True):
        raise WriteBlocked("monitor-only mode: write to reg 441 was not sent")
    log.record_refused("jog", "Y = -593.0 mm is outside the allowed work space", {"axis": "Y"})
    log.close()
    recs = list(read_records(tmp_path))
    assert [(r.kind, r.role, r.result) for r in recs] == [
        ("write", "engineer", Result.OK),
        ("write", "engineer", Result.FAILED),
        ("write", "operator", Result.BLOCKED),
        ("refused", "operator", Result.REFUSED),
    ]
    assert recs[0].command == "teach enable (440 ← 0x80)"
    assert recs[0].args == {"fc": 6, "address": 440, "values": [0x80]}
    assert recs[1].command.startswith("write GV200") and recs[1].detail == "no answer from 10.0.0.5:502"
    assert recs[0].controller_time is not None and recs[0].controller_time.startswith("2026-01-02T03:04:0")
    assert len({(r.session, r.seq) for r in recs}) == 4


def test_one_file_per_day_rotation_and_size_cap(tmp_path: Path) -> None:
    clock = Clock(dt.datetime(2026, 3, 1, 12, 0, tzinfo=dt.UTC))
    log = AuditLog(
        tmp_path, now=clock, max_file_bytes=2000, max_total_bytes=7000, keep_days=30, fsync=FsyncPolicy.NEVER
    )
    for i in range(40):
        log.record("action", f"teach P{i}")
    clock.t += dt.timedelta(days=1)
    log.record("action", "next day")
    log.close()
    names = [p.name for p in audit_files(tmp_path)]
    assert "audit-2026-03-02.jsonl" in names and all(p.stat().st_size <= 2000 for p in audit_files(tmp_path))
    assert sum(p.stat().st_size for p in audit_files(tmp_path)) <= 7000
    assert any(n.startswith("audit-2026-03-01.") and n.count(".") == 2 for n in names)  # rotated parts
    # the oldest parts went first: what is left is the most recent of day one, in order
    day1 = [r.command for r in read_records(tmp_path, dt.date(2026, 3, 1), dt.date(2026, 3, 1))]
    assert day1 == [f"teach P{i}" for i in range(40 - len(day1), 40)]
    # the files of all but the newest keep_days days on disk go when a new file is opened (by the
    # count of days written, never by the clock: see the next test)
    clock.t += dt.timedelta(days=40)
    AuditLog(tmp_path, now=clock, keep_days=2).record("action", "much later")
    assert [p.name for p in audit_files(tmp_path)] == ["audit-2026-03-02.jsonl", "audit-2026-04-11.jsonl"]


def test_a_clock_a_year_ahead_deletes_no_record(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Issue 19 s5: a PC clock one year ahead deleted every older file (5 records -> 0)."""
    clock = Clock(dt.datetime(2026, 3, 1, 12, 0, tzinfo=dt.UTC))
    for day in range(5):
        with AuditLog(tmp_path, now=clock, keep_days=90) as log:
            log.record("action", f"teach P{day}")
        clock.t += dt.timedelta(days=1)
    clock.t += dt.timedelta(days=365)  # the clock jumps a year ahead
    with AuditLog(tmp_path, now=clock, keep_days=90) as log:
        log.record("action", "after the jump")
    commands = [r.command for r in read_records(tmp_path)]
    assert commands == [f"teach P{d}" for d in range(5)] + ["after the jump"]


def test_a_clock_stepped_back_across_midnight_keeps_a_write_paired(tmp_path: Path) -> None:
    """Issue 19 s5: a clock stepped back across midnight between a write and its answer turned the
    successful write "unknown" (its outcome line went to the older day's file, read first)."""
    clock = Clock(dt.datetime(2026, 3, 2, 0, 0, 1, tzinfo=dt.UTC))
    with AuditLog(tmp_path, now=clock) as log, log.writing(441, [1], single=True):
        clock.t -= dt.timedelta(seconds=5)  # 23:59:56 the day before
    stats = ReadStats()
    assert [r.result for r in read_records(tmp_path, stats=stats)] == [Result.OK]
    assert stats.unknown == 0
    # files an older TeachPad wrote that way (the outcome line in the older day's file) pair too
    (tmp_path / "old").mkdir()
    lines = (tmp_path / "audit-2026-03-02.jsonl").read_bytes().splitlines(keepends=True)
    (tmp_path / "old" / "audit-2026-03-02.jsonl").write_bytes(lines[0])
    (tmp_path / "old" / "audit-2026-03-01.jsonl").write_bytes(lines[1])
    assert [r.result for r in read_records(tmp_path / "old")] == [Result.OK]


def test_a_line_cut_short_is_skipped_and_the_next_writer_starts_a_fresh_line(tmp_path: Path) -> None:
    log = AuditLog(tmp_path)
    log.record("action", "one")
    log.close()
    path = audit_files(tmp_path)[0]
    with open(path, "ab") as f:
        f.write(b'{"host_time":"2026-')  # a crash in the middle of a line
    stats = ReadStats()
    assert [r.command for r in read_records(tmp_path, stats=stats)] == ["one"] and stats.skipped == 1
    log = AuditLog(tmp_path)
    log.record("action", "two")
    log.close()
    stats = ReadStats()
    assert [r.command for r in read_records(tmp_path, stats=stats)] == ["one", "two"] and stats.skipped == 1


def test_filters_and_csv_export(tmp_path: Path) -> None:
    clock = Clock(dt.datetime(2026, 5, 1, 8, 0).astimezone())
    log = AuditLog(tmp_path, now=clock, role="operator")
    log.record_write(441, [1], single=True)
    clock.t += dt.timedelta(hours=2)
    log.set_role("administrator")
    log.record("action", "change connection", args={"host": "10.0.0.9"})
    clock.t += dt.timedelta(days=1)
    log.set_role("operator")
    log.record_refused("delete point", "needs the engineer role", {"id": 3})
    log.close()
    assert [r.command for r in query(tmp_path, AuditFilter(role="administrator"))] == ["change connection"]
    assert [r.command for r in query(tmp_path, AuditFilter(result=Result.REFUSED))] == ["delete point"]
    assert [r.command for r in query(tmp_path, AuditFilter(command="STOP"))] == ["stop (441 ← 1)"]
    window = AuditFilter(
        start=dt.datetime(2026, 5, 1, 9, 0).astimezone(), end=dt.datetime(2026, 5, 1, 23, 0).astimezone()
    )
    assert [r.command for r in query(tmp_path, window)] == ["change connection"]
    out = io.StringIO()
    assert export_csv(query(tmp_path), out) == 3
    rows = list(csv.DictReader(io.StringIO(out.getvalue())))
    assert rows[1]["role"] == "administrator" and rows[1]["args"] == '{"host": "10.0.0.9"}'


CHILD = r"""
import sys
from pathlib import Path
from app.link.client import ConnectionSettings, RobotClient
from app.safety.audit import AuditLog, FsyncPolicy

directory, port, tag = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
log = AuditLog(directory, role="operator", fsync=FsyncPolicy[sys.argv[4]], max_file_bytes=16 * 1024)
client = RobotClient(ConnectionSettings(host="127.0.0.1", port=port))
client.connect()
seq = 0
while True:
    values = [seq & 0xFFFF, seq >> 16, tag, 0]
    with log.writing(0, values):
        client.write_registers(0, values)
    seq += 1
"""


def test_every_write_appears_once_also_after_kill_9(tmp_path: Path, sim: Any) -> None:
    # no fsync at all: a killed process loses nothing it wrote (the page cache survives it), so
    # this holds for every policy; fsync is about power loss
    policy = "NEVER"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    kills = 4
    for tag in range(1, kills + 1):
        before = len(sim.writes)
        argv = [sys.executable, "-c", CHILD, str(tmp_path), str(sim.port), str(tag), policy]
        child = subprocess.Popen(argv, env=env, cwd=ROOT)
        try:
            deadline = time.monotonic() + 30.0
            while len(sim.writes) < before + 150 + 40 * tag and child.poll() is None:
                assert time.monotonic() < deadline, "the child wrote too little"
                time.sleep(0.01)
            assert child.poll() is None, "the child died by itself"
        finally:
            child.send_signal(signal.SIGKILL)
            wait_child(child, "the writing child, killed")
    stats = ReadStats()
    recs = [r for r in read_records(tmp_path, stats=stats) if r.kind == "write"]
    assert stats.skipped <= kills  # at most a cut last line per kill (in practice none)
    key = {id(r): (r.args["values"][2], r.args["values"][0] | r.args["values"][1] << 16) for r in recs}
    audited = [key[id(r)] for r in recs]
    assert len(audited) == len(set(audited)), "a write was recorded twice"
    received = {
        (w.values[2], w.values[0] | w.values[1] << 16)
        for w in sim.writes
        if w.address == 0 and len(w.values) == 4
    }
    assert received <= set(audited), "a write the controller received is not in the audit"  # write-ahead
    unknown = [key[id(r)] for r in recs if r.result == Result.UNKNOWN]
    assert all(r.result in (Result.OK, Result.UNKNOWN) for r in recs)
    assert len(unknown) <= kills and stats.unknown == len(unknown)  # at most the write in flight
    for tag, seq in unknown:  # and only the last one of its child
        assert seq == max(s for t, s in audited if t == tag)
    assert {key[id(r)] for r in recs if r.result == Result.OK} <= received
    assert len(audit_files(tmp_path)) > 1  # rotated while being killed


def test_an_unwritable_audit_never_blocks_the_write_and_says_so_once(tmp_path: Path) -> None:
    blocker = tmp_path / "audit"
    blocker.write_text("a file where the folder should be")
    heard: list[str] = []
    log = AuditLog(blocker, on_error=heard.append)
    with log.writing(441, [1], single=True):
        pass  # the write itself went out
    log.record_write(441, [1], single=True)
    assert log.dropped == 3 and len(heard) == 1 and "cannot be written" in heard[0]  # write + outcome, record


def test_a_write_is_one_record_also_when_its_outcome_line_is_in_the_next_file(tmp_path: Path) -> None:
    """Write-ahead: the write's line before it goes out, the outcome line after; the reader merges
    them, across a rotation too; a write whose outcome never came reads as unknown."""
    log = AuditLog(tmp_path, max_file_bytes=600)
    with log.writing(441, [1], single=True):
        assert [r.result for r in read_records(tmp_path)] == [Result.UNKNOWN]  # in the file already
        log.record("action", "x" * 400)  # fills the file: the outcome goes to the next one
    with pytest.raises(LinkError), log.writing(0, [1, 2]):
        raise LinkError("the link is down")
    log.record_write(2, [3], single=True)  # a one-line write (no outcome line) still reads as before
    with log.writing(4, [5], single=True):
        pass
    log.record_write(6, [7], single=True, pending=True)  # the process died here: no outcome
    log.close()
    assert len(audit_files(tmp_path)) > 1
    stats = ReadStats()
    recs = list(read_records(tmp_path, stats=stats))
    assert [(r.kind, r.args.get("address"), r.result) for r in recs] == [
        ("write", 441, Result.OK),
        ("action", None, Result.OK),
        ("write", 0, Result.FAILED),
        ("write", 2, Result.OK),
        ("write", 4, Result.OK),
        ("write", 6, Result.UNKNOWN),
    ]
    assert recs[2].detail == "the link is down" and "stopped before the answer" in recs[5].detail
    assert stats.unknown == 1 and stats.records == 6 and stats.skipped == 0


def test_an_unanswered_write_does_not_hold_back_what_follows(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(audit_read, "MAX_OUTCOME_LAG", 5)
    log = AuditLog(tmp_path)
    log.record_write(6, [7], single=True, pending=True)  # never answered: its process died
    for i in range(12):
        log.record("action", f"later {i}")
    log.close()
    reader = read_records(tmp_path)
    first = next(reader)  # out after MAX_OUTCOME_LAG records, not after the whole trail
    assert first.result == Result.UNKNOWN and len(list(reader)) == 12


def test_the_reader_lives_in_audit_read() -> None:
    # its importers (app/cli/support.py, ui/panels/audit_viewer.py) import it from there; the writer
    # does not hand it on (issue 22: no re-exports, tests/test_architecture.py)
    assert query.__module__ == "app.safety.audit_read"
    assert {"query", "read_records", "export_csv"} <= set(audit_read.__all__)
    assert not set(audit_read.__all__) & set(getattr(audit, "__all__", ()))

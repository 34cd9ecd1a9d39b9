"""Tamper evidence (issue 19 s5): each audit record carries the hash of the one before it, per file
and across rotation and sessions; ``teachpad-cli audit --verify`` (and the viewer) say where the
chain breaks: a record rewritten, a record deleted. Files of an older TeachPad read as no chain."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from app.cli.main import main
from app.safety.audit import AuditLog, FsyncPolicy
from app.safety.audit_chain import verify_chain
from app.safety.audit_read import audit_files


def _trail(directory: Path) -> list[Path]:
    """Two sessions, rotated: 3 files or more."""
    for session in range(2):
        with AuditLog(directory, max_file_bytes=1200, fsync=FsyncPolicy.NEVER) as log:
            for i in range(6):
                log.record("action", f"session {session} teach P{i}")
    files = audit_files(directory)
    assert len(files) >= 3
    return files


def _lines(path: Path) -> list[bytes]:
    return path.read_bytes().splitlines(keepends=True)


def _verify(directory: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(["audit", "--verify", "--audit-dir", str(directory)])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out


def test_an_untouched_trail_is_one_chain_across_files_and_sessions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _trail(tmp_path)
    report = verify_chain(tmp_path)
    assert report.intact and report.records == report.chained == 12 and report.unchained == 0
    code, out = _verify(tmp_path, capsys)
    assert code == ExitCode.OK and "12 records, the chain is intact" in out


def test_a_rewritten_record_breaks_the_chain_at_the_next_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first = _trail(tmp_path)[0]
    lines = _lines(first)
    doc = json.loads(lines[1])
    doc["command"] = "nothing happened here"
    lines[1] = (json.dumps(doc, separators=(",", ":")) + "\n").encode()
    first.write_bytes(b"".join(lines))
    code, out = _verify(tmp_path, capsys)
    assert code == ExitCode.FAILED
    assert f"chain broken at {first.name} line 3: the chain breaks: the record before it" in out
    assert f"({first.name} line 2) was changed" in out and "BROKEN in 1 place" in out


def test_a_deleted_record_breaks_the_chain_and_is_named(tmp_path: Path) -> None:
    first = _trail(tmp_path)[0]
    lines = _lines(first)
    first.write_bytes(b"".join(lines[:1] + lines[2:]))
    (chain_break,) = verify_chain(tmp_path).breaks
    assert chain_break.line == 2 and "removed before it (seq 1 of session" in chain_break.text


def test_the_chain_runs_across_rotation(tmp_path: Path) -> None:
    files = _trail(tmp_path)
    files[0].write_bytes(b"".join(_lines(files[0])[:-1]))  # the last record of the first file
    (chain_break,) = verify_chain(tmp_path).breaks
    assert chain_break.file == files[1].name and chain_break.line == 1


def test_files_without_hashes_read_as_no_chain_not_broken(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _trail(tmp_path)
    for path in audit_files(tmp_path):  # as an older TeachPad wrote them
        docs = [json.loads(raw) for raw in _lines(path)]
        path.write_text("".join(json.dumps({k: v for k, v in d.items() if k != "prev"}) + "\n" for d in docs))
    report = verify_chain(tmp_path)
    assert report.intact and report.unchained == 12 and report.chained == 0
    code, out = _verify(tmp_path, capsys)
    assert code == ExitCode.OK and "no chain" in out
    # a newer TeachPad carries on from the last of them: the new part is one chain
    with AuditLog(tmp_path) as log:
        log.record("action", "after the update")
    report = verify_chain(tmp_path)
    assert report.intact and report.chained == 1 and report.unchained == 12


def test_the_viewer_says_where_the_chain_breaks(qtbot: Any, tmp_path: Path) -> None:
    from ui.panels.audit_viewer import AuditViewer

    first = _trail(tmp_path)[0]  # written today: in the viewer's default days
    viewer = AuditViewer(tmp_path)
    qtbot.addWidget(viewer)
    assert "chain" not in viewer.status.text()
    lines = _lines(first)
    first.write_bytes(b"".join(lines[:2] + lines[3:]))
    viewer.refresh()
    assert f"The chain of hashes breaks at {first.name} line 3: records before it were removed" in (
        viewer.status.text()
    )

"""``teachpad-cli points upload`` and the controller's boot (issue 19 sections 3 and 4), against the
real simulator: a restart mid-upload reads as a restart (never "uploaded N"), leaves no point at a
wiped zero pose; an interrupted upload resumes with ``--needed`` from its upload record of the same
boot; another boot or another controller voids the record; a save that fails is said after what
was uploaded, with what it means."""

from __future__ import annotations

import errno
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from pymodbus.constants import ExcCodes

from app.cli.exit_codes import ExitCode
from app.points import atomic
from app.points import project as project_module
from app.points.project import load_project
from app.points.upload_record import load_record, record_path
from app.protocol import registers
from app.protocol.codec import registers_to_float
from app.protocol.registers import CANARY_GV, stage_gv_for
from tests.cli.ctrl_c import ROOT, ctrl_c_child, interrupt_cli, untraced_env
from tests.cli.test_cli import run
from tests.waits import CHILD_TIMEOUT, kill_child

N = 30
ZERO = (0.0,) * 6


def _pose(i: int) -> tuple[float, ...]:
    return (300.0 + i, -float(i), 400.0, 180.0, 0.0, float(i % 90))


def _project(sim: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path, n: int = N) -> Path:
    csv = tmp_path / "points.csv"
    header = "id,name,x,y,z,a,b,c,e1,e2,e3,e4,e5,tool,note"
    rows = [f"{i},P{i},{300 + i},{-i},400,180,0,{i % 90},0,0,0,0,0,200," for i in range(1, n + 1)]
    csv.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    project = tmp_path / "cell.teachpad.json"
    code, _, err = run(sim, capsys, "points", "import", str(project), "--csv", str(csv))
    assert code == ExitCode.OK, err
    return project


def _creates(sim: Any, since: int) -> list[int]:
    """The point ids of the create-points written since write ``since`` (GV200, as sent)."""
    params = 2 * registers.GV_PARAM0
    ids: list[int] = []
    for w in sim.writes[since:]:
        if w.address == params:
            ids.append(round(_float(w.values[:2])))
    return ids


def _float(words: tuple[int, ...]) -> float:
    return float(registers_to_float(list(words)))


def _held_right(sim: Any) -> dict[int, tuple[float, ...]]:
    held = dict(sim.state().points)
    assert all(pose == pytest.approx(_pose(i)) for i, pose in held.items()), held
    return held


def test_a_restart_mid_upload_reads_as_a_restart_and_leaves_no_zero_point(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The controller restarts right after the upload staged P10's pose (GV6.., written while P9
    is created): the restart wipes GV0..GV99, so P10 would be created at (0,0,0,0,0,0). The CLI
    sees the canary at 0, says "restarted", does not claim the upload, and the controller holds
    no point at a pose other than the project's. A ``--needed`` re-run sends all again."""
    sim = sim_factory(command_latency=0.02)  # the controller works a while: the poses are staged
    project = _project(sim, capsys, tmp_path)
    stage = 2 * stage_gv_for(CANARY_GV)  # the second pose block's first register
    sim.restart_after_write(stage, 5)  # the 5th staged pose there: P10's (P2, P4, ... P10)
    code, out, err = run(sim, capsys, "--timeout", "1", "points", "upload", str(project))
    assert code == ExitCode.FAILED, (out, err)
    assert "uploaded" not in out, out
    assert "the controller restarted during the upload" in err, err
    assert "it forgot every temp point" in err and "Upload the 30 again" in err
    assert "not sent after it: P" in err and "stopped without" not in err
    held = _held_right(sim)  # no point at zeros: each one the controller holds is at its own pose
    assert ZERO not in held.values()
    assert held and max(held) < N  # only points after the restart, the rest not sent
    record = load_record(record_path(project))
    assert record is not None and record.points == {} and record.identity.boot is None  # void
    # the re-run sends every point: the restart voided the record
    since = len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    assert sorted(_creates(sim, since)) == list(range(1, N + 1))
    assert "already on the controller" not in out
    assert sorted(_held_right(sim)) == list(range(1, N + 1))


def test_the_points_sent_around_a_restart_go_again_through_the_upload_driver(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The points sent around a restart are created again the way every upload goes (the one
    upload driver, :mod:`app.link.upload_driver`): a point the controller refuses is that point's
    only, the next ones of its tool frame still go out on the new boot. (The CLI's own repair sent
    each tool frame in one call: after P12's refusal the rest of the frame was never created
    again, and the CLI counted them all "refused".) Seen at the simulator: the create points after
    the repair's fresh token."""
    sim = sim_factory(command_latency=0.02)  # the controller works a while: the poses are staged
    project = _project(sim, capsys, tmp_path)
    sim.restart_after_write(2 * stage_gv_for(CANARY_GV), 5)  # as above: P10's staged pose is wiped
    sim.refuse_point_write(12, times=1000)  # the controller refuses P12, in the upload and again after
    code, out, err = run(sim, capsys, "--timeout", "1", "points", "upload", str(project))
    assert code == ExitCode.FAILED, (out, err)
    assert "the controller restarted during the upload" in err, err
    found = re.search(r"; ((?:P\d+,)*P\d+), sent around it, were created again after it: ", err)
    assert found is not None, err
    suspects = [int(p[1:]) for p in found.group(1).split(",")]
    assert 12 in suspects and suspects[-1] > 12, suspects  # P12 refused with others after it
    assert "(1 refused; the others may be at wrong poses on the controller)" in err, err
    canary = 2 * CANARY_GV  # the repair's fresh token for the new boot: its last write
    fresh = max(i for i, w in enumerate(sim.writes) if w.address <= canary < w.address + len(w.values))
    again = _creates(sim, fresh)
    assert again == [p for p in suspects if p != 12], (again, suspects)  # in order, each once
    held = _held_right(sim)
    assert set(suspects) - {12} <= set(held) and 12 not in held


def _repairing(sim: Any) -> bool:
    """The points sent around a restart are being created again: a create point went out after
    the repair's fresh token (the run's second write of the canary: the first armed the boot)."""
    canary = 2 * CANARY_GV
    tokens = [i for i, w in enumerate(list(sim.writes)) if w.address <= canary < w.address + len(w.values)]
    return len(tokens) >= 2 and bool(_creates(sim, tokens[1]))


def test_ctrl_c_while_the_points_sent_around_a_restart_go_again(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Ctrl-C while the points sent around a restart are created again is the upload driver's
    Ctrl-C, as in any upload: what was done is kept and said -- the restart, the points created
    again before it -- the upload record of the old boot is void, exit 130. (The CLI's own repair
    let the KeyboardInterrupt out: a bare "interrupted", the restart unsaid.)"""
    sim = sim_factory(command_latency=0.3)  # each point a while: Ctrl-C lands during the repair
    project = _project(sim, capsys, tmp_path)
    sim.restart_after_write(2 * stage_gv_for(CANARY_GV), 5)  # as above: P10's staged pose is wiped
    code, err = interrupt_cli(sim, ["points", "upload", str(project)], lambda _s: _repairing(sim))
    assert code == ExitCode.INTERRUPTED, err
    assert "the controller restarted during the upload" in err, err
    found = re.search(
        r"; ((?:P\d+,)*P\d+), sent around it, were created again after it: ((?:P\d+,)*P\d+|none) "
        r"\(interrupted; the others may be at wrong poses on the controller\)",
        err,
    )
    assert found is not None and "Traceback" not in err, err
    suspects, again = (set(re.findall(r"P(\d+)", group)) for group in found.groups())
    assert again <= suspects, (again, suspects)
    # at the simulator: a point at a wrong pose (the wiped one) is one the CLI did not say it made again
    wrong = {str(i) for i, pose in sim.state().points.items() if pose != pytest.approx(_pose(i))}
    assert wrong <= suspects - again, (wrong, suspects, again)
    record = load_record(record_path(project))
    assert record is not None and record.points == {} and record.identity.boot is None  # void


def test_an_interrupted_upload_resumes_from_its_record_and_another_boot_sends_all(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """Ctrl-C mid-upload keeps the upload record of that boot; ``--needed`` then sends only what
    the record does not hold (the loaded project's points are all *unknown*, the record knows),
    a point edited since is sent again, and after a restart (another boot) everything is."""
    sim = sim_factory(command_latency=0.05)
    project = _project(sim, capsys, tmp_path)
    code, err = interrupt_cli(sim, ["points", "upload", str(project)], lambda s: len(s.points) >= 12)
    assert code == ExitCode.INTERRUPTED, err
    record = load_record(record_path(project))
    assert record is not None and record.identity.boot
    kept = sorted(record.points)
    assert len(kept) >= 8 and set(kept) <= set(_held_right(sim))  # confirmed: on the controller
    # edit one confirmed point in the project: it is not the one the controller holds any more
    text = project.read_text(encoding="utf-8").replace('"x": 301.0', '"x": 311.0')
    project.write_text(text, encoding="utf-8")
    since = len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    sent = _creates(sim, since)
    assert sorted(sent) == sorted({1} | set(range(1, N + 1)) - set(kept)), (sent, kept)
    assert f"{len(kept) - 1} point(s) already on the controller" in out
    assert sim.state().points[1] == pytest.approx((311.0, -1.0, 400.0, 180.0, 0.0, 1.0))
    assert len(sim.state().points) == N
    record = load_record(record_path(project))
    assert record is not None and sorted(record.points) == list(range(1, N + 1))
    # nothing left: --needed sends nothing
    since = len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert (code, _creates(sim, since)) == (ExitCode.OK, []), err
    assert "nothing to upload" in out
    # a restart between two runs: another boot, the record is void, everything is sent
    sim.restart_controller()
    since = len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    assert sorted(_creates(sim, since)) == list(range(1, N + 1))


def test_another_controller_does_not_resume_the_record(
    sim_factory: Any, make_client: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """The record names its controller (endpoint, unit, word order, canary token): a second
    controller, even one whose canary holds the same token, gets every point."""
    first, second = sim_factory(command_latency=0.0), sim_factory(command_latency=0.0)
    project = _project(first, capsys, tmp_path, 6)
    code, _, err = run(first, capsys, "points", "upload", str(project))
    assert code == ExitCode.OK, err
    record = load_record(record_path(project))
    assert record is not None and sorted(record.points) == list(range(1, 7)) and record.identity.boot
    make_client(second).write_gv(CANARY_GV, [record.identity.boot])  # the same token, by chance
    since = len(second.writes)
    code, out, err = run(second, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    assert sorted(_creates(second, since)) == list(range(1, 7))
    assert "already on the controller" not in out


def test_a_full_disk_is_said_after_what_was_uploaded_and_what_it_means(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The project and its upload record cannot be written (ENOSPC): the points are on the
    controller and the CLI says so first, then that nothing of it was saved and what that means;
    nothing is said as done before the saves were tried; exit 1 (a file that cannot be written)."""
    sim = sim_factory(command_latency=0.0)
    project = _project(sim, capsys, tmp_path, 10)
    before = project.read_bytes()

    def full(path: str | os.PathLike[str], data: bytes, *, mode: int | None = None) -> None:
        print("<saving>", file=sys.stdout, flush=True)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setattr(atomic, "atomic_write_bytes", full)  # the upload record's writer
    monkeypatch.setattr(project_module, "atomic_write_bytes", full)  # the project's
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    monkeypatch.undo()
    assert code == ExitCode.FAILED
    assert len(sim.state().points) == 10
    # the saves first, then the account: what was uploaded, then what was (not) kept
    assert out.index("<saving>") < out.index("uploaded 10 point(s)"), out
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    said = lines[0]
    assert said.startswith("teachpad-cli: error: ") and "No space left on device" in said
    assert "The 10 point(s) uploaded are on the controller" in said
    assert "the project file is as it was before this upload" in said
    assert "the upload record could not be kept either" in said and "--needed will send them again" in said
    assert project.read_bytes() == before and load_project(project).upload_history == {}


def test_a_controller_that_refuses_the_canary_gets_the_upload_without_a_record(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """GV99 refused (a Modbus exception): the points are uploaded all the same, the CLI says a
    restart would go unseen, and no upload record is kept (nothing proves what the controller holds)."""
    sim = sim_factory(command_latency=0.0)
    project = _project(sim, capsys, tmp_path, 5)
    sim.set_exception(ExcCodes.ILLEGAL_ADDRESS, range(2 * CANARY_GV, 2 * CANARY_GV + 2))
    code, out, err = run(sim, capsys, "points", "upload", str(project))
    assert code == ExitCode.OK, err
    assert "uploaded 5 point(s)" in out and len(_held_right(sim)) == 5
    assert "the restart canary GV99 cannot be used" in err and "no upload record was kept" in err
    assert not record_path(project).exists()


def test_a_malformed_record_is_not_trusted(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    sim = sim_factory(command_latency=0.0)
    project = _project(sim, capsys, tmp_path, 4)
    record_path(project).write_text('{"format": "teachpad-upload-record", "version": 1}', encoding="utf-8")
    since = len(sim.writes)
    code, _, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    assert "not a TeachPad upload record" in err and "it is not used (every point is sent)" in err
    assert "Traceback" not in err and sorted(_creates(sim, since)) == [1, 2, 3, 4]
    record = load_record(record_path(project))  # replaced by a good one
    assert record is not None and sorted(record.points) == [1, 2, 3, 4]


def test_a_killed_upload_resumes_from_the_record_written_while_it_ran(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """kill -9 mid-upload: the record written while it ran (every UPLOAD_RECORD_PERIOD) holds
    only points the controller holds at their poses, and ``--needed`` sends the rest."""
    n = 80
    sim = sim_factory(command_latency=0.05)
    project = _project(sim, capsys, tmp_path, n)
    where = record_path(project)
    proc = subprocess.Popen(
        ctrl_c_child(sim.port, ["points", "upload", str(project)]),
        cwd=ROOT,
        env=untraced_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        assert sim.wait_for(lambda s: where.exists() and len(s.points) >= 24, CHILD_TIMEOUT)
        proc.kill()
    finally:
        kill_child(proc)
    record = load_record(where)
    assert record is not None and record.identity.boot
    kept = set(record.points)
    held = _held_right(sim)
    assert len(kept) >= 8 and kept <= set(held) and len(held) < n, (sorted(kept), len(held))
    since = len(sim.writes)
    code, out, err = run(sim, capsys, "points", "upload", str(project), "--needed")
    assert code == ExitCode.OK, err
    assert sorted(_creates(sim, since)) == sorted(set(range(1, n + 1)) - kept)
    assert f"{len(kept)} point(s) already on the controller" in out
    assert sorted(_held_right(sim)) == list(range(1, n + 1))

"""The session the GUI uses: roles enforced and audited, steps and jogs refused before the wire."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.link.types import StepFrame
from app.protocol.enums import TeachFrame
from app.safety.audit import AuditLog
from app.safety.audit_read import Result, read_records
from app.safety.box import Box
from app.safety.envelope import Envelope, EnvelopeRefused, ViolationCode
from app.safety.jog_guard import JogMotion
from app.safety.roles import Action, IdleLock, Role, RoleStore, WrongPassword
from app.safety.session import PermissionRefused, SafetySession


@pytest.fixture
def session(tmp_path: Path) -> SafetySession:
    store = RoleStore(tmp_path / "roles.json", scrypt_n=2**8)
    store.set_password(Role.ADMINISTRATOR, "admin-pw", by=Role.ADMINISTRATOR)
    store.set_password(Role.ENGINEER, "eng-pw", by=Role.ADMINISTRATOR)
    now = [0.0]
    s = SafetySession(store, AuditLog(tmp_path / "audit"), idle_lock=IdleLock(60.0, clock=lambda: now[0]))
    s.clock = now  # type: ignore[attr-defined]
    return s


def test_an_operator_cannot_change_the_connection_and_the_refusal_is_audited(
    session: SafetySession, tmp_path: Path
) -> None:
    assert session.reason(Action.CONNECTION) == (
        "change connection: needs the administrator role (logged in as operator)"
    )
    with pytest.raises(PermissionRefused, match="needs the administrator role"):
        session.require(Action.CONNECTION, {"host": "10.0.0.9"})
    with pytest.raises(WrongPassword):
        session.login(Role.ADMINISTRATOR, "guess")
    session.login(Role.ADMINISTRATOR, "admin-pw")
    session.require(Action.CONNECTION)
    session.clock[0] = 61.0  # type: ignore[attr-defined]
    assert session.poll_idle() is Role.OPERATOR
    session.audit.close()
    recs = [(r.kind, r.command, r.role, r.result) for r in read_records(tmp_path / "audit")]
    assert recs == [
        ("refused", "change connection", "operator", Result.REFUSED),
        ("login", "log in as administrator", "operator", Result.REFUSED),
        ("login", "log in as administrator", "administrator", Result.OK),
        ("login", "locked back to operator after 60 s idle", "administrator", Result.OK),
    ]


def test_reduced_mode_on_for_anyone_off_for_an_engineer(session: SafetySession) -> None:
    session.envelope = Envelope(max_jog_ratio=80, reduced_jog_ratio=10)
    session.set_reduced(True)
    assert session.jog_ratio(50) == 10
    with pytest.raises(PermissionRefused):
        session.set_reduced(False)
    session.login(Role.ENGINEER, "eng-pw")
    session.set_reduced(False)
    assert session.jog_ratio(90) == 80


def test_a_step_out_of_the_envelope_never_reaches_the_controller(
    session: SafetySession, sim: Any, make_client: Any, tmp_path: Path
) -> None:
    client = make_client(sim)
    pose = client.read_pose()
    session.envelope = Envelope(keep_in=Box("cell", (-1000, pose.y - 50, -1000), (1000, 1000, 1000)))

    def guarded_step(offsets: list[float]) -> None:  # what the GUI's step controller does
        now = client.read_pose()
        session.check_step(now, offsets, joint=False, speed=50.0)
        client.step(StepFrame.BASE, offsets, speed=50.0)

    with pytest.raises(EnvelopeRefused, match=r"^step refused: Y = .* outside the allowed work") as info:
        guarded_step([0, -80, 0, 0, 0, 0])
    assert info.value.violation.code is ViolationCode.KEEP_IN
    assert sim.writes == []  # nothing was sent
    guarded_step([0, -30, 0, 0, 0, 0])
    assert sim.state().pose[1] == pytest.approx(pose.y - 30, abs=0.5)
    # 20 mm from the edge; at 250 mm/s a 0.1 s poll (+ latency) needs 38.5 mm
    with pytest.raises(EnvelopeRefused, match=r"^jog refused: .*within stopping distance"):
        session.check_jog_start(client.read_pose(), JogMotion(TeachFrame.BASE, 1, 0, 100.0), poll_period=0.1)
    session.audit.close()
    refused = [r for r in read_records(tmp_path / "audit") if r.result == Result.REFUSED]
    assert [r.command for r in refused] == ["step", "jog"] and refused[0].args["offsets"][1] == -80

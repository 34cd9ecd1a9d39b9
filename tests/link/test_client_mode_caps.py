"""The client's two guards of issue 18, at the simulator's write log: a controller in manual mode
is switched to auto only when the caller was allowed to (go to zero, run program), as its own
audited write; reduced-speed caps bound every speed the client writes."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from app.errors import ManualModeRefused, ReducedSpeedRefused
from app.link.client import RobotClient
from app.link.types import StepFrame
from app.protocol import registers
from app.protocol.codec import WordOrder, registers_to_float
from app.protocol.enums import TeachFrame, WorkMode
from app.safety.audit import AuditLog
from app.safety.audit_read import query
from app.safety.caps import MotionCaps

MakeClient = Any
CAPS = MotionCaps(ratio=10.0, speed=250.0, reach=1000.0)


def gv_values(sim: Any, gv: int) -> list[float]:
    low = registers.gv_reg(gv)
    return [
        registers_to_float(list(w.values[low - w.address : low - w.address + 2]), WordOrder.LOW_FIRST)
        for w in sim.writes
        if low - w.address >= 0 and low - w.address + 2 <= len(w.values)
    ]


@pytest.mark.parametrize("operation", ["go to zero", "run program"])
def test_manual_mode_is_refused_audited_and_nothing_written(
    sim_factory: Any, make_client: MakeClient, tmp_path: Path, operation: str
) -> None:
    sim = sim_factory(work_mode=WorkMode.MANUAL)
    client: RobotClient = make_client(sim)
    client.audit = AuditLog(tmp_path)
    refused = f"^{operation} refused: the controller is in manual mode"
    with pytest.raises(ManualModeRefused, match=refused) as info:
        if operation == "go to zero":
            client.go_zero(None)
        else:
            client.run_program(2)
    assert info.value.params == {"operation": operation, "mode": 0}
    assert sim.writes == [] and sim.state().work_mode is WorkMode.MANUAL
    client.audit.close()
    [record] = query(tmp_path)
    assert (record.kind, record.command, record.result) == ("refused", operation, "refused")


def test_an_allowed_switch_is_its_own_write_before_the_command(
    sim_factory: Any, make_client: MakeClient, tmp_path: Path
) -> None:
    sim = sim_factory(work_mode=WorkMode.MANUAL)
    client: RobotClient = make_client(sim)
    client.audit = AuditLog(tmp_path)
    client.go_zero(1, switch_to_auto=True)
    assert [(w.address, w.values) for w in sim.writes] == [(444, (1,)), (445, (1,))]
    client.audit.close()
    writes = [r for r in query(tmp_path) if r.kind == "write"]
    assert [r.args["address"] for r in writes] == [444, 445]  # two records: the mode change is audited
    # the mode change is a plain write (answered: ok); the go to zero awaits its outcome (not followed here)
    assert "work mode" in writes[0].command and writes[0].result == "ok"


def test_auto_mode_needs_no_switch(sim: Any, make_client: MakeClient) -> None:
    client: RobotClient = make_client(sim)
    client.go_zero(1)  # auto already: no 444
    assert [w.address for w in sim.writes] == [445]


def test_reduced_speed_caps_every_speed_written(sim: Any, make_client: MakeClient) -> None:
    client: RobotClient = make_client(sim)
    client.caps = CAPS
    client.run_program(2, speed_ratio=100)
    assert sim.writes[-2].address == registers.REG_PROGRAM_ID and sim.writes[-2].values[3] == 10
    client.stop()
    assert sim.wait_for(lambda s: not s.moving, 5.0)
    client.step(StepFrame.BASE, [0, 0, -5, 0, 0, 0], speed=800)
    client.step(StepFrame.JOINT, [2, 0, 0, 0, 0, 0], speed=5)
    client.step(StepFrame.JOINT, [2, -2, 1, 0, 0, 0], speed=5)
    x, y, z, a, b, c = client.read_pose().xyzabc
    client.create_point(3, pose=[x, y, z - 20, a, b, c])
    client.move_to_point(3, speed=800)  # a plan's segment, the points table's Move to point, the CLI's move
    assert gv_values(sim, registers.GV_EXPECTED_SPEED) == pytest.approx(
        [250.0, CAPS.joint_rpm_cap, CAPS.joint_rpm_cap / 2.5, 250.0], rel=1e-6
    )
    client.teach_enable(TeachFrame.BASE, 2, 0)
    client.teach_set_ratio(60)
    client.teach_set_ratio(0)
    client.teach_disable()
    assert gv_values(sim, registers.GV_PARAM3)[-4:-1] == [0.0, 10.0, 0.0]  # enable, the jog, its stop
    n = len(sim.writes)
    with pytest.raises(ReducedSpeedRefused, match="go to zero refused in reduced-speed mode"):
        client.go_zero(None)
    assert len(sim.writes) == n

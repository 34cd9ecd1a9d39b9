"""``teachpad-cli status`` says when the controller's floats look word-swapped, and what to set
(issue 21): the simulator writing high word first, read low word first -> a warning on stderr and
``word_order_warning`` in the JSON; read in its own order -> nothing, at its start pose and at the
zero pose."""

from __future__ import annotations

import json
from typing import Any

import pytest

from app.cli.exit_codes import ExitCode
from tests.cli.test_cli import ROOMY_POLL, run

pytestmark = pytest.mark.timeout(60)


def test_status_says_the_floats_look_word_swapped(
    sim_factory: Any, capsys: pytest.CaptureFixture[str]
) -> None:
    sim = sim_factory(word_order="high-first")
    code, out, err = run(sim, capsys, *ROOMY_POLL, "--word-order", "low-first", "status")
    assert code == ExitCode.OK
    assert err.startswith("teachpad-cli: warning: the controller's floats look word-swapped"), err
    assert "--word-order high-first" in err and len(err.strip().splitlines()) == 1
    code, out, err = run(sim, capsys, *ROOMY_POLL, "--word-order", "low-first", "status", "--json")
    said = json.loads(out)["word_order_warning"]
    assert said["suggested"] == "high-first" and "word-swapped" in said["message"]
    # read in its own order: nothing said
    code, out, err = run(sim, capsys, *ROOMY_POLL, "--word-order", "high-first", "status", "--json")
    assert code == ExitCode.OK and err == "" and json.loads(out)["word_order_warning"] is None


@pytest.mark.parametrize("order", ["low-first", "high-first"])
def test_the_right_word_order_is_quiet_at_the_start_and_the_zero_pose(
    sim_factory: Any, capsys: pytest.CaptureFixture[str], order: str
) -> None:
    sim = sim_factory(word_order=order)
    code, out, err = run(sim, capsys, *ROOMY_POLL, "--word-order", order, "status")
    assert code == ExitCode.OK and err == ""
    for axis in range(1, 12):
        sim.set_joint(axis, 0.0)  # the zero pose
    code, out, err = run(sim, capsys, *ROOMY_POLL, "--word-order", order, "status", "--json")
    assert code == ExitCode.OK and err == "" and json.loads(out)["word_order_warning"] is None
    assert json.loads(out)["joints"] == [0.0] * 6

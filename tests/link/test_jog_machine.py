"""The jog state machine and its dead-man, as the simulator sees it (no Qt)."""

from __future__ import annotations

from typing import Any

import pytest

from app.errors import LinkError, TeachPadError
from app.link.jog import PreemptedError
from app.link.types import JogRequest, LinkState
from app.protocol.enums import TeachFrame
from tests.link.harness import PartsHost
from tests.ui.pendant_support import ratio_writes, register_writes


def _press(axis: int = 0, ratio: float = 30.0, frame: TeachFrame = TeachFrame.BASE) -> JogRequest:
    return JogRequest(frame, axis, 1, ratio)


def test_press_enables_teach_then_writes_the_ratio_and_release_writes_zero(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    host.jog.press(_press())
    assert sim.wait_for(lambda s: s.jogging and s.teach_ratio == 30.0)
    assert [v for _, v in register_writes(sim, 440)] == [0x80]
    host.jog.release()
    assert ratio_writes(sim)[-1] == 0.0 and sim.state().teach_enabled  # teach stays on
    host.jog.press(_press(axis=2, ratio=20.0))  # same frame, other axis: no new enable
    assert [v for _, v in register_writes(sim, 440)] == [0x80]
    assert sim.wait_for(lambda s: s.jogging and s.teach_ratio == 20.0)


def test_a_release_during_the_enable_ends_the_sequence_before_the_ratio(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    host.urgent.append(host.jog.release)  # arrives while teach enable is being awaited
    with pytest.raises(PreemptedError):
        host.jog.press(_press())
    assert all(v == 0.0 for v in ratio_writes(sim))
    assert not sim.state().jogging


def test_silence_drops_the_jog_and_ratio_zero_goes_out_first_on_return(host: PartsHost, sim: Any) -> None:
    sim.set_watchdog(None)  # a controller without a watchdog: the resync closes the jog's connection
    host.connect(sim, poll_timeout=0.3)
    host.jog.press(_press())
    assert sim.wait_for(lambda s: s.jogging)
    sim.set_silent(True)
    host.poll()
    assert host.states()[-1] is LinkState.NOT_ANSWERING
    assert host.jog.jog is None
    assert any("jog stopped" in e.message for e in host.of("errorOccurred"))
    with pytest.raises(TeachPadError, match="not answering") as refused:  # no new jog while silent
        host.jog.press(_press())
    assert not isinstance(refused.value, LinkError)  # refused before the wire: no link failure
    assert sim.state().jogging  # the controller keeps going until it hears us
    writes_before = len(sim.writes)
    sim.set_silent(False)
    host.poll_until_answered()
    first = sim.writes[writes_before]
    assert first.address == 406 and first.values == (0, 0)  # GV203 = 0.0: the first write back
    assert not sim.state().jogging
    assert host.states()[-1] is LinkState.CONNECTED


def test_idle_teach_is_disabled_after_the_idle_time(
    host: PartsHost, sim: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    from app import timing

    monkeypatch.setattr(timing, "TEACH_IDLE_DISABLE", 0.0)
    host.connect(sim)
    host.jog.press(_press())
    host.jog.release()
    host.poll()
    assert not sim.state().teach_enabled
    assert [v for _, v in register_writes(sim, 440)] == [0x80, 0x81]

"""The link supervisor: connect, backoff, link loss, the restart canary (no Qt)."""

from __future__ import annotations

from typing import Any

import pytest

from app import timing
from app.link.capture import TrafficCapture
from app.link.supervisor import LinkSupervisor, check_canary_gv
from app.link.types import ControllerIdentity, LinkState
from tests.link.harness import PartsHost


def test_connect_publishes_state_pose_and_status_then_polls(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    assert host.states() == [LinkState.CONNECTING, LinkState.CONNECTED]
    assert {"poseChanged", "statusChanged"} <= set(host.names()) and host.polling
    assert sim.writes == []  # canary off: connecting never writes


def test_unreachable_backs_off(sim_factory: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(timing, "RECONNECT_BACKOFF", (0.1, 0.2))
    sim = sim_factory()
    port = sim.port
    sim.stop()
    parts = PartsHost()
    from app.connection import ConnectionSettings

    parts.connect_to(ConnectionSettings(host="127.0.0.1", port=port, timeout=0.2))
    for _ in range(2):
        parts.try_connect()
    assert parts.states() == [LinkState.CONNECTING, LinkState.DOWN]
    assert parts.reconnect_delays == [0.1, 0.2, 0.2]  # the last delay repeats
    parts.close()


def test_transport_failures_in_a_row_take_the_link_down_and_fail_the_queue(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    for _ in range(timing.LINK_LOSS_POLLS - 1):
        host.link_failed("reset")
    assert host.link_up
    host.link_failed("reset")
    assert not host.link_up and host.states()[-1] is LinkState.DOWN
    assert host.of("failQueued") == ["the link to the controller is down: not sent"]


def test_reconnect_after_a_loss_says_reconnected(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    host.link_lost("test")
    host.try_connect()
    assert host.states()[-2:] == [LinkState.DOWN, LinkState.CONNECTED]
    assert host.names().count("controllerReconnected") == 1


def test_the_canary_notices_a_restart(sim: Any) -> None:
    parts = PartsHost(canary_gv=99)
    try:
        parts.connect(sim)
        token = parts.supervisor.canary_token
        assert token is not None
        parts.supervisor.canary_read(token)
        assert "controllerRestarted" not in parts.names()
        parts.supervisor.canary_read(0.0)
        assert parts.names().count("controllerRestarted") == 1
        assert parts.supervisor.canary_token not in (None, token)  # armed again
    finally:
        parts.close()


def test_the_canary_must_be_a_spare_gv() -> None:
    with pytest.raises(ValueError, match=r"GV0\.\.GV5"):
        check_canary_gv(3)
    with pytest.raises(ValueError):
        LinkSupervisor(PartsHost(), 2, capture=TrafficCapture())


# --- which controller, which boot (issue 18) -----------------------------------------------------


def _controller(parts: PartsHost) -> ControllerIdentity:
    identity = parts.of("connectionChanged")[-1].controller
    assert isinstance(identity, ControllerIdentity)
    return identity


def test_every_connect_says_which_controller_and_which_boot(sim_factory: Any) -> None:
    first, second = sim_factory(), sim_factory()
    parts = PartsHost(canary_gv=99)
    try:
        parts.connect(first)
        one = _controller(parts)
        assert (one.endpoint, one.unit, one.canary_gv) == (f"127.0.0.1:{first.port}", 1, 99)
        assert one.boot == parts.supervisor.canary_token and one.boot is not None
        # lost and back, the same boot: the canary still holds our token (read, never written again)
        canary_writes = len(first.writes_to(198))
        parts.link_lost("test")
        assert parts.of("connectionChanged")[-1].controller is None  # not connected: no controller
        parts.try_connect()
        assert _controller(parts).same_boot(one) and len(first.writes_to(198)) == canary_writes
        # restarted while the link was down: the same place, another boot (a new token written)
        parts.link_lost("test")
        first.restart_controller()
        parts.try_connect()
        restarted = _controller(parts)
        assert restarted.same_place(one) and not restarted.same_boot(one)
        assert len(first.writes_to(198)) == canary_writes + 1
        # Connect… to another controller: another place
        parts.connect(second)
        other = _controller(parts)
        assert not other.same_place(restarted) and not other.same_boot(restarted)
    finally:
        parts.close()


def test_a_restart_under_a_live_link_is_a_new_identity_published_before_the_restart(sim: Any) -> None:
    parts = PartsHost(canary_gv=99)
    try:
        parts.connect(sim)
        one = _controller(parts)
        parts.supervisor.canary_read(0.0)  # the canary reads wiped: the controller restarted
        names = parts.names()
        last_state = len(names) - 1 - names[::-1].index("connectionChanged")
        assert last_state < names.index("controllerRestarted")
        assert not _controller(parts).same_boot(one) and _controller(parts).same_place(one)
    finally:
        parts.close()


def test_without_a_canary_no_two_connections_are_the_same_boot(host: PartsHost, sim: Any) -> None:
    host.connect(sim)
    identity = _controller(host)
    assert identity.boot is None and not identity.same_boot(identity)
    assert sim.writes == []  # and nothing is written to tell

"""One controller's poller for the gateway: its own thread, client, timeouts and backoff.

Monitor-only unless the plant may write to the controller: the :class:`~app.link.client.RobotClient`
is made with ``monitor_only=True`` (the one write guard refuses every write); with plant writes
enabled in the cell file it is writable, audited, and its :class:`~app.gateway.plant.PlantWriter`
makes the plant's commands between two polls (:mod:`app.gateway.plant`). The poller reads the
status block (with the clock every :attr:`GatewayTiming.clock_period`), then the pose block.

**When a controller is dead** (the rule behind the gateway's DDEATH): when it has not answered for
:attr:`GatewayTiming.death_after` (0.2 s, :data:`app.timing.GATEWAY_DEATH_AFTER`) since its *last
answer* -- not when one request outlived the poll timeout. Each read waits for its answer until
that moment, so an answer that comes late (a busy PC, a loaded controller) is still taken and the
controller stays alive; a request the gateway itself sent late (its own thread late to run) still
gets half the window. So a controller that goes silent (SIGSTOP, unplugged) is dead at most
``death_after`` after its last answer, within the issue's 250 ms of silence with room for the
DDEATH's way to the broker; one that answers, however late, within the window is never dead. The
window is never shorter than the poll timeout (``settings.effective_poll_timeout``: 0.15 s over
TCP, by baud over RTU: a slow serial line's answers take that long on the wire). A controller that
is not alive (before its first answer, after its death) gets the whole window per read.

A poll that fails (the window ran out, a refused or lost connection, a malformed answer) is reported
at once (:meth:`DeviceListener.silent`), and the next tries come after :attr:`GatewayTiming.backoff`;
a dead controller costs the others nothing (each has its own thread and link).
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from dataclasses import dataclass, field
from typing import Protocol

from app import timing
from app.cell.cell_file import CellController
from app.errors import ResponseTimeout, TeachPadError
from app.gateway.metrics import Reading
from app.gateway.plant import PlantWriter
from app.link.client import RobotClient
from app.protocol.datetime_regs import ControllerClock

__all__ = ["ControllerPoller", "DeviceListener", "GatewayTiming"]

_log = logging.getLogger(__name__)


def _backoff() -> tuple[float, ...]:
    return timing.GATEWAY_RECONNECT_BACKOFF


@dataclass(frozen=True)
class GatewayTiming:
    """The gateway's clocks (defaults: :mod:`app.timing`, read when made; tests pass shorter ones)."""

    poll_hz: float = field(default_factory=lambda: timing.GATEWAY_POLL_HZ)
    poll_timeout: float | None = None  # s; None: the connection's (0.15 s over TCP, by baud over RTU)
    backoff: tuple[float, ...] = field(default_factory=_backoff)
    keepalive: int = field(default_factory=lambda: timing.GATEWAY_KEEPALIVE)
    broker_retry: tuple[int, int] = field(default_factory=lambda: timing.GATEWAY_BROKER_RETRY)
    clock_period: float = field(default_factory=lambda: timing.GATEWAY_CLOCK_PERIOD)
    death_after: float = field(default_factory=lambda: timing.GATEWAY_DEATH_AFTER)  # s of silence: dead
    stop_wait: float = field(default_factory=lambda: timing.GATEWAY_STOP_WAIT)


class DeviceListener(Protocol):
    """What the poller tells (from its own thread)."""

    def answered(self, device: str, reading: Reading) -> None: ...

    def silent(self, device: str, reason: str) -> None: ...


class ControllerPoller:
    """Polls one controller until :meth:`stop`; tells ``listener`` every answer and every failure."""

    def __init__(
        self,
        controller: CellController,
        listener: DeviceListener,
        gateway: GatewayTiming,
        writer: PlantWriter | None = None,
    ) -> None:
        self.name = controller.name
        # monitor-only (the write guard refuses every write) unless the plant may write to it
        self.writer = writer if writer is not None and writer.enabled else None
        settings = controller.settings(monitor_only=self.writer is None)
        if gateway.poll_timeout is not None:
            settings = dataclasses.replace(settings, poll_timeout=gateway.poll_timeout)
        self._client = RobotClient(settings)
        if self.writer is not None:
            self._client.audit = self.writer.audit  # every write recorded, as the pendant's
            self._client.watch_shared_every = timing.CLOCK_POLL_PERIOD  # another master's writes
        self._listener = listener
        self._timing = gateway
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name=f"gateway-poll-{self.name}", daemon=True)
        self.errors = 0  # failed polls since the start
        self._failures = 0  # failed polls in a row
        self._next_clock = 0.0
        self._answered_at: float | None = None  # monotonic time of its last answer (None: not alive)
        self._window = max(gateway.death_after, settings.effective_poll_timeout)

    def start(self) -> None:
        self._thread.start()

    def request_stop(self) -> None:
        """Ask the thread to end after its current poll, without waiting (then :meth:`stop`)."""
        self._stop.set()

    def stop(self) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()

    def _run(self) -> None:
        period = 1.0 / self._timing.poll_hz
        next_poll = time.monotonic()
        try:
            while not self._stop.is_set():
                if self.poll_once():
                    next_poll += period
                    now = time.monotonic()
                    if next_poll < now - period:  # late by more than a period: no burst to catch up
                        next_poll = now
                else:
                    steps = self._timing.backoff
                    next_poll = time.monotonic() + steps[min(self._failures, len(steps)) - 1]
                self._stop.wait(max(0.0, next_poll - time.monotonic()))
        finally:
            self._client.close()

    def poll_once(self) -> bool:
        """One poll; False when it failed (told to the listener as silence)."""
        client = self._client
        try:
            if not client.connected:
                client.connect()
                if self.writer is not None:
                    client.watch_shared_baseline()  # another master's writes are told from here on
            clock = self._read(client)
        except TeachPadError as exc:
            self.errors += 1
            self._failures += 1
            reason = str(exc)
            if isinstance(exc, ResponseTimeout) and self._answered_at is not None:
                silent_ms = (time.monotonic() - self._answered_at) * 1000.0
                reason = f"no answer for {silent_ms:.0f} ms since its last one ({reason})"
            self._answered_at = None
            _log.info("%s: poll failed: %s", self.name, reason)
            self._listener.silent(self.name, reason)
            return False
        self._failures = 0
        if clock is not None:
            self._next_clock = time.monotonic() + self._timing.clock_period
        return True

    def _timeout(self) -> float:
        """How long the next request may wait for its answer (the module's rule): until the
        controller has been silent the death window since its last answer, at least half the
        window; the whole window while it is not alive (nothing to tell in time then)."""
        last, window = self._answered_at, self._window
        if last is None:
            return window
        return max(last + window - time.monotonic(), window / 2)

    def _read(self, client: RobotClient) -> ControllerClock | None:
        with_clock = time.monotonic() >= self._next_clock
        t0 = time.perf_counter()
        status = client.read_status(with_clock=with_clock, timeout=self._timeout())
        rtt_ms = (time.perf_counter() - t0) * 1000.0
        self._answered_at = time.monotonic()
        pose = client.read_pose(timeout=self._timeout())
        answered_at = self._answered_at = time.monotonic()
        reading = Reading(
            pose=pose,
            status=status,
            clock=status.clock,
            rtt_ms=rtt_ms,
            errors=self.errors,
            answered_at=answered_at,
            wall_ms=int(time.time() * 1000),
        )
        self._listener.answered(self.name, reading)
        if self.writer is not None:
            self.writer.after_poll(client, status, pose)
            # a plant command's status reads are answers too: its writes' time is no silence
            self._answered_at = max(answered_at, client.status_read_at)
        return status.clock

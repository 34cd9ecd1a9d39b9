"""An operation's progress as data: what the link reports of a request before its one result.

The worker publishes each report with the ticket of the request it belongs to (the request id
``RobotLink.submit(op)`` returned): ``RobotLink.progressed(ticket, report)`` carries every one,
and ``link.track(ticket).progressed(report)`` only that request's -- so a panel, a controller or a
script that submitted an upload hears its own upload's points and progress, never another's.

:class:`~app.link.ops.UploadPoints` reports a :class:`PointUploaded` per point, in order, and
:class:`UploadProgress` (points tried, total) at most every
:data:`app.timing.UPLOAD_PROGRESS_PERIOD`, the first (0) and the last always; then its result.
:class:`~app.link.ops.ReadRegisters` reports what it read (:class:`RegisterBlocks`), once, before
its result.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

__all__ = ["PointUploaded", "Progress", "RegisterBlocks", "UploadProgress"]


@dataclass(frozen=True)
class UploadProgress:
    """Points of the upload tried so far (created or not), of ``total``."""

    done: int
    total: int


@dataclass(frozen=True)
class PointUploaded:
    """One point of the upload: created (``ok``; ``unconfirmed``: without an error, but the
    controller's command status never changed, the observe rule) or not, in ``reason``'s words."""

    point_id: int
    ok: bool
    reason: str = ""
    unconfirmed: bool = False


@dataclass(frozen=True)
class RegisterBlocks:
    """What a :class:`~app.link.ops.ReadRegisters` read: ``values`` register -> value of every
    block read, ``refused`` first register of a refused block -> its Modbus exception code,
    ``read_at`` the PC's clock (``time.time()``) when the first block was asked for."""

    blocks: tuple[tuple[int, int], ...]
    values: Mapping[int, int] = field(default_factory=dict)
    refused: Mapping[int, int] = field(default_factory=dict)
    read_at: float = 0.0
    request_id: int | None = None

    def block(self, start: int, count: int) -> list[int] | None:
        """The registers ``start .. start+count-1``, or None when any of them was not read."""
        try:
            return [self.values[start + i] for i in range(count)]
        except KeyError:
            return None

    def refusal(self, start: int, count: int) -> int | None:
        """The exception code of a refused block that overlaps ``start .. start+count-1``."""
        for (first, n), code in ((b, self.refused[b[0]]) for b in self.blocks if b[0] in self.refused):
            if first < start + count and start < first + n:
                return code
        return None


#: What ``progressed`` carries.
Progress = UploadProgress | PointUploaded | RegisterBlocks

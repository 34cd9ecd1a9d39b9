"""An operation's progress as data: what the link reports of a request before its one result.

The worker publishes each report with the ticket of the request it belongs to (the request id
``RobotLink.submit(op)`` returned): ``RobotLink.progressed(ticket, report)`` carries every one,
and ``link.track(ticket).progressed(report)`` only that request's -- so a panel, a controller or a
script that submitted an upload hears its own upload's points and progress, never another's.

Today only :class:`~app.link.ops.UploadPoints` reports progress: a :class:`PointUploaded` per
point, in order, and :class:`UploadProgress` (points tried, total) at most every
:data:`app.timing.UPLOAD_PROGRESS_PERIOD`, the first (0) and the last always; then its result.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PointUploaded", "Progress", "UploadProgress"]


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


#: What ``progressed`` carries.
Progress = UploadProgress | PointUploaded

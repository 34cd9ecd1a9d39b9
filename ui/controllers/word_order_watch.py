"""Watches the poses the link reads for a register profile whose float word order is probably
wrong (:mod:`app.protocol.word_order_check`) and says so once per connection.

Every pose the link publishes is judged with the word order in force (the link's settings) until
the judgement says "swapped"; then ``warned(verdict)`` is emitted once and nothing more is judged
until the next connection (a new connection, maybe with another profile, is judged afresh:
``warned(None)`` takes the warning away when the link goes down or connects again).
"""

from __future__ import annotations

from PySide6.QtCore import QObject, Signal, Slot

from app.link.robot_link import RobotLink
from app.link.types import ConnectionState, LinkState
from app.models import Pose
from app.protocol.word_order_check import WordOrderVerdict, is_pose, judge_pose

__all__ = ["WordOrderWatch"]

# the link has left the connection the warning was about
_NEW_CONNECTION = (LinkState.CONNECTING, LinkState.DISCONNECTED, LinkState.DOWN)


class WordOrderWatch(QObject):
    """See the module docstring. ``verdict``: the warning in force (None: none)."""

    warned = Signal(object)  # WordOrderVerdict | None

    def __init__(self, link: RobotLink, parent: QObject | None = None) -> None:
        super().__init__(parent)
        self._link = link
        self.verdict: WordOrderVerdict | None = None
        link.state.poseChanged.connect(self._on_pose)
        link.state.connectionChanged.connect(self._on_connection)

    @Slot(Pose)
    def _on_pose(self, pose: Pose) -> None:
        settings = self._link.settings
        if self.verdict is not None or settings is None:
            return
        if is_pose((*pose.xyzabc, *pose.ext)):
            return  # read as a pose: not swapped, whatever the other order would make of it (the
            # other order is decoded only for a read that is not a pose: ~60 us less a poll)
        verdict = judge_pose(pose, settings.word_order)
        if verdict.swapped:
            self.verdict = verdict
            self.warned.emit(verdict)

    @Slot(ConnectionState)
    def _on_connection(self, connection: ConnectionState) -> None:
        if connection.state in _NEW_CONNECTION and self.verdict is not None:
            self.verdict = None
            self.warned.emit(None)

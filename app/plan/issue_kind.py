"""How bad a plan's issue is (:class:`IssueKind`), apart from the checks themselves.

The checks, the tables and the messages that colour or word an issue's kind import it from
here, so the window's first paint does not import the checks (and the
geometry they use) before a plan is checked.
"""

from __future__ import annotations

import enum

__all__ = ["IssueKind"]


class IssueKind(enum.Enum):
    ERROR = "error"  # the plan cannot run as it is
    NEEDS_UPLOAD = "needs-upload"  # a point must be (re)created on the controller first
    WARNING = "warning"  # it can run, but look

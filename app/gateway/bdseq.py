"""The edge node's ``bdSeq`` kept across restarts of the gateway (Sparkplug 3.0: it goes up by one
with every new MQTT session, a restart of the edge node included).

A small JSON file per edge node (``{"format": "teachpad-gateway-bdseq", "version": 1, "group": G,
"node": N, "bdSeq": 7}``), written atomically each time a session's bdSeq is chosen (before its
CONNECT, whose will carries it): it holds the last bdSeq used, and the next start uses that + 1
(0..255 and round again). By default in the user's data folder (``<data>/teachpad/gateway/
GROUP.NODE.bdseq.json``: one per group and node, so two gateways of one PC keep their own).

A file that cannot be read (damaged, another program's) is said once and counted from 0 again; one
that cannot be written is said once per problem and the gateway goes on (the count then restarts
with the next start: what a consumer sees is a bdSeq it did not expect, which Sparkplug hosts
already take as a new session).
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

from app.points.atomic import atomic_write_bytes
from app.user_dirs import data_dir

__all__ = ["BdSeqStore", "default_bdseq_file"]

FORMAT = "teachpad-gateway-bdseq"
VERSION = 1
MAX_BYTES = 4096
_log = logging.getLogger(__name__)


def default_bdseq_file(group: str, node: str) -> Path:
    """Where a gateway of ``group`` / ``node`` keeps its bdSeq by default."""
    return data_dir() / "gateway" / f"{group}.{node}.bdseq.json"


class BdSeqStore:
    """The last bdSeq used by the edge node ``group`` / ``node``, in ``path`` (see the module)."""

    def __init__(self, path: str | os.PathLike[str], group: str, node: str) -> None:
        self.path = Path(path)
        self.group = group
        self.node = node
        self._said: str | None = None  # the last write problem said (each said once)

    def last(self) -> int | None:
        """The bdSeq the last session used (None: no file yet, or one that cannot be used: said)."""
        try:
            if self.path.stat().st_size > MAX_BYTES:
                raise ValueError(f"larger than {MAX_BYTES} bytes")
            doc = json.loads(self.path.read_text(encoding="utf-8"))
            if not isinstance(doc, dict) or doc.get("format") != FORMAT:
                raise ValueError("not a TeachPad gateway bdSeq file")
            value = doc.get("bdSeq")
            if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= 255:
                raise ValueError(f"bdSeq must be a whole number 0..255, got {value!r}")
        except FileNotFoundError:
            return None
        except (OSError, ValueError, UnicodeDecodeError) as exc:
            _log.warning("bdSeq file %s cannot be used (%s): counting from 0 again", self.path, exc)
            return None
        return value

    def first(self) -> int:
        """The bdSeq of this start's first session: the last one used + 1, or 0."""
        last = self.last()
        return 0 if last is None else (last + 1) % 256

    def save(self, bdseq: int) -> None:
        """Keep ``bdseq`` as the one in use (atomically; a failure is said, not raised)."""
        doc = {"format": FORMAT, "version": VERSION, "group": self.group, "node": self.node, "bdSeq": bdseq}
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            atomic_write_bytes(self.path, (json.dumps(doc) + "\n").encode("utf-8"))
        except OSError as exc:
            problem = exc.strerror or str(exc)
            if problem != self._said:
                self._said = problem
                _log.warning(
                    "bdSeq file %s cannot be written (%s): a restart will count from 0", self.path, problem
                )
            return
        self._said = None

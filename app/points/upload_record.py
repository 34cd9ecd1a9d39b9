"""What one boot of a controller confirmed of an upload: the record ``points upload`` resumes from.

A project file cannot know what a controller holds (every loaded point is *unknown*), so
``teachpad-cli points upload --needed`` would send everything again. The upload keeps, beside
the project (:func:`record_path`, written atomically), an :class:`UploadRecord`: the controller's
:class:`~app.link.types.ControllerIdentity` (endpoint, unit, word order, the restart canary's GV
and the token it held) and, per point, the pose and tool frame the controller confirmed.

When is it safe to skip a point because of it (:meth:`UploadRecord.holds`)? Only when all of:

* the identity's place is the same (endpoint, unit, word order, canary GV) and the canary reads,
  now, exactly the record's token (nonzero). A controller restart clears GV0..GV99, and every
  TeachPad that arms the canary again writes a fresh random token, so the same token proves the
  same boot: the temp points created since are still there (:meth:`UploadRecord.same_boot`);
* the point was *confirmed*: its create answered "done" and a canary read after that answer
  still showed the token (a restart between staging a pose and creating the point would have
  created it at zeros: that read sees the 0);
* the project's point has the same pose and tool frame as the one confirmed.

What no record can see, said plainly: another Modbus master may overwrite a temp point without
touching the canary (``run`` re-creates every point before its move for that reason). Unknown,
malformed or foreign records are ignored (everything is sent), never trusted.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from app.link.types import ControllerIdentity
from app.points import atomic
from app.points.point import FileFormatError, TempPoint

__all__ = ["RECORD_SUFFIX", "UploadRecord", "load_record", "record_path", "save_record"]

FORMAT_NAME = "teachpad-upload-record"
FORMAT_VERSION = 1
RECORD_SUFFIX = ".upload-record.json"
RECORD_MAX_BYTES = 16 * 1024 * 1024

#: what the controller confirmed of a point: X Y Z A B C and the tool frame
Held = tuple[float, float, float, float, float, float, int]
T = TypeVar("T")


def record_path(project: Path) -> Path:
    """The record beside ``project`` (``demo.teachpad.json`` -> ``demo.teachpad.json.upload-record.json``)."""
    return project.with_name(project.name + RECORD_SUFFIX)


def held_of(point: TempPoint) -> Held:
    x, y, z, a, b, c = point.xyzabc
    return (x, y, z, a, b, c, point.tool)


@dataclass
class UploadRecord:
    """The points one boot of one controller (``identity``, its token known) confirmed."""

    identity: ControllerIdentity
    points: dict[int, Held] = field(default_factory=dict)

    def same_boot(self, here: ControllerIdentity) -> bool:
        """True when ``here`` (the place now, with the token the canary reads now) is this boot."""
        return self.identity.same_boot(here) and bool(self.identity.boot)

    def holds(self, point: TempPoint) -> bool:
        """The controller of this boot confirmed ``point`` with its present pose and tool frame."""
        return self.points.get(point.id) == held_of(point)

    def confirm(self, points: list[TempPoint]) -> None:
        for p in points:
            self.points[p.id] = held_of(p)

    def to_json(self) -> str:
        ident = self.identity
        doc = {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "controller": {
                "endpoint": ident.endpoint,
                "unit": ident.unit,
                "word_order": ident.word_order,
                "canary_gv": ident.canary_gv,
                "token": ident.boot,
            },
            "points": [[pid, *held] for pid, held in sorted(self.points.items())],
        }
        return json.dumps(doc, ensure_ascii=False, allow_nan=False) + "\n"


def save_record(path: Path, record: UploadRecord) -> None:
    """Write ``record`` atomically (:func:`app.points.atomic.atomic_write_bytes`); OSError as it comes."""
    atomic.atomic_write_bytes(path, record.to_json().encode("utf-8"))


def load_record(path: Path) -> UploadRecord | None:
    """The record at ``path``; None when there is none. :class:`FileFormatError` when it cannot be
    read or is not a record this TeachPad wrote (the caller says so and trusts nothing of it)."""
    if not path.exists():
        return None
    data = atomic.read_limited(path, RECORD_MAX_BYTES)
    try:
        doc = json.loads(data.decode("utf-8"))
        return _record_from(doc)
    except (UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
        raise FileFormatError(f"not a TeachPad upload record ({exc})", path=str(path)) from None


def _record_from(doc: Any) -> UploadRecord:
    if not isinstance(doc, dict) or doc.get("format") != FORMAT_NAME or doc.get("version") != FORMAT_VERSION:
        raise ValueError("unknown format or version")
    c = doc["controller"]
    gv, token = c["canary_gv"], c["token"]
    identity = ControllerIdentity(
        _typed(c["endpoint"], str),
        _typed(c["unit"], int),
        _typed(c["word_order"], str),
        None if gv is None else _typed(gv, int),
        None if token is None else _finite(token),
    )
    points: dict[int, Held] = {}
    for row in doc["points"]:
        if not isinstance(row, list) or len(row) != 8:
            raise ValueError("a point row is not [id, x, y, z, a, b, c, tool]")
        pid, x, y, z, a, b, c6, tool = row
        points[_typed(pid, int)] = (
            _finite(x),
            _finite(y),
            _finite(z),
            _finite(a),
            _finite(b),
            _finite(c6),
            _typed(tool, int),
        )
    return UploadRecord(identity, points)


def _typed(value: object, kind: type[T]) -> T:
    if isinstance(value, bool) or not isinstance(value, kind):
        raise TypeError(f"{value!r} is not {kind.__name__}")
    return value


def _finite(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{value!r} is not a finite number")
    return float(value)

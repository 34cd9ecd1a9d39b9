"""Writing the project file: the project as a JSON document and as the file's text.

The format is described in :mod:`app.points.project` (which reads it); whatever loading
accepts, this writes back.

Every writer works from a :class:`ProjectSnapshot`: an immutable copy taken in the thread that
owns the project (the points, segments and upload records are frozen already, so the copy is a
few tuples of references: milliseconds for a 58 MB project), which another thread may then turn
into the file's text while the project changes (the autosave, :mod:`app.points.autosave`).
"""

from __future__ import annotations

import json
import types
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from app.errors import InvalidInput
from app.plan.segments import Segment
from app.points import atomic
from app.points.point import EXT_FIELDS, POSE_FIELDS, TempPoint
from app.points.project_model import LastUpload, Project
from app.points.provenance import provenance_to_json
from app.watchlist.entry import WatchEntry
from app.watchlist.project_io import KEY as WATCH_LIST_KEY
from app.watchlist.project_io import watch_list_to_json

FORMAT_NAME = "teachpad-project"
FORMAT_VERSION = 1


def _point_to_dict(p: TempPoint, history: LastUpload | None = None) -> dict[str, Any]:
    d: dict[str, Any] = {"id": p.id, "name": p.name}
    d.update(zip(POSE_FIELDS, p.xyzabc, strict=True))
    d.update(zip(EXT_FIELDS, p.ext, strict=True))
    d.update({"tool": p.tool, "note": p.note})
    made = provenance_to_json(p.made)
    if made is not None:
        d["made"] = made
    if history is not None:
        d["uploaded"] = {"time": history.time, "endpoint": history.endpoint}
    return d


def _segment_to_dict(s: Segment) -> dict[str, Any]:
    d: dict[str, Any] = {"type": s.kind.value}
    if s.is_arc:
        d["via"] = s.via_id
    d.update(
        {
            "end": s.end_id,
            "speed": s.speed,
            "orientation": s.orientation,
            "ignore_middle": s.ignore_middle,
            "tool": s.tool,
        }
    )
    return d


@dataclass(frozen=True)
class PlanSnapshot:
    name: str
    loops: int
    segments: tuple[Segment, ...]


@dataclass(frozen=True)
class ProjectSnapshot:
    """What the project file holds, at one revision, safe to read from any thread."""

    name: str
    description: str
    created: str
    modified: str
    points: tuple[TempPoint, ...]
    upload_history: Mapping[int, LastUpload]  # a read-only copy
    plans: tuple[PlanSnapshot, ...]
    revision: int
    watch_list: tuple[WatchEntry, ...] = ()


def take_snapshot(project: Project) -> ProjectSnapshot:
    """An immutable copy of ``project`` (call it in the thread that changes the project)."""
    return ProjectSnapshot(
        name=project.name,
        description=project.description,
        created=project.created,
        modified=project.modified,
        points=project.ledger.snapshot(),
        upload_history=types.MappingProxyType(dict(project.upload_history)),
        plans=tuple(PlanSnapshot(p.name, p.loops, tuple(p.segments)) for p in project.plans),
        revision=project.revision,
        watch_list=project.watch_list,
    )


def _snapshot_of(project: Project | ProjectSnapshot) -> ProjectSnapshot:
    return project if isinstance(project, ProjectSnapshot) else take_snapshot(project)


def project_to_dict(project: Project | ProjectSnapshot) -> dict[str, Any]:
    snap = _snapshot_of(project)
    return {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "name": snap.name,
        "description": snap.description,
        "created": snap.created,
        "modified": snap.modified,
        "points": [_point_to_dict(p, snap.upload_history.get(p.id)) for p in snap.points],
        "plans": [
            {"name": p.name, "loops": p.loops, "segments": [_segment_to_dict(s) for s in p.segments]}
            for p in snap.plans
        ],
        **({WATCH_LIST_KEY: watch_list_to_json(snap.watch_list)} if snap.watch_list else {}),
    }


def _dumps(value: object) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False)


def _json_list(items: Iterable[str], indent: str) -> Iterator[str]:
    """A JSON list laid out one item a line, in pieces (the items' text as they come)."""
    first = True
    for item in items:
        yield ("[\n" if first else ",\n") + indent + "  " + item
        first = False
    yield "[]" if first else "\n" + indent + "]"


def _project_pieces(snap: ProjectSnapshot) -> Iterator[str]:
    """The file's text in pieces: one per point and per segment (each piece's dict is freed at
    once, and no single step works on the whole text: a writer thread lets the GUI thread run)."""
    head = {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "name": snap.name,
        "description": snap.description,
        "created": snap.created,
        "modified": snap.modified,
    }
    yield "{\n" + ",\n".join(f"  {_dumps(k)}: {_dumps(v)}" for k, v in head.items())
    yield ',\n  "points": '
    history = snap.upload_history
    yield from _json_list((_dumps(_point_to_dict(p, history.get(p.id))) for p in snap.points), "  ")
    yield ',\n  "plans": '
    first = True
    for plan in snap.plans:
        opening = "[\n" if first else ",\n"
        yield f'{opening}    {{"name": {_dumps(plan.name)}, "loops": {_dumps(plan.loops)}, "segments": '
        yield from _json_list((_dumps(_segment_to_dict(s)) for s in plan.segments), "    ")
        yield "}"
        first = False
    yield "[]" if first else "\n  ]"
    if snap.watch_list:  # optional: a project without a watch list is written as before
        yield f",\n  {_dumps(WATCH_LIST_KEY)}: "
        yield from _json_list((_dumps(e) for e in watch_list_to_json(snap.watch_list)), "  ")
    yield "\n}\n"


def project_to_json(project: Project | ProjectSnapshot) -> str:
    """The file's text: plain JSON laid out one point and one segment per line (readable,
    and a changed point is a one-line diff)."""
    return "".join(_project_pieces(_snapshot_of(project)))


class ProjectTooLarge(InvalidInput):
    """The project's file would exceed what TeachPad reads back (:data:`app.points.atomic.MAX_FILE_BYTES`):
    it is not written -- never a file TeachPad then refuses to open."""

    code = "project_too_large"

    def __init__(self, size: int, limit: int) -> None:
        super().__init__(
            f"the project would be {size} bytes, more than TeachPad opens ({limit} bytes); "
            "nothing was written",
            params={"size": size, "limit": limit},
        )
        self.size, self.limit = size, limit


def project_bytes(project: Project | ProjectSnapshot) -> bytes:
    """The project's file as it would be written; :class:`ProjectTooLarge` when TeachPad could not
    read it back (checked before any write: :func:`~app.points.project.save_project`, the autosave,
    an import's check)."""
    data = b"".join(piece.encode("utf-8") for piece in _project_pieces(_snapshot_of(project)))
    limit = atomic.MAX_FILE_BYTES
    if len(data) > limit:
        raise ProjectTooLarge(len(data), limit)
    return data

"""Writing the project file: the project as a JSON document and as the file's text.

The format is described in :mod:`app.points.project` (which reads it and re-exports these
names); whatever loading accepts, this writes back.
"""

from __future__ import annotations

import json
from typing import Any

from app.errors import InvalidInput
from app.plan.segments import Segment
from app.points import atomic
from app.points.point import EXT_FIELDS, POSE_FIELDS, TempPoint
from app.points.project_model import Project, UploadRecord

FORMAT_NAME = "teachpad-project"
FORMAT_VERSION = 1


def _point_to_dict(p: TempPoint, history: UploadRecord | None = None) -> dict[str, Any]:
    d: dict[str, Any] = {"id": p.id, "name": p.name}
    d.update(zip(POSE_FIELDS, p.xyzabc, strict=True))
    d.update(zip(EXT_FIELDS, p.ext, strict=True))
    d.update({"tool": p.tool, "note": p.note})
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


def project_to_dict(project: Project) -> dict[str, Any]:
    return {
        "format": FORMAT_NAME,
        "version": FORMAT_VERSION,
        "name": project.name,
        "description": project.description,
        "created": project.created,
        "modified": project.modified,
        "points": [_point_to_dict(p, project.upload_history.get(p.id)) for p in project.ledger],
        "plans": [
            {"name": p.name, "loops": p.loops, "segments": [_segment_to_dict(s) for s in p.segments]}
            for p in project.plans
        ],
    }


def _dumps(value: object) -> str:
    return json.dumps(value, ensure_ascii=False, allow_nan=False)


def _json_list(items: list[str], indent: str) -> str:
    if not items:
        return "[]"
    return "[\n" + ",\n".join(indent + "  " + item for item in items) + "\n" + indent + "]"


def project_to_json(project: Project) -> str:
    """The file's text: plain JSON laid out one point and one segment per line (readable,
    and a changed point is a one-line diff)."""
    doc = project_to_dict(project)
    lines = [f"  {_dumps(k)}: {_dumps(v)}" for k, v in doc.items() if k not in ("points", "plans")]
    lines.append(f'  "points": {_json_list([_dumps(p) for p in doc["points"]], "  ")}')
    plans = []
    for plan in doc["plans"]:
        head = ", ".join(f"{_dumps(k)}: {_dumps(v)}" for k, v in plan.items() if k != "segments")
        segments = _json_list([_dumps(s) for s in plan["segments"]], "    ")
        plans.append(f'{{{head}, "segments": {segments}}}')
    lines.append(f'  "plans": {_json_list(plans, "  ")}')
    return "{\n" + ",\n".join(lines) + "\n}\n"


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


def project_bytes(project: Project) -> bytes:
    """The project's file as it would be written; :class:`ProjectTooLarge` when TeachPad could not
    read it back (checked before any write: :func:`~app.points.project.save_project`, the autosave,
    an import's check)."""
    data = project_to_json(project).encode("utf-8")
    limit = atomic.MAX_FILE_BYTES
    if len(data) > limit:
        raise ProjectTooLarge(len(data), limit)
    return data

"""The worker's parts have narrow seams, and everything a Stop does is one module (issue 22).

* No part reaches a sibling through the worker (``host.jog.reset()``, ``self._host.supervisor``):
  the worker composes them (app/link/sequence.py, app/link/lifecycle.py) and hands each only
  what it uses; ``app/link/host.py`` has no view of a part any more.
* The Stop: the worker's table runs it through :class:`app.link.halt.StopJob`, and every write of
  the controller's stop (441) the link makes outside the stop line's own frame is made in
  app/link/halt.py.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any

import app.link.host
from app.link.ops import Stop

LINK = Path(__file__).resolve().parents[2] / "app" / "link"
#: The composers: they know every part and sequence them.
COMPOSERS = {"worker.py", "lifecycle.py", "sequence.py"}
#: The worker's parts and the worker's methods that sequence them (polling, reconnecting, the queue).
SIBLINGS = {
    "supervisor",
    "poller",
    "jog",
    "uploader",
    "motion",
    "motions",
    "capture",
    "stop_line",
    "stop_job",
    "commands",
    "handlers",
    "start_polling",
    "stop_polling",
    "start_reconnect",
    "stop_reconnect",
    "run_jobs",
    "fail_queued",
}


def _is_host(node: ast.expr) -> bool:
    """``host`` or ``self._host``: the worker as a part holds it."""
    if isinstance(node, ast.Name):
        return node.id == "host"
    return (
        isinstance(node, ast.Attribute)
        and node.attr == "_host"
        and isinstance(node.value, ast.Name)
        and node.value.id == "self"
    )


def _sibling_reaches(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        f"{path.name}:{node.lineno}: host.{node.attr}"
        for node in ast.walk(tree)
        if isinstance(node, ast.Attribute) and node.attr in SIBLINGS and _is_host(node.value)
    ]


def test_no_part_reaches_a_sibling_through_the_worker() -> None:
    reaches = [
        r for path in sorted(LINK.glob("*.py")) if path.name not in COMPOSERS for r in _sibling_reaches(path)
    ]
    assert reaches == []


def test_the_parts_protocols_have_no_view_of_a_part() -> None:
    gone = {"WorkerHost", "SupervisorView", "PollerView", "JogView", "UploaderView"}
    assert gone.isdisjoint(vars(app.link.host))


def test_the_worker_runs_the_stop_through_the_stop_module(qapp: Any) -> None:
    from app.link.worker import RobotWorker

    worker = RobotWorker(canary_gv=None)
    try:
        handler = worker.handlers._table[Stop]
        assert type(getattr(handler, "__self__", None)).__module__ == "app.link.halt", handler
    finally:
        worker.deleteLater()


def _client_stop_calls(path: Path) -> list[str]:
    """Calls of ``<...client...>.stop()`` / ``prior.stop()``: the controller's stop (441) written."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    calls = []
    for node in ast.walk(tree):
        if not (
            isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "stop"
        ):
            continue
        receiver = ast.unparse(node.func.value)
        if "client" in receiver or "prior" in receiver:
            calls.append(f"{path.name}:{node.lineno}: {receiver}.stop()")
    return calls


def test_every_stop_the_link_writes_is_written_in_the_stop_module() -> None:
    calls = [c for path in sorted(LINK.glob("*.py")) for c in _client_stop_calls(path)]
    assert calls and all(c.startswith("halt.py:") for c in calls), calls

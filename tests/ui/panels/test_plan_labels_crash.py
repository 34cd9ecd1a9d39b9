"""The planner's segfault of stop 27 (``test_a_new_run_clears_plan_finished`` crashed in 5 of 6 runs
in ``GraphicsView.paintEvent``): how it came about, and the two changes that end it.

1. A new run (:meth:`PlanPreview.start_live`) refilled the live trail's ring buffer with NaN *in
   place*, and the trail curves held views of that buffer (pyqtgraph keeps the arrays it is given):
   their data turned all NaN under them, and pyqtgraph 0.14's ``arrayToLineSegments`` raises
   ``ValueError`` for a curve whose points are all non-finite (it computes -1 segments). pyqtgraph
   catches it in ``paint`` and warns (``RuntimeWarning``, an exception under pytest's
   ``filterwarnings = error``, and under any "error" warnings filter).
2. shiboken6 6.11.2 / 6.11.3 (``Sbk_GetPyOverride``): when a Python exception is pending at a virtual
   call whose override is not cached yet (an item painted for the first time), it ``Py_DECREF``s the
   function ``BindingManager::getOverride`` returned as a *borrowed* reference. The point labels
   were pyqtgraph ``TextItem``s removed and made anew at every plan change: each new label painted
   after the exception took one reference from ``TextItem.paint`` until the class's function was
   freed, and the next paint used it (a segfault in ``_PyObject_GC_UNTRACK``).

Now the trail curves get copies (and are emptied by a new run), and the labels are plain Qt items
(no Python ``paint``) made once per slot and reused.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PySide6.QtWidgets import QGraphicsSimpleTextItem

from app.models import Pose
from tests.cli.ctrl_c import untraced_env
from ui.panels.plan_preview import PlanPreview

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture
def preview(qtbot: Any) -> PlanPreview:
    widget = PlanPreview()
    qtbot.addWidget(widget)
    widget.resize(1000, 320)
    widget.show()
    return widget


def trail_x(curve: Any, axis: int = 0) -> np.ndarray:
    """The x (or y, ``axis`` 1) data of a curve, empty when it has none."""
    data = curve.getData()[axis]
    return np.asarray(data if data is not None else [], dtype=float)


def test_a_new_run_leaves_no_trail_on_a_refilled_buffer(qtbot: Any, preview: PlanPreview) -> None:
    top = preview.projections["top"]
    preview.start_live()
    for k in range(4):
        preview.on_pose(Pose(10.0 + k, 20.0, 30.0, 0.0, 0.0, 0.0))
        qtbot.waitUntil(lambda k=k: trail_x(top.trail)[-1:].tolist() == [10.0 + k])
    preview.stop_live()
    preview.start_live()  # the next run: the ring buffer starts again (NaN)
    for proj in preview.projections.values():
        xs, ys = trail_x(proj.trail), trail_x(proj.trail, 1)
        assert np.isfinite(xs).all() and np.isfinite(ys).all(), (xs, ys)  # not NaN under the curve
    preview.grab()  # paints without an error (an exception here is what set the crash off)


def test_the_labels_are_reused_qt_items(preview: PlanPreview) -> None:
    xyz = np.array([(300.0, 0.0, 300.0), (400.0, 100.0, 320.0), (500.0, 0.0, 300.0)])
    preview.set_points(xyz, ["P1", "P2", "P3"])
    top = preview.projections["top"]
    first = list(top.labels)
    assert all(type(label) is QGraphicsSimpleTextItem for label in first)  # no Python paint
    preview.set_points(xyz[:2] + 10.0, ["P4", "P5"])
    assert top.labels == first[:2] and [label.text() for label in top.labels] == ["P4", "P5"]
    assert not first[2].isVisible()  # the slot not needed now is hidden, not removed
    preview.set_points(xyz, ["P1", "P2", "P3"])
    assert top.labels == first


_CHILD = """
import json, sys, types, warnings
warnings.simplefilter("error")  # as under pytest: pyqtgraph's warning from paint raises
from PySide6.QtCore import QEventLoop, QTimer
from PySide6.QtWidgets import QApplication
app = QApplication([])
import numpy as np
import pyqtgraph as pg
from app.models import Pose
from app.plan.geometry import plan_path
from app.plan.segments import Plan, Segment
from app.points.ledger import PointLedger, make_point
from ui.panels.plan_preview import PlanPreview

classes = {m for o in vars(pg).values() if isinstance(o, type) for m in o.__mro__}
held = {f"{c.__qualname__}.{k}": v for c in classes for k, v in vars(c).items()
        if isinstance(v, types.FunctionType)}  # held here: an over-released one is not freed
base = {k: sys.getrefcount(v) for k, v in held.items()}
errors = []
sys.excepthook = lambda t, v, tb: errors.append(f"{t.__name__}: {str(v)[:200]}")


def settle(ms=40):
    loop = QEventLoop()
    QTimer.singleShot(ms, loop.quit)
    loop.exec()


preview = PlanPreview()
preview.resize(1000, 320)
preview.show()
settle()
for run in range(8):
    xyz = np.array([(300.0 + run, 0.0, 300.0), (400.0, 100.0 + run, 320.0), (500.0, 0.0, 300.0 + run)])
    ledger = PointLedger([make_point(i + 1, "", (*row, 180, 0, 0)) for i, row in enumerate(xyz)])
    plan = Plan("p", [Segment.line(1), Segment.line(2), Segment.line(3)])
    preview.set_path(plan_path(plan, ledger, (300.0, 0.0, 300.0)))  # a plan change: its path,
    preview.set_points(xyz, [f"P{run}{i}" for i in range(3)])  # its points' labels
    preview.start_live()  # a run: the trail starts again
    settle()  # painted before the run's first pose
    for k in range(3):
        preview.on_pose(Pose(300.0 + 10 * k, 10.0 * run, 300.0, 0.0, 0.0, 0.0))
        settle()
    preview.on_pose(Pose(340.0, 10.0 * run, 300.0, 0.0, 0.0, 0.0))
    preview.stop_live()  # the run's end: its last pose drawn, the next run starts before a paint
released = {k: sys.getrefcount(v) - base[k] for k, v in held.items() if sys.getrefcount(v) < base[k]}
print("RESULT " + json.dumps({"released": released, "errors": errors[:5]}), flush=True)
"""


def test_runs_and_plan_changes_release_no_reference_of_pyqtgraph(tmp_path: Path) -> None:
    """Eight runs and plan changes in a child process (a crash must not take the suite with it),
    warnings as errors: no pyqtgraph function loses a reference, nothing raises while painting."""
    env = {**untraced_env(), "QT_QPA_PLATFORM": "offscreen"}
    out = subprocess.run(
        [sys.executable, "-X", "faulthandler", "-c", _CHILD],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
        check=False,
    )
    assert out.returncode == 0, f"exit {out.returncode}\n{out.stderr[-3000:]}"
    result = json.loads(next(x for x in out.stdout.splitlines() if x.startswith("RESULT ")).split(" ", 1)[1])
    assert result == {"released": {}, "errors": []}, result

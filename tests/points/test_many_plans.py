"""Plan-name uniqueness is checked in one pass, not pairwise (issue 19 section 6: 20,000 plans took
11-14 s to load, 40,000 took 53 s) -- and it is still enforced, however many plans there are."""

from __future__ import annotations

import json

import pytest

from app.errors import InvalidInput
from app.plan.segments import Plan, validate_plan_name
from app.points import project as project_module
from app.points.point import FileFormatError
from app.points.project import parse_project
from app.points.project_model import Project
from app.points.project_write import project_to_json

MANY = 20_000


def _text(names: list[str]) -> str:
    doc = json.loads(project_to_json(Project(name="many")))
    doc["plans"] = [{"name": name, "loops": 1, "segments": []} for name in names]
    return json.dumps(doc)


def test_many_plans_load_and_a_duplicate_name_is_still_refused() -> None:
    names = [f"plan {i}" for i in range(MANY)]
    assert len(parse_project(_text(names)).plans) == MANY
    with pytest.raises(FileFormatError, match=r"another plan is named 'plan 7'"):
        parse_project(_text([*names, " plan 7 "]))  # compared after stripping, as always
    plans = [Plan(name) for name in names]
    with pytest.raises(InvalidInput, match="two plans are named 'plan 19999'"):
        Project(plans=[*plans, Plan("plan 19999")])
    project = Project(plans=plans)
    with pytest.raises(InvalidInput, match="already exists"):
        project.add_plan(Plan("plan 0"))


class _CountingName(str):
    """A plan name that counts the comparisons made with it (a pairwise check makes n²/2)."""

    compared = 0

    def __eq__(self, other: object) -> bool:
        _CountingName.compared += 1
        return str.__eq__(self, other)

    __hash__ = str.__hash__


def test_loading_compares_each_name_a_bounded_number_of_times(monkeypatch: pytest.MonkeyPatch) -> None:
    n = 3_000
    real = validate_plan_name
    monkeypatch.setattr(project_module, "validate_plan_name", lambda value: _CountingName(real(value)))
    _CountingName.compared = 0
    assert len(parse_project(_text([f"plan {i}" for i in range(n)])).plans) == n
    assert _CountingName.compared <= 2 * n, _CountingName.compared  # pairwise: about n * n / 2

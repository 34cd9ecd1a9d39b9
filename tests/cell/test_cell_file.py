"""The cell file: read, written atomically, and every problem one line naming the controller and the field."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from app.cell.cell_file import Cell, CellController, CellFileError, load_cell, save_cell
from app.points import atomic
from app.protocol.codec import WordOrder
from app.safety.register_profile import RegisterProfile, save_register_profile
from app.view3d.profile import default_profile, profile_to_dict


def _doc(*controllers: dict[str, Any], **top: Any) -> dict[str, Any]:
    return {
        "format": "teachpad-cell",
        "version": 1,
        "name": "cell 3",
        "controllers": list(controllers),
        **top,
    }


def _write(folder: Path, doc: object) -> Path:
    path = folder / "cell.json"
    path.write_text(json.dumps(doc), encoding="utf-8")
    return path


def test_read_with_profiles_relative_to_the_cell_file(tmp_path: Path) -> None:
    save_register_profile(
        tmp_path / "r1.registers.json", RegisterProfile("r1", word_order=WordOrder.HIGH_FIRST, unit=5)
    )
    (tmp_path / "arm.json").write_text(json.dumps(profile_to_dict(default_profile())))
    path = _write(
        tmp_path,
        _doc(
            {
                "name": "R1",
                "host": "10.0.3.11",
                "register_profile": "r1.registers.json",
                "robot_profile": "arm.json",
            },
            {"name": "R2", "rtu": "/dev/ttyUSB0", "baud": 9600, "unit": 2},
            {
                "name": "R3",
                "host": "10.0.3.13",
                "port": 1502,
                "unit": 7,
                "register_profile": "r1.registers.json",
            },
        ),
    )
    cell = load_cell(path)
    r1, r2, r3 = cell.controllers
    assert cell.name == "cell 3"
    s1 = r1.settings()
    assert (s1.host, s1.port, s1.unit, s1.word_order, s1.monitor_only) == (
        "10.0.3.11",
        502,
        5,
        WordOrder.HIGH_FIRST,
        True,
    )
    assert r1.robot is not None and r1.robot.dof == default_profile().dof
    s2 = r2.settings()
    assert (s2.serial_port, s2.baudrate, s2.unit, s2.transport) == ("/dev/ttyUSB0", 9600, 2, "rtu")
    assert r3.settings().unit == 7  # the cell's unit overrides the register profile's


def test_saved_atomically_and_read_back_the_same(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cell = Cell(
        "c", (CellController("R1", host="h", port=1502, unit=3), CellController("R2", rtu="/dev/ttyS0"))
    )
    path = tmp_path / "cell.json"
    written: list[Path] = []
    real = atomic.atomic_write_bytes

    def spy(target: Any, data: bytes, **kw: Any) -> None:
        written.append(Path(target))
        real(target, data, **kw)

    monkeypatch.setattr("app.cell.cell_file.atomic_write_bytes", spy)
    save_cell(path, cell)
    assert written == [path]
    assert load_cell(path) == cell
    assert not list(tmp_path.glob(".teachpad-tmp.*"))


@pytest.mark.parametrize(
    ("controller", "said"),
    [
        (
            {"name": "R2", "host": "h", "port": 70000},
            "controller 'R2': port must be a whole number 1..65535, got 70000",
        ),
        ({"name": "R2", "host": "h", "rtu": "/dev/x"}, "controller 'R2': needs either host"),
        ({"name": "R2"}, "controller 'R2': host is missing"),
        ({"name": "R2", "rtu": "/dev/x", "baud": 7}, "controller 'R2': baud must be"),
        ({"name": "R2", "rtu": "/dev/x", "port": 5}, "controller 'R2': port is for Modbus TCP"),
        ({"name": "R2", "host": "h", "unit": 300}, "controller 'R2': unit must be a whole number 0..247"),
        ({"name": "R2", "host": "h", "speed": 1}, "controller 'R2': unknown field \"speed\""),
        ({"name": "", "host": "h"}, "controller 2: name must be"),
        (
            {"name": "R2", "host": "h", "register_profile": "none.json"},
            "controller 'R2': register_profile: register profile",
        ),
        ({"name": "R2", "host": "h", "robot_profile": "none.json"}, "controller 'R2': robot_profile:"),
        ({"name": "R1", "host": "h"}, "controller 'R1': name is used twice"),
        ("R2", "controller 2: must be an object"),
        (
            {"name": "R2", "host": "h", "plant_writes": "program/run"},
            "controller 'R2': plant_writes must be a list of names",
        ),
        (
            {"name": "R2", "host": "h", "plant_writes": ["program/run", "jog"]},
            "controller 'R2': plant_writes: \"jog\" is not a write the plant may make",
        ),
        (
            {"name": "R2", "host": "h", "plant_writes": ["speed_ratio", "speed_ratio"]},
            "controller 'R2': plant_writes names a write twice",
        ),
        (
            {"name": "R2", "host": "h", "external_axes": 6},
            "controller 'R2': external_axes must be a whole number 0..5",
        ),
    ],
)
def test_a_problem_is_one_line_naming_the_controller_and_the_field(
    tmp_path: Path, controller: Any, said: str
) -> None:
    path = _write(tmp_path, _doc({"name": "R1", "host": "h"}, controller))
    with pytest.raises(CellFileError) as caught:
        load_cell(path)
    text = str(caught.value)
    assert "\n" not in text
    assert text.startswith("cell file cell.json: ")
    assert said in text


@pytest.mark.parametrize(
    ("doc", "said"),
    [
        ("{", "is not valid JSON"),
        ({"format": "teachpad-project", "version": 1}, "is not a TeachPad cell file"),
        (_doc({"name": "R1", "host": "h"}, version=2), "newer TeachPad"),
        (_doc(), "controllers must be a list of 1 to"),
        (_doc({"name": "R1", "host": "h"}, extra=1), "unknown field"),
    ],
)
def test_a_bad_file_says_so_in_one_line(tmp_path: Path, doc: Any, said: str) -> None:
    path = tmp_path / "cell.json"
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(CellFileError, match=said):
        load_cell(path)


def test_a_missing_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(CellFileError, match="does not exist"):
        load_cell(tmp_path / "nowhere.json")


def test_plant_writes_and_external_axes_are_read_and_written_back(tmp_path: Path) -> None:
    writes = ["program/run", "program/stop", "speed_ratio"]
    path = _write(
        tmp_path,
        _doc(
            {"name": "R1", "host": "h"},
            {"name": "R2", "host": "h", "external_axes": 2, "plant_writes": writes},
        ),
    )
    cell = load_cell(path)
    assert (cell.controllers[0].plant_writes, cell.controllers[0].external_axes) == ((), 0)  # off by default
    assert (cell.controllers[1].plant_writes, cell.controllers[1].external_axes) == (tuple(writes), 2)
    save_cell(path, cell)
    assert load_cell(path) == cell
    assert "plant_writes" not in json.loads(path.read_text())["controllers"][0]

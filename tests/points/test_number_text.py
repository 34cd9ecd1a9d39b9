"""How a point's numbers read (issue 21): the CSV and the cell editor write a float32 as its
shortest text, a value nearer 0 than the display's resolution reads 0, A/C at -180 read +180;
a CSV written so reads back as the same point on the controller."""

from __future__ import annotations

from app.points.csv_io import parse_points_csv, points_to_csv
from app.points.ledger import PointLedger
from app.points.ledger_import import ImportMode
from app.points.number_text import display_text, shown_value, value_text
from app.points.point import SyncState, make_point
from app.protocol.codec import decode_floats, encode_floats


def taught(*values: float) -> tuple[float, ...]:
    """The pose as the link delivers it: float32 register pairs decoded."""
    return tuple(decode_floats(encode_floats(values)))


def csv_row(*values: float) -> list[str]:
    point = make_point(1, "P1", taught(*values))
    return points_to_csv([point]).splitlines()[1].split(",")[2:8]


def test_csv_writes_the_shortest_float32_text() -> None:
    pose = taught(596.903, -9.2e-06, 300.0, 180.0, 0.0, 90.0)
    assert pose[0] != 596.903  # what the controller holds: 596.9030151367188
    assert csv_row(*pose) == ["596.903", "0.0", "300.0", "180.0", "0.0", "90.0"]


def test_a_and_c_at_minus_180_read_plus_180() -> None:
    assert csv_row(400, 0, 300, -180.0, 0, -180.0) == ["400.0", "0.0", "300.0", "180.0", "0.0", "180.0"]
    assert csv_row(400, 0, 300, -179.9999, 0, 180.0) == ["400.0", "0.0", "300.0", "180.0001", "0.0", "180.0"]
    assert display_text(taught(-179.9999)[0], "a") == display_text(taught(179.9999)[0], "a") == "180.000"
    assert display_text(-180.0, "c") == "180.000"
    assert display_text(-180.0, "b") == "-180.000"  # B is no wrapping angle (±90)
    assert shown_value(-179.0, "a") == -179.0  # only what would show as -180.000 moves


def test_minus_zero_reads_zero() -> None:
    assert display_text(-0.0) == display_text(-0.0004) == display_text(-9.2e-06) == "0.000"
    assert value_text(-0.0) == value_text(-9.2e-06) == "0.0"
    assert display_text(-0.6) == "-0.600" and value_text(-0.001) == "-0.001"


def test_a_csv_round_trip_keeps_the_point_on_the_controller() -> None:
    """The CSV's 596.903 reads back as the float32 the controller holds: re-importing the file
    does not mark the point changed."""
    point = make_point(7, "P7", taught(596.903, 1.1, 2.2, 179.9999, 0.5, 33.3), sync=SyncState.ON_CONTROLLER)
    ledger = PointLedger([point])
    back = parse_points_csv(points_to_csv([point]))
    assert back[0].xyzabc != point.xyzabc  # other float64 values ...
    assert back[0].same_on_controller(point)  # ... the same float32 ones
    ledger.import_points(back, ImportMode.REPLACE)
    assert ledger[0].sync is SyncState.ON_CONTROLLER


def test_a_point_at_minus_180_reads_back_as_its_plus_180_twin() -> None:
    """The CSV writes A = -179.9999 as 180.0001: the same orientation, another number, so the
    re-imported point is uploaded again (changed) before a move, never assumed there."""
    point = make_point(8, "P8", taught(400, 0, 300, -179.9999, 0, 0), sync=SyncState.ON_CONTROLLER)
    back = parse_points_csv(points_to_csv([point]))
    assert back[0].a == 180.0001 and not back[0].same_on_controller(point)

"""The points table's columns and roles, and how a point's values and sync state read in it."""

from __future__ import annotations

from PySide6.QtCore import (
    QCoreApplication,
    Qt,
)

from app.points.number_text import display_text, value_text
from app.points.point import EXT_FIELDS, POSE_FIELDS, SyncState
from app.points.point import TR_CONTEXT as POINTS_CORE_CONTEXT
from app.protocol.registers import TOOL_NONE
from ui.palette import (
    COLOR_ERROR,
    COLOR_ERROR_BG,
    COLOR_NEUTRAL,
    COLOR_NEUTRAL_BG,
    COLOR_OK,
    COLOR_OK_BG,
    COLOR_WARN_BG,
    COLOR_WARN_DARK,
    COLOR_WARN_TEXT,
)

#: Columns of the table: the point's fields in CSV order, with the sync state before the note.
COLUMNS: tuple[str, ...] = ("id", "name", *POSE_FIELDS, *EXT_FIELDS, "tool", "sync", "note")
COL_ID = COLUMNS.index("id")
COL_NAME = COLUMNS.index("name")
COL_X = COLUMNS.index("x")
COL_C = COLUMNS.index("c")
COL_E1 = COLUMNS.index("e1")
COL_E5 = COLUMNS.index("e5")
COL_TOOL = COLUMNS.index("tool")
COL_SYNC = COLUMNS.index("sync")
COL_NOTE = COLUMNS.index("note")
EXT_COLUMNS: tuple[int, ...] = tuple(range(COL_E1, COL_E5 + 1))
NUMBER_COLUMNS: frozenset[int] = frozenset((COL_ID, *range(COL_X, COL_E5 + 1)))

#: Custom roles.
POINT_ID_ROLE = Qt.ItemDataRole.UserRole + 1  # int, any column
SYNC_ROLE = Qt.ItemDataRole.UserRole + 2  # SyncState, any column

#: Text the tool cell accepts for "no tool frame" besides 200.
TOOL_NONE_WORDS: frozenset[str] = frozenset(("", "none", "-", "无"))

SYNC_COLOURS: dict[SyncState, tuple[str, str]] = {  # state -> (text, background)
    SyncState.UNKNOWN: (COLOR_NEUTRAL, COLOR_NEUTRAL_BG),
    SyncState.ON_CONTROLLER: (COLOR_OK, COLOR_OK_BG),
    SyncState.CHANGED: (COLOR_WARN_TEXT, COLOR_WARN_BG),
    SyncState.FAILED: (COLOR_ERROR, COLOR_ERROR_BG),
    SyncState.UNCONFIRMED: (COLOR_WARN_DARK, COLOR_OK_BG),  # likely there: green ground, amber text
}


def sync_text(state: SyncState) -> str:
    """The sync state in the current language (the core marks the English in context Points)."""
    return QCoreApplication.translate(POINTS_CORE_CONTEXT, state.text)


def tool_display(tool: int) -> str:
    if tool == TOOL_NONE:
        return QCoreApplication.translate("PointsModel", "none")
    return QCoreApplication.translate("PointsModel", "tool {n}").format(n=tool)  # as in the CSV and GV245


def format_number(value: float, field: str = "") -> str:
    """The table's text of a number (3 decimals, no -0.000, +180 for A/C: app/points/number_text.py)."""
    return display_text(value, field)


def edit_text(value: float, field: str = "") -> str:
    """Editor text of a number: its shortest float32 text, as the CSV writes it (``596.903``,
    ``400.0``, ``0.0`` for -9.2e-06; app/points/number_text.py)."""
    return value_text(value, field)


# --------------------------------------------------------------------------------------------
# The points model
# --------------------------------------------------------------------------------------------

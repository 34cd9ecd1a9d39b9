"""The GUI's colours, named by what they mean, in one place.

Panels, table models, plots and style sheets take their colours from here (``#rrggbb``
strings, usable in style sheets, ``QColor(...)`` and ``pg.mkPen(...)``). A colour used for a
meaning (an error, a warning, a selection) has one value everywhere.
"""

from __future__ import annotations

from typing import Final

# --- states: text on a light background, and the matching light background ---------------
COLOR_ERROR: Final = "#c62828"
COLOR_ERROR_BG: Final = "#fde0e0"
COLOR_ERROR_DARK: Final = "#8e0000"  # borders, pressed buttons
COLOR_ERROR_HOVER: Final = "#d32f2f"
COLOR_WARN: Final = "#ef8f00"  # lamps, borders, bold hints
COLOR_WARN_TEXT: Final = "#8a5300"  # warning text on white (amber is too light to read)
COLOR_WARN_DARK: Final = "#7a4a00"  # warning text on COLOR_WARN_BG
COLOR_WARN_BG: Final = "#fff1d6"
COLOR_OK: Final = "#2e7d32"
COLOR_OK_BG: Final = "#e3f4e4"
COLOR_INFO: Final = "#1565c0"
COLOR_NEUTRAL: Final = "#5f6368"  # captions, hints, "off"
COLOR_NEUTRAL_BG: Final = "#eceff1"
COLOR_BORDER: Final = "#cfd8dc"
COLOR_WHITE: Final = "#ffffff"

# --- text and plot ink ---------------------------------------------------------------------
COLOR_INK: Final = "#263238"  # plot titles, axis text, marker outlines
COLOR_INK_SOFT: Final = "#37474f"  # secondary text, point labels, received frames
COLOR_AXIS: Final = "#455a64"  # plot axes, taught points
COLOR_GRID: Final = "#dde3e6"

# --- selection and plan drawing ------------------------------------------------------------
COLOR_HIGHLIGHT: Final = "#ff6f00"  # the selected segment, the live marker
COLOR_ACTIVE_BG: Final = "#d6e6fb"  # the row being run
COLOR_PATH: Final = COLOR_INFO  # a plan's path
COLOR_START: Final = COLOR_OK  # where a plan starts
COLOR_TCP: Final = COLOR_ERROR  # the robot's tool point
COLOR_TRAIL: Final = "#ef9a9a"  # the tool point's trail

# --- curves (matplotlib's first three, then purple) ----------------------------------------
COLOR_CURVE_RED: Final = "#d62728"
COLOR_CURVE_GREEN: Final = "#2ca02c"
COLOR_CURVE_BLUE: Final = "#1f77b4"
COLOR_CURVE_PURPLE: Final = "#6a1b9a"

# --- staleness and alarms (the pose strip, the alarm banner) --------------------------------
COLOR_STALE: Final = "#90a4ae"  # a value not confirmed within the freshness limit
COLOR_STALE_BG: Final = "#eceff1"
COLOR_ALARM_BANNER: Final = "#b71c1c"  # the window-wide alarm banner's background
COLOR_ALARM_BANNER_TEXT: Final = "#ffffff"

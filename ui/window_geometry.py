"""The main window's size at start: the default (clamped to the screen), the minimum the layout
stays usable at, and the geometry and dock layout remembered from the last session."""

from __future__ import annotations

from PySide6.QtGui import QGuiApplication
from PySide6.QtWidgets import QMainWindow

from ui.settings import AppSettings

__all__ = ["DEFAULT_SIZE", "MIN_SIZE", "default_size", "restore_window"]

DEFAULT_SIZE = (1600, 960)  # clamped to the screen's available size
MIN_SIZE = (1024, 700)  # the layout stays usable down to this


def default_size() -> tuple[int, int]:
    """:data:`DEFAULT_SIZE` within the primary screen's available area, never under :data:`MIN_SIZE`."""
    width, height = DEFAULT_SIZE
    screen = QGuiApplication.primaryScreen()
    if screen is not None:
        available = screen.availableGeometry()
        width, height = min(width, available.width()), min(height, available.height())
    return max(width, MIN_SIZE[0]), max(height, MIN_SIZE[1])


def restore_window(window: QMainWindow, settings: AppSettings) -> bool:
    """The remembered geometry and dock layout; False when there was no dock layout to restore."""
    geometry = settings.window_geometry()
    if geometry is not None:
        window.restoreGeometry(geometry)
    state = settings.window_state()
    return state is not None and window.restoreState(state)

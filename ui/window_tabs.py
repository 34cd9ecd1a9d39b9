"""A work tab whose panel is built the first time it is needed, not with the window.

The Points and Planner tabs are hidden behind the Monitor at start: building them (and importing
the planner's numpy-based geometry and checks) made the window's first paint wait for panels
nobody sees yet. :class:`LazyTab` holds an empty placeholder in the tab until the tab comes to the
front or someone asks for :attr:`LazyTab.panel` (a test, a menu, the 3D view); then it builds the
panel, runs the callbacks registered with :meth:`LazyTab.on_built` -- the safety gating among
them, so a panel is never shown, nor reachable, before its role gating applies -- and puts the
panel in the placeholder's place, at the same index, keeping the tab current if it was.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

from PySide6.QtCore import QObject, Slot
from PySide6.QtWidgets import QTabWidget, QWidget

P = TypeVar("P", bound=QWidget)


class LazyTab(QObject, Generic[P]):
    """One tab of ``tabs`` whose widget ``build()`` makes on first use (see the module docstring)."""

    def __init__(self, tabs: QTabWidget, build: Callable[[], P], name: str) -> None:
        super().__init__(tabs)
        self._tabs = tabs
        self._build_panel: Callable[[], P] | None = build
        self._panel: P | None = None
        self._building = False
        self._when_built: list[Callable[[P], object]] = []
        self._placeholder: QWidget | None = QWidget()
        self._placeholder.setObjectName(f"{name}Placeholder")
        tabs.addTab(self._placeholder, "")
        tabs.currentChanged.connect(self._on_current)

    @property
    def built(self) -> bool:
        return self._panel is not None

    @property
    def panel(self) -> P:
        """The panel (built now if it was not yet)."""
        panel = self._panel
        if panel is None:
            panel = self._build()
        return panel

    @property
    def widget(self) -> QWidget:
        """What the tab holds now: the panel, or its placeholder before it is built."""
        if self._panel is not None:
            return self._panel
        assert self._placeholder is not None
        return self._placeholder

    def on_built(self, callback: Callable[[P], object]) -> None:
        """Call ``callback(panel)`` once the panel exists (now, if it does), before it is shown."""
        if self._panel is not None:
            callback(self._panel)
        else:
            self._when_built.append(callback)

    def _build(self) -> P:
        if self._building:  # a callback asked for the panel while it is being built
            raise RuntimeError("a lazily built tab was asked for while it was being built")
        build, self._build_panel = self._build_panel, None
        assert build is not None
        self._building = True
        try:
            panel = build()
            self._panel = panel
            for callback in self._when_built:  # before the panel is in the tab: gated from the start
                callback(panel)
            self._when_built.clear()
        finally:
            self._building = False
        self._swap_in(panel)
        return panel

    def _swap_in(self, panel: P) -> None:
        tabs, placeholder = self._tabs, self._placeholder
        self._placeholder = None
        index = tabs.indexOf(placeholder) if placeholder is not None else -1
        if index >= 0:
            current = tabs.currentIndex() == index
            text, tip = tabs.tabText(index), tabs.tabToolTip(index)
            tabs.blockSignals(True)
            try:
                tabs.insertTab(index, panel, text)
                tabs.setTabToolTip(index, tip)
                tabs.removeTab(index + 1)
                if current:
                    tabs.setCurrentIndex(index)
            finally:
                tabs.blockSignals(False)
        if placeholder is not None:
            placeholder.deleteLater()

    @Slot(int)
    def _on_current(self, index: int) -> None:
        if self._placeholder is not None and self._tabs.widget(index) is self._placeholder:
            self._build()

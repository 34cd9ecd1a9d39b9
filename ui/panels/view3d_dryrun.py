"""The dry run bar of the 3D view: play the selected plan on the drawn arm, at a chosen speed
multiple, with a scrubber. It only moves the drawing: nothing is sent to the controller.

Time comes from :class:`app.view3d.path.DryRun` (the planner's geometry and time estimates);
a timer advances it :data:`DRY_RUN_FPS` times a second by the elapsed wall time times the
speed multiple. The timeline holds every loop of the plan; for a plan of more than one loop the
bar says which one plays ("loop 2 of 20").
"""

from __future__ import annotations

import time
from typing import Final

from PySide6.QtCore import QEvent, Qt, QTimer, Signal, Slot
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QSlider, QToolButton, QWidget

from app.plan.presenter import format_duration
from app.view3d.path import DryRun, DryRunState

DRY_RUN_FPS: Final = 30
SLIDER_STEPS: Final = 1000
SPEEDS: Final = (0.25, 0.5, 1.0, 2.0, 5.0, 10.0)
DEFAULT_SPEED_INDEX: Final = 2


class DryRunBar(QWidget):
    """Play / pause, speed, scrubber and time. Signal ``stateChanged(object)`` with a
    :class:`DryRunState`, or None when the dry run is left (the live arm shows again)."""

    stateChanged = Signal(object)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("DryRunBar")
        self.run: DryRun | None = None
        self.time = 0.0
        self._wall: float | None = None
        self.play_button = QToolButton(self)
        self.play_button.setCheckable(True)
        self.play_button.toggled.connect(self._on_play)
        self.stop_button = QToolButton(self)
        self.stop_button.clicked.connect(self.leave)
        self.speed_box = QComboBox(self)
        for speed in SPEEDS:
            self.speed_box.addItem(f"{speed:g}×", speed)
        self.speed_box.setCurrentIndex(DEFAULT_SPEED_INDEX)
        self.slider = QSlider(Qt.Orientation.Horizontal, self)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.valueChanged.connect(self._on_slider)
        self.time_label = QLabel(self)
        self.time_label.setMinimumWidth(110)
        self.loop_label = QLabel(self)
        self.loop_label.setObjectName("DryRunLoopLabel")
        self.caption = QLabel(self)
        self.timer = QTimer(self)
        self.timer.setInterval(1000 // DRY_RUN_FPS)
        self.timer.timeout.connect(self._tick)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        for w in (self.caption, self.play_button, self.stop_button, self.speed_box):
            layout.addWidget(w)
        layout.addWidget(self.slider, 1)
        layout.addWidget(self.loop_label)
        layout.addWidget(self.time_label)
        self.retranslate()
        self.set_run(None)

    def retranslate(self) -> None:
        self.caption.setText(self.tr("Dry run:"))
        self.play_button.setText(self.tr("Pause") if self.play_button.isChecked() else self.tr("Play"))
        self.play_button.setToolTip(self.tr("Play the plan on the drawn arm; nothing is sent to the robot"))
        self.stop_button.setText(self.tr("Live arm"))
        self.stop_button.setToolTip(self.tr("Leave the dry run and show the robot's arm again"))
        self.speed_box.setToolTip(self.tr("Speed of the dry run, times the planned speed"))
        self.slider.setToolTip(self.tr("Drag to any moment of the plan"))
        self._show_time()

    def changeEvent(self, event: QEvent) -> None:
        if event.type() == QEvent.Type.LanguageChange:
            self.retranslate()
        super().changeEvent(event)

    @property
    def active(self) -> bool:
        """Whether the arm shows the dry run (playing, or scrubbed away from the live arm)."""
        return self._active

    @property
    def speed(self) -> float:
        return float(self.speed_box.currentData())

    def set_run(self, run: DryRun | None) -> None:
        """A new timeline (the plan changed); leaves an ongoing dry run."""
        self.run = run
        usable = run is not None and run.duration > 0
        self._active = False
        self.play_button.setChecked(False)
        for w in (self.play_button, self.slider, self.speed_box):
            w.setEnabled(usable)
        self.stop_button.setEnabled(False)
        self.time = 0.0
        self.slider.blockSignals(True)
        self.slider.setValue(0)
        self.slider.blockSignals(False)
        self._show_time()

    @Slot()
    def leave(self) -> None:
        self.play_button.setChecked(False)
        self._active = False
        self.stop_button.setEnabled(False)
        self.stateChanged.emit(None)

    def seek(self, t: float) -> DryRunState | None:
        """Show the plan at ``t`` seconds (enters the dry run)."""
        if self.run is None or self.run.duration <= 0:
            return None
        self.time = max(0.0, min(self.run.duration, t))
        self._active = True
        self.stop_button.setEnabled(True)
        self.slider.blockSignals(True)
        self.slider.setValue(round(self.time / self.run.duration * SLIDER_STEPS))
        self.slider.blockSignals(False)
        self._show_time()
        state = self.run.at(self.time)
        self.stateChanged.emit(state)
        return state

    @Slot(bool)
    def _on_play(self, playing: bool) -> None:
        self.retranslate()
        if playing and self.run is not None:
            if self.time >= self.run.duration:
                self.time = 0.0
            self._wall = time.monotonic()
            self.seek(self.time)
            self.timer.start()
        else:
            self.timer.stop()
            self._wall = None

    @Slot()
    def _tick(self) -> None:
        if self.run is None or self._wall is None:
            self.timer.stop()
            return
        now = time.monotonic()
        self.advance((now - self._wall) * self.speed)
        self._wall = now

    def advance(self, seconds: float) -> None:
        """Move the dry run on by ``seconds`` of plan time (stops at the end)."""
        if self.run is None:
            return
        self.seek(self.time + seconds)
        if self.time >= self.run.duration:
            self.play_button.setChecked(False)

    @Slot(int)
    def _on_slider(self, value: int) -> None:
        if self.run is not None:
            self.seek(value / SLIDER_STEPS * self.run.duration)

    def _show_time(self) -> None:
        total = self.run.duration if self.run is not None else 0.0
        self.time_label.setText(f"{format_duration(self.time)} / {format_duration(total)}")
        self.loop_label.setText(self.loop_text())
        self.loop_label.setVisible(bool(self.loop_label.text()))

    def loop_text(self) -> str:
        """Which loop plays ("loop 2 of 20"); "" for a plan of one loop (or none)."""
        if self.run is None or self.run.loops == 1:
            return ""
        loop, _local = self.run.loop_at(self.time)
        if self.run.loops == 0:
            return self.tr("loop %1 (endless: every later loop is the same)").replace("%1", str(loop))
        return self.tr("loop %1 of %2").replace("%1", str(loop)).replace("%2", str(self.run.loops))

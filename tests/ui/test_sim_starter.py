"""``teachpad --sim`` starts the simulator process after the window's first paint, off the GUI
thread, and never leaves it running when the window closes first."""

from __future__ import annotations

from typing import Any

import pytest
from PySide6.QtWidgets import QWidget

from ui import main as teachpad
from ui.main import SimProcess, _SimStarter

pytestmark = pytest.mark.timeout(60)


def test_the_simulator_starts_after_the_first_paint(qtbot: Any, make_client: Any) -> None:
    window = QWidget()
    qtbot.addWidget(window)
    starter = _SimStarter(window)
    assert starter.sim is None  # nothing before the window painted
    try:
        with qtbot.waitSignal(starter.started, timeout=30_000) as started:
            window.show()
        sim = started.args[0]
        assert isinstance(sim, SimProcess) and starter.sim is sim
        client = make_client(port=sim.port)
        assert client.read_status().alarms == 0
        client.close()
    finally:
        starter.close()
    assert sim.process.poll() == 0  # stopped by itself when its stdin closed


def test_closing_while_it_starts_stops_it(qtbot: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    made: list[SimProcess] = []
    real_start = SimProcess.start

    def start(*args: Any, **kwargs: Any) -> SimProcess:
        sim = real_start(*args, **kwargs)
        made.append(sim)
        return sim

    monkeypatch.setattr(teachpad.SimProcess, "start", start)
    window = QWidget()
    qtbot.addWidget(window)
    starter = _SimStarter(window)
    starter.start()  # as after the first paint
    starter.close()  # the window closed at once: waits for the start, then stops the simulator
    assert len(made) == 1 and made[0].process.poll() is not None
    assert starter.sim is None


def test_a_window_that_never_paints_still_gets_its_simulator(
    qtbot: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Started minimized or on another desktop, the window does not paint: the simulator starts
    anyway, a little later."""
    monkeypatch.setattr(teachpad, "SIM_START_LATEST_MS", 100)
    window = QWidget()  # never shown
    qtbot.addWidget(window)
    starter = _SimStarter(window)
    try:
        with qtbot.waitSignal(starter.started, timeout=30_000) as started:
            pass
        sim = started.args[0]
        assert isinstance(sim, SimProcess) and starter.sim is sim
    finally:
        starter.close()
    assert sim.process.poll() == 0

"""The console's messages and confirmations (issue 15, item 4): an operator's emergency stop says so and
how to clear it; Abort, and closing with a session running, ask first (the dialog answered with qtbot);
no question without a session; the scope's axes read in units the signals can show."""

import numpy as np
import pytest
from PySide6.QtWidgets import QMessageBox

from tests.gui.conftest import DEMO, answer_question, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

OPERATOR = "Emergency stop (operator): force off"


def refuse_questions(console, monkeypatch):
    def ask(title, question):
        raise AssertionError(f"asked {title!r} without a session")
    monkeypatch.setattr(console, "confirm", ask)


def test_an_operator_emergency_stop_says_so_and_how_to_clear_it(idle_console, qapp):
    console = idle_console
    c = console.controller
    console.stop_button.click()
    faults = console.status.labels["faults"]
    wait_until(qapp, lambda: OPERATOR in faults.text(), 5)
    for text in (faults.text(), console.state_label.text(), console.status.message.text()):
        assert OPERATOR in text and "press Resume to clear" in text and "watchdog" not in text
    console.pause_button.click()  # Resume clears it
    wait_until(qapp, lambda: c.state in ("idle", "finished", "aborted"), 5)
    wait_until(qapp, lambda: "LATCHED" not in faults.text(), 5)


def test_abort_asks_first_no_keeps_the_session_yes_aborts_it(idle_console, qtbot, tmp_path):
    console = idle_console
    c = console.controller
    console.setup.participant.setText("ASK01")
    console.setup.results.setText(str(tmp_path))
    console.start_session(seed=1)
    assert c.in_session, console.setup.error.text()
    answer_question(console, qtbot, QMessageBox.StandardButton.No)
    console.abort_button.click()
    assert c.in_session and console.confirmation is None
    answer_question(console, qtbot, QMessageBox.StandardButton.Yes)
    console.abort_button.click()
    assert not c.in_session and c.state == "aborted"


def test_abort_without_a_session_asks_nothing(idle_console, monkeypatch):
    refuse_questions(idle_console, monkeypatch)
    assert not idle_console.controller.in_session
    assert idle_console.abort_session(confirm=True)


@pytest.fixture
def fake_console(qapp, tmp_path):
    """A console over a fake engine host (no process): closing it must not stop the shared console's engine."""
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController
    from tests.live.fakes import FakeHost

    controller = SessionController(audio="null", midi="none", make_host=FakeHost)
    console = Console(controller)
    console.timer.stop()  # the fake engine's status has no loop readouts for the status bar
    console.show()
    assert console.choose_protocol(str(DEMO))
    controller.host.state = "running"
    console.setup.participant.setText("ASK02")
    console.setup.results.setText(str(tmp_path))
    yield console
    if console.isVisible():
        console.abort_session()
        console.close()


def test_closing_with_a_session_running_asks_first(fake_console, qtbot):
    console = fake_console
    c = console.controller
    console.start_session(seed=2)
    assert c.in_session, console.setup.error.text()
    answer_question(console, qtbot, QMessageBox.StandardButton.No)
    console.close()
    assert console.isVisible() and c.in_session
    answer_question(console, qtbot, QMessageBox.StandardButton.Yes)
    console.close()
    assert not console.isVisible() and not c.in_session


def test_closing_without_a_session_asks_nothing(fake_console, monkeypatch):
    refuse_questions(fake_console, monkeypatch)
    fake_console.close()
    assert not fake_console.isVisible()


def tick_strings(plot):
    axis = plot.getAxis("left")
    low, high = plot.getViewBox().viewRange()[1]
    levels = axis.tickValues(low, high, max(axis.height(), 100))
    return [s for spacing, values in levels for s in axis.tickStrings(values, axis.autoSIPrefixScale * axis.scale, spacing)]


@pytest.mark.parametrize("size, prefixes", [
    (1e-33, {"v": "mm/s", "s": "mm/s", "f": "mN"}),  # a string decaying after a stop
    (1e-12, {"v": "mm/s", "s": "mm/s", "f": "mN"}),
    (0.0, {"v": "mm/s", "s": "mm/s", "f": "mN"}),
    (2.0, {"v": "m/s", "s": "m/s", "f": "N"}),  # large signals keep their own prefix
])
def test_scope_axes_never_read_finer_than_the_noise_floor(qapp, size, prefixes):
    from studyapp.gui.scope import Scope

    scope = Scope()
    scope.resize(800, 600)
    scope.show()
    scope.set_scene(5000.0, ["KALLEV"])
    n = 2500
    wave = size * np.sin(np.arange(n) / 40.0)
    block = {c: wave for c in ("position", "velocity_lvt", "velocity_true", "source_velocity",
                               "string_velocity", "force")}
    block.update(t=np.arange(n) / 5000.0, estimates={"KALLEV": wave}, end=n)
    scope.add(block)
    scope.redraw()
    for _ in range(20):
        qapp.processEvents()
    for where, unit in prefixes.items():
        plot = scope.plots[where]
        assert f"({unit})" in plot.getAxis("left").labelString()
        strings = tick_strings(plot)
        assert strings and not any("e" in s for s in strings), strings  # no "2e-33"
        low, high = plot.getViewBox().viewRange()[1]
        assert high - low >= 0.9 * {"v": 0.92e-3, "s": 0.92e-3, "f": 0.049}[where]  # 8 sigma of the floor
    scope.close()


def test_the_apparatus_panel_follows_a_controller_plugged_in(idle_console, qapp):
    console = idle_console
    c = console.controller
    status = c.engine.status()
    waiting = "none yet (JACK): plugging a controller in is picked up within 2 s"
    for midi, words in ((waiting, waiting), ("box:knobs (JACK)", "input box:knobs (JACK)"),
                        (waiting, waiting)):
        c.events.status.emit(status={**status, "midi": midi}, lost=0, knob_latency=(None, None))
        assert console.setup.midi.text().startswith(words)
    assert "on-screen knobs work meanwhile" in console.setup.midi.text()
    c.events.status.emit(status=status, lost=0, knob_latency=(None, None))  # the engine's own again


def test_shut_down_closes_mid_session_without_asking(fake_console, monkeypatch):
    console = fake_console
    console.start_session(seed=3)
    assert console.controller.in_session
    refuse_questions(console, monkeypatch)
    console.shut_down()  # Ctrl-C, an unattended run, a script: no one to ask
    assert not console.isVisible() and not console.controller.in_session

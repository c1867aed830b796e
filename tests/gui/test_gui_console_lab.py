"""The console in a lab (issue 22, items 7, 10, 13 and 15): the participant's space bar never pauses the
session, a session aborted can be resumed from the console as it stands, the participant never sees the
study's aim, and at 1,366 x 768 during a session the blinding tick and the status bar's warning are in view.
Offscreen Qt, the shared console and its engine."""

import json

import pytest
from PySide6.QtCore import QPoint, QRect, Qt
from PySide6.QtWidgets import QApplication, QScrollArea

from studyapp.experiment.protocol import load_protocol
from studyapp.live.controller import PAGE_SETTLE_S
from tests.gui.conftest import DEMO, ENGINE_START, ROOT, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"
LEVEL_CHECK_FIRST = """
[study]
name = "lab"
title = "An aim the participant must not read: noisiness of eight estimators"
tasks = ["rating"]
seed = 3

[apparatus]
rate = 5000.0

[[pages]]
kind = "calibration"
text = "Listen to the tone."
tone_hz = 440.0
level_dbfs = -20.0

[rating]
conditions = ["LVT", "LOWPASS"]
fmax = 1.0
instructions = "Rate the two dials."
"""


def events(folder):
    return [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]


@pytest.fixture
def lab_console(idle_console, qapp, tmp_path):
    """The shared console on a protocol whose first step is the headphone level check; demo again after."""
    console = idle_console
    protocol = tmp_path / "lab.toml"
    protocol.write_text(LEVEL_CHECK_FIRST)
    assert console.choose_protocol(str(protocol)), console.setup.error.text()
    wait_until(qapp, lambda: console.controller.engine is not None, ENGINE_START)
    console.setup.results.setText(str(tmp_path / "results"))
    yield console
    c = console.controller
    if c.in_session:
        console.abort_session()
    console.setup.resume.setChecked(False)
    console.setup.fill_session_info()
    assert console.choose_protocol(str(DEMO))
    wait_until(qapp, lambda: c.engine is not None, ENGINE_START)


def start(console, qapp, participant):
    console.setup.participant.setText(participant)
    console.start_button.click()
    assert console.setup.error.text() == ""
    wait_until(qapp, lambda: console.controller.playing, ENGINE_START)


def to_the_trial(console, qapp):
    """Acknowledge the pages up to the first trial, as their reader would."""
    c = console.controller
    while c.runner.trial.page is not None:
        step = c.runner.trial.step
        wait_until(qapp, lambda: c.page_age() >= PAGE_SETTLE_S, 5)
        c.acknowledge_page(c.runner.trial.page.by)
        wait_until(qapp, lambda: c.runner.trial.step != step, 10)


def test_the_space_bar_after_confirm_level_never_pauses(lab_console, qapp, qtbot):
    console, c = lab_console, lab_console.controller
    console.activateWindow()
    start(console, qapp, "P01")
    assert c.runner.trial.page.kind == "calibration"
    qtbot.mouseClick(console.page_controls.confirm_button, Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: c.runner.trial.step == 1, 10)
    to_the_trial(console, qapp)
    folder = c.session.folder
    for _ in range(3):  # the participant's space bar, wherever the keyboard focus is now
        qtbot.keyClick(QApplication.focusWidget() or console, Qt.Key.Key_Space)
        qtbot.wait(int(1000 * 0.2))
    assert c.state == "running"
    logged = events(folder)
    assert not [e for e in logged if e["type"] == "pause"]
    assert [e["on"] for e in logged if e["type"] == "bowing"] == [True, False, True]  # the bow, as space means


def test_a_session_aborted_resumes_from_the_console_as_it_stands(lab_console, qapp, tmp_path):
    console, c = lab_console, lab_console.controller
    setup = console.setup
    setup.experimenter.setText("A. Lead")
    setup.session_number.setValue(4)
    setup.notes.setText("first run")
    start(console, qapp, "P02")
    folder = c.session.folder
    console.abort_session()
    wait_until(qapp, lambda: c.state == "aborted", 10)
    setup.resume.setChecked(True)  # the experimenter's fields stay as they were: greyed, not passed on
    assert not any(w.isEnabled() for w in (setup.experimenter, setup.session_number, setup.notes, setup.order_row))
    start(console, qapp, "P02")
    assert c.session.folder == folder
    runs = [e for e in events(folder) if e["type"] == "run_start"]
    assert [e["resume"] for e in runs] == [False, True]
    info = json.loads((folder / "session.json").read_text())
    assert (info["experimenter"], info["session_number"], info["notes"]) == ("A. Lead", 4, "first run")
    console.abort_session()
    setup.resume.setChecked(False)
    assert setup.experimenter.isEnabled() and setup.notes.isEnabled()


def test_a_long_refusal_is_shown_whole(lab_console, qapp):
    console = lab_console
    console.resize(1366, 768)
    console.setup.show_error("experimenter: set when a session starts, not when it is resumed: allowed is to "
                             "leave it empty with resume; and a second sentence, long enough to wrap twice or more")
    for _ in range(10):
        qapp.processEvents()
    error = console.setup.error
    assert error.height() >= error.heightForWidth(error.width()), (error.height(), error.heightForWidth(error.width()))
    console.setup.show_error("")


def test_the_participant_never_sees_the_studys_aim(lab_console, qapp):
    console = lab_console
    aim = load_protocol(console.setup.protocol_path).title
    participant = console.participant_window
    assert participant.title.text() == "Listening study"
    start(console, qapp, "P03")
    for _ in range(5):
        qapp.processEvents()
    texts = [w.text() for w in participant.findChildren(type(participant.title)) if w.isVisibleTo(participant)]
    assert texts and not any(aim in t or "noisiness" in t for t in texts), texts
    assert aim in console.windowTitle()  # the experimenter's


def in_view(widget, console):
    """``widget`` is shown, inside the console, and not hidden past a scroll area's edge."""
    rect = QRect(widget.mapTo(console, QPoint(0, 0)), widget.size())
    if not widget.isVisibleTo(console) or not console.rect().contains(rect):
        return False
    parent = widget.parentWidget()
    while parent is not None and parent is not console:
        if isinstance(parent, QScrollArea):
            inner = QRect(widget.mapTo(parent.viewport(), QPoint(0, 0)), widget.size())
            return parent.viewport().rect().contains(inner)
        parent = parent.parentWidget()
    return True


def test_during_a_session_at_1366x768_the_blinding_tick_and_the_warnings_fit(idle_console, qapp, tmp_path):
    console, c = idle_console, idle_console.controller
    try:
        assert console.choose_protocol(str(SINCLAIR))
        wait_until(qapp, lambda: c.engine is not None and "estimate:KALFOAW" in console.scope.traces, ENGINE_START)
        console.resize(1366, 768)
        console.setup.results.setText(str(tmp_path / "results"))
        start(console, qapp, "P04")
        c.message("the emergency stop was cleared by the experimenter, and so on", level="warning")
        wait_until(qapp, lambda: console.status.labels["fps"].text(), 5)
        for _ in range(10):
            qapp.processEvents()
        assert in_view(console.blind, console)
        # the readouts at their widest (a loaded machine's counts), then the warning again: it is the latest
        console.status.show_status({"achieved_rate": 4998.0, "rate": 5000.0, "load_mean": 0.99, "load_max": 1.25,
                                    "deadline_misses": 12345, "audio_underruns": 678, "faults": 9,
                                    "fault_latched": False, "fault": "", "events_dropped": 4321}, lost=98765,
                                   knob_latency=(0.0123, 0.0456))
        warning = "the emergency stop was cleared by the experimenter, and so on"
        console.status.show_message(warning, 5000)
        for _ in range(10):
            qapp.processEvents()
        message = console.status.message
        shown = message.shown_text()
        assert message.text() == warning and len(shown.rstrip("…")) >= 40, (message.text(), shown)
    finally:
        if c.in_session:
            console.abort_session()
        assert console.choose_protocol(str(DEMO))
        wait_until(qapp, lambda: c.engine is not None, ENGINE_START)


def test_the_participants_bowing_surface_bows_through_the_controller(lab_console, qapp, qtbot):
    """Press, drag and release on the surface: the hand's target follows the pointer, logged as a trace."""
    console, c = lab_console, lab_console.controller
    start(console, qapp, "P05")
    to_the_trial(console, qapp)
    participant = console.participant_window
    participant.show()
    surface = participant.surface
    wait_until(qapp, lambda: surface.isVisible() and surface.width() > 100, 5)
    y = surface.height() // 2
    qtbot.mousePress(surface, Qt.MouseButton.LeftButton, pos=QPoint(surface.width() // 4, y))
    assert c.runner.bowing and c.runner.gesture == "live"
    for k in range(20):
        qtbot.mouseMove(surface, QPoint(surface.width() // 4 + k * surface.width() // 40, y))
        qtbot.wait(20)
    qtbot.mouseRelease(surface, Qt.MouseButton.LeftButton, pos=QPoint(surface.width() * 3 // 4, y))
    assert not c.runner.bowing
    trace = c.runner.trace.record(c.runner.trial.trial)
    assert trace is not None and trace["bow"][1] == 1 and trace["bow"][-1] == 0
    assert trace["x_mm"][-1] > trace["x_mm"][0]  # the pointer went right: so did the hand's target
    participant.hide()


def test_the_simulated_participant_replays_a_logged_gesture_in_the_console(lab_console, qapp, tmp_path):
    """``run --simulated-participant --replay-gesture``: its hand moves through the console as logged."""
    import math

    from studyapp.experiment.hand_trace import HandTrace

    console, c = lab_console, lab_console.controller
    trace = HandTrace()
    for k in range(100):  # 1 s of quick strokes at 4 Hz, 5 mm either side, the bow on
        trace.move(0.01 * k, 0.005 * math.sin(2 * math.pi * 4 * 0.01 * k), True)
    record = trace.record(1)
    console.replay = {0: record}
    console.setup.simulated.setChecked(True)
    try:
        start(console, qapp, "SIM01")
        folder = c.session.folder
        wait_until(qapp, lambda: c.state == "finished" or console.simulated is None, 600)
        assert c.state == "finished", console.log.toPlainText()[-2000:]
    finally:
        console.replay = None
        console.setup.simulated.setChecked(False)
        if c.in_session:
            console.abort_session()
    logged = events(folder)
    trials = {e["step"] for e in logged if e["type"] == "trial_start" and e["conditions"]}
    assert {e["step"] for e in logged if e["type"] == "gesture" and e["name"] == "live"} == trials
    traces = [e for e in logged if e["type"] == "hand_trace"]
    assert {e["step"] for e in traces} == trials
    for e in traces:
        assert max(e["x_mm"]) > 3.0 and min(e["x_mm"]) < -3.0  # the logged strokes, replayed

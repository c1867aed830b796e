"""Whole sessions through the console's own controls (pytest-qt, offscreen); responses end up on disk."""

import json
from pathlib import Path

import pytest
from PySide6.QtCore import QPoint, Qt
from PySide6.QtWidgets import QMessageBox

from studyapp.experiment.export import export_responses
from studyapp.model.fmax_knob import fmax_from_knob
from tests.gui.conftest import DEMO, ENGINE_START, answer_question, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

SESSION_TIME = 300.0  # s: the simulated participant bows ~15 s in real time; a loaded machine is slower

# The smallest session that has what the console's controls carry: a page, the rating (two knobs, so its
# normalised ratings are 0 and 1), an adjustment trial. The demo (a third condition, a practice trial and two
# more adjustment trials repeating the first) took 108 s idle (issue 39); the demo itself is played headless by
# tests/experiment/test_experiment_data_modes.py. The knob spans 1.5 decades so LEVANT breaks down (3.35 N,
# docs/breakdown.md) at knob ~36, not ~59: fewer 1.2 s probes on the way up.
SESSION = """
[study]
name = "console"
title = "Through the console"
tasks = ["rating", "adjustment"]
seed = 1

[apparatus]
rate = 5000.0
knobs = 8
pads = 8
gesture = "strokes"

[[pages]]
kind = "welcome"
text = "Welcome: rate two knobs, then adjust one."

[rating]
conditions = ["LOWPASS", "LEVANT"]
fmax = 1.0
instructions = "Rate the two knobs, then press the pad."

[adjustment]
conditions = ["LEVANT"]
trials = 1
ceiling = 40.0
decades = 1.5
instructions = "Bow the string, turn the knob up until it breaks down, then press the pad."
"""


def events_of(results):
    (path,) = Path(results).glob("*/*/*/events.jsonl")
    return [json.loads(line) for line in path.read_text().splitlines()]


def participant_texts(console):
    w = console.participant_window
    return " ".join(label.text() for label in (w.title, w.progress, w.instructions, w.notice))


def test_simulated_participant_plays_a_session_through_the_console(idle_console, qapp, qtbot, tmp_path):
    console = idle_console
    c = console.controller
    protocol = tmp_path / "console.toml"
    protocol.write_text(SESSION)
    assert console.choose_protocol(str(protocol)), console.setup.error.text()
    results = tmp_path / "results"
    turned, pressed, seen = [], [], []
    console.knobs.knob_turned.connect(lambda i, v: turned.append((i, v)))
    console.knobs.pad_pressed.connect(pressed.append)
    c.events.trial.connect(lambda **kw: seen.append(participant_texts(console)))
    c.events.response.connect(lambda **kw: seen.append(participant_texts(console)))
    console.setup.participant.setText("SIM01")
    console.setup.results.setText(str(results))
    console.setup.simulated.setChecked(True)
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    assert c.state == "starting", console.setup.error.text()
    # a lost engine (ENGINE_LOST waits for the experimenter) fails now, with the console's log, not after 480 s
    wait_until(qapp, lambda: c.state in ("finished", "aborted", "engine_lost"), ENGINE_START + SESSION_TIME)
    assert c.state == "finished", console.log.toPlainText()[-2000:]
    console.setup.simulated.setChecked(False)

    rows = export_responses(results)
    rating = rows[rows.task == "rating"]
    adjustment = rows[rows.task == "adjustment"]
    assert set(rating.condition) == {"LOWPASS", "LEVANT"} and set(adjustment.condition) == {"LEVANT"}
    conditions = {"LOWPASS", "LEVANT"}
    assert sorted(rating.rating)[0] == 0.0 and sorted(rating.rating)[-1] == 1.0
    assert (adjustment.fmax > 0).all() and (adjustment.fmax <= 40.0).all()
    assert set(rows.participant) == {"SIM01"}

    events = events_of(results)
    assert events[-2]["type"] == "session_end" and events[-1]["type"] == "run_stop"
    knob_events = [e for e in events if e["type"] == "knob"]
    pad_events = [e for e in events if e["type"] == "pad"]
    # every logged knob turn and pad press came through the on-screen controls
    assert knob_events and len(knob_events) == len(turned)
    assert [(e["index"], e["value"]) for e in knob_events] == turned
    assert len(pad_events) == len(pressed) == 2  # the rating, the adjustment trial (a page: Continue)
    pages = [e["kind"] for e in events if e["type"] == "response" and e.get("kind")]
    assert pages[0] == "welcome" and "instructions" in pages  # pages answered through the participant's window
    # it judges breakdown bowing with the protocol's gesture, as the paper's participants did (issue 20 item 3):
    # it never holds the handle still
    assert not any(e["type"] == "gesture" and e["name"] == "hold" for e in events)
    # the participant's window never named a condition
    assert seen and all(name not in text for text in seen for name in conditions)
    assert "Thank you" in console.participant_window.notice.text()
    # the analysis tab shows the study just run
    console.analyse_results()
    assert console.tabs.currentWidget() is console.analysis
    # SIM01 is simulated: left out, and the view says how to include it (issue 22 item 11)
    assert console.analysis.study is None and "--include-simulated" in console.analysis.status_label.text()
    console.analysis.include_simulated.setChecked(True)
    assert console.analysis.study is not None and list(console.analysis.study.participants) == ["SIM01"]
    console.tabs.setCurrentIndex(0)


PROTOCOL = """
[study]
name = "clicks"
title = "Scripted clicks"
tasks = ["rating", "adjustment"]
seed = 3

[apparatus]
rate = 5000.0

[rating]
conditions = ["LVT", "LOWPASS"]
fmax = 1.0
instructions = "Rate the knobs."

[adjustment]
conditions = ["LVT"]
trials = 1
ceiling = 40.0
decades = 2.0
instructions = "Turn up until it breaks, then press the pad."
"""


def test_scripted_clicks_pause_and_emergency_stop(idle_console, qapp, qtbot, tmp_path):
    console = idle_console
    c = console.controller
    protocol = tmp_path / "clicks.toml"
    protocol.write_text(PROTOCOL)
    results = tmp_path / "results"
    assert console.choose_protocol(str(protocol))
    console.setup.participant.setText("P01")
    console.setup.results.setText(str(results))
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: c.playing, ENGINE_START)
    assert console.trial_label.text() == "Trial 1 of 1, step 1 of 2"
    assert console.participant_window.progress.text() == "Trial 1 of 1"  # of the current task's trials
    pads = console.knobs.pads

    # rating: the confirm is refused until both knobs are rated
    # (every control goes through the worker, which applies its action and reports it back)
    qtbot.mouseClick(pads[0], Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: "confirm refused" in console.log.toPlainText(), 5)
    console.knobs.dials[0].setValue(110)
    wait_until(qapp, lambda: "at F_max = 1 N" in console.condition_label.text(), 5)
    console.blind.setChecked(True)
    assert console.condition_label.text() == "hidden (blinding)"
    assert all(label.text() == "" for label in console.knobs.captions)
    console.blind.setChecked(False)
    # paused: the participant's knobs do nothing
    qtbot.mouseClick(console.pause_button, Qt.MouseButton.LeftButton)
    assert c.state == "paused" and not console.knobs.isEnabled()
    c.knob(1, 77)
    qtbot.mouseClick(console.pause_button, Qt.MouseButton.LeftButton)
    assert c.state == "running"
    console.knobs.dials[1].setValue(15)
    # bow with the mouse on the bowing pad
    pad = console.bowing_pad
    y = pad.height() // 2
    qtbot.mousePress(pad, Qt.MouseButton.LeftButton, pos=QPoint(pad.width() // 3, y))
    for x in range(pad.width() // 3, 2 * pad.width() // 3, 10):
        qtbot.mouseMove(pad, QPoint(x, y))
    qtbot.mouseRelease(pad, Qt.MouseButton.LeftButton, pos=QPoint(2 * pad.width() // 3, y))
    qtbot.mouseClick(pads[0], Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: console.trial_label.text() == "Trial 1 of 1, step 2 of 2", 10)

    # abort (answering its question); starting the participant again is refused; resuming continues at trial 2
    answer_question(console, qtbot, QMessageBox.StandardButton.Yes)
    enabled = console.abort_button.isEnabled()
    qtbot.mouseClick(console.abort_button, Qt.MouseButton.LeftButton)
    # what the click met, should it not abort (a loaded run once found the session running and no question asked)
    assert c.state == "aborted" and console.start_button.isEnabled(), \
        f"state {c.state}, in session {c.in_session}, Abort enabled {enabled}, modal {qapp.activeModalWidget()}"
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    assert c.state == "aborted" and "already has a session" in console.setup.error.text()
    console.setup.resume.setChecked(True)
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: c.playing, ENGINE_START)
    console.setup.resume.setChecked(False)
    assert console.trial_label.text() == "Trial 1 of 1, step 2 of 2" and console.setup.error.text() == ""

    # adjustment: up to knob 60, emergency stop, the trial starts again from 0
    dial = console.knobs.dials[0]
    assert dial.value() == 0 and console.knobs.captions[0].text() == "F_max"
    dial.setValue(60)
    # the experimenter stops once the turn took effect (a turn reported after the stop is a late_control)
    wait_until(qapp, lambda: c.controls_taken >= c.controls_sent, 10)
    qtbot.mouseClick(console.stop_button, Qt.MouseButton.LeftButton)
    assert c.state == "emergency" and c.emergency
    qtbot.mouseClick(console.pause_button, Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: c.playing, 10)
    assert dial.value() == 0
    dial.setValue(30)
    # heard before it is confirmed (issue 31 item 4): the bow on at the setting
    wait_until(qapp, lambda: c.controls_taken >= c.controls_sent, 10)
    console.set_bowing(True)
    wait_until(qapp, lambda: c.runner.task.heard_fmax >= c.runner.task.fmax > 0, 10)
    qtbot.mouseClick(pads[0], Qt.MouseButton.LeftButton)
    wait_until(qapp, lambda: c.state == "finished", 10)

    rows = export_responses(results)
    rating = rows[rows.task == "rating"].set_index("condition")
    session = json.loads(next(results.glob("*/*/*/session.json")).read_text())
    first, second = session["schedule"][0]["conditions"]  # knob 1 plays the first, knob 2 the second
    assert {first, second} == {"LVT", "LOWPASS"}
    assert rating.loc[first, "value"] == 110 and rating.loc[second, "value"] == 15
    assert rating.loc[first, "rating"] == 0.0 and rating.loc[second, "rating"] == 1.0
    (fmax,) = rows[rows.task == "adjustment"].fmax
    assert fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))

    events = events_of(results)
    types = [e["type"] for e in events]
    assert types.count("response") == 2
    assert [e["resume"] for e in events if e["type"] == "run_start"] == [False, True]
    assert "pause" in types and "resume" in types and "emergency_stop" in types and "emergency_clear" in types
    assert not any(e["type"] == "knob" and e["value"] == 77 for e in events)  # ignored while paused
    assert any(e["type"] == "gesture" and e["name"] == "live" for e in events)  # the mouse took the bow
    assert [e["on"] for e in events if e["type"] == "bowing"][:2] == [True, False]
    restarts = [e for e in events if e["type"] == "trial_start" and e["task"] == "adjustment"]
    assert [e["restart"] for e in restarts] == [False, True, True]  # aborted, resumed; emergency stop
    adjust_knobs = [e["value"] for e in events if e["type"] == "knob" and e["task"] == "adjustment"]
    assert adjust_knobs[0] == 60 and adjust_knobs[-1] == 30

    assert console.choose_protocol(str(DEMO))
    wait_until(qapp, lambda: c.engine is not None, ENGINE_START)


def test_a_knob_waiting_for_pickup_is_shown_on_the_console_and_to_the_participant(idle_console):
    pickup = idle_console.controller.events.pickup
    pickup.emit(control="knob1", index=0, pending=True, text="turn the knob down to pick up")
    assert idle_console.pickup_label.text() == "knob1: turn the knob down to pick up"
    assert idle_console.participant_window.pickup.text() == "turn the knob down to pick up"
    pickup.emit(control="knob1", index=0, pending=False, text="")
    assert idle_console.pickup_label.text() == "" and idle_console.participant_window.pickup.text() == ""

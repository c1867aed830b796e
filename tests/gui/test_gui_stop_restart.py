"""An emergency stop in the simulated participant's first adjustment trial, then Resume (issue 31 item 4).

Before: the bow was never put back, the participant turned on to the knob's top over silence and its 40 N
was accepted, then it raised ("did not finish") and the session sat in "Running". Now the trial starts
again, the participant plays it again from its start, and no response is above the largest F_max heard.
"""

import json
from pathlib import Path

import pytest
from PySide6.QtCore import Qt

from tests.gui.conftest import ENGINE_START, wait_until

pytest.importorskip("pytestqt")

pytestmark = pytest.mark.gui

SESSION_TIME = 300.0  # s, as test_gui_session.py


def heard_in_attempts(events):
    """{step: largest F_max logged by a knob while the bow was on, in the step's last attempt}."""
    heard, bowing = {}, False
    for e in events:
        step = e.get("step")
        if e["type"] == "trial_start":
            heard[step], bowing = 0.0, False
        elif e["type"] == "bowing":
            bowing = e["on"]
        elif e["type"] == "knob" and bowing and e.get("fmax") is not None:
            heard[step] = max(heard[step], e["fmax"])
    return heard


@pytest.mark.xfail(strict=False, reason="issue 31 item 4, open: at a load of 20 on 2 cores the session was seen to "
                   "stall in a later adjustment trial after the restarted one was answered (below its heard F_max); "
                   "not diagnosed yet")
def test_esc_then_resume_in_the_first_adjustment_trial(idle_console, qapp, qtbot, tmp_path):
    console = idle_console
    c = console.controller
    errors = []
    c.events.message.connect(lambda text, level, topic: level == "error" and errors.append(text))
    console.setup.participant.setText("SIMESC")
    console.setup.results.setText(str(tmp_path))
    console.setup.simulated.setChecked(True)
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    console.setup.simulated.setChecked(False)

    def turned_up():
        runner = c.runner
        return (c.playing and runner is not None and runner.trial is not None and runner.trial.task == "adjustment"
                and runner.task is not None and runner.task.value >= 12)

    wait_until(qapp, turned_up, ENGINE_START + SESSION_TIME)
    qtbot.keyClick(console.participant_window, Qt.Key.Key_Escape)
    assert c.state == "emergency"
    qtbot.mouseClick(console.pause_button, Qt.MouseButton.LeftButton)  # Resume
    wait_until(qapp, lambda: c.state in ("finished", "aborted") or console.simulated is None, SESSION_TIME)
    wait_until(qapp, lambda: c.state in ("finished", "aborted"), 30)
    assert c.state == "finished"
    assert not [e for e in errors if "simulated participant" in e]

    (log,) = Path(tmp_path).glob("*/*/*/events.jsonl")
    events = [json.loads(line) for line in log.read_text().splitlines()]
    heard = heard_in_attempts(events)
    responses = [e for e in events if e["type"] == "response" and e["task"] == "adjustment"]
    assert responses and all(r["fmax"] <= heard[r["step"]] + 1e-9 for r in responses)
    stops = [e for e in events if e["type"] == "emergency_stop"]
    assert stops and stops[0]["by"] == "participant"  # Esc on the participant's window is the participant's

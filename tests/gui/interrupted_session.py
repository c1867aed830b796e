"""One session played by the simulated participant in the console, interrupted in its first adjustment trial
(issue 31 item 4): an emergency stop (Esc on the participant's window) then Resume, or a watchdog trip (the
engine's worker stopped by SIGSTOP until the watchdog cuts it) then Resume, which starts a new engine.

``play_interrupted`` plays it and judges it from the session's log: each adjustment response against the
largest F_max heard in its attempt (``heard_in_attempts``: a knob logged while the bow was on, from the
attempt's ``trial_start``), and whether the session stalled (no event logged for ``stall_s`` seconds while
it runs, or no end within ``session_s``). Used by tests/gui/test_gui_stop_restart.py (one try of each) and
scripts/esc_resume_tries.py (ten).
"""

import json
import os
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path

from PySide6.QtCore import Qt
from PySide6.QtTest import QTest

INTERRUPTS = ("esc", "watchdog")


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


@dataclass
class Outcome:
    state: str  # the controller's state at the end: "finished" unless it stalled or aborted
    stalled: str = ""  # why it was judged stalled ("" when it did not)
    above_heard: list = field(default_factory=list)  # adjustment responses above their attempt's heard F_max
    responses: int = 0  # adjustment responses
    errors: list = field(default_factory=list)  # error messages the console showed
    restarts: int = 0  # engines lost and restarted by this script's Resume (the planned one included)
    events: list = field(default_factory=list)


def _wait(app, predicate, timeout, step=0.01):
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            return False
        app.processEvents()
        time.sleep(step)
    return True


def _first_adjustment_turned_up(c, value):
    runner = c.runner
    return (c.playing and runner is not None and runner.trial is not None and runner.trial.task == "adjustment"
            and runner.task is not None and runner.task.value >= value)


def _interrupt(console, app, how):
    c = console.controller
    if how == "esc":
        QTest.keyClick(console.participant_window, Qt.Key.Key_Escape)
        assert c.state == "emergency", c.state
    else:
        pid = c.engine.process.pid
        os.kill(pid, signal.SIGSTOP)
        try:
            assert _wait(app, lambda: c.state == "engine_lost", 30), f"no watchdog trip: state {c.state}"
        finally:
            os.kill(pid, signal.SIGCONT)
    console.pause_button.click()  # Resume: clears the stop, or starts a new engine


def play_interrupted(console, app, results, participant, seed, how="esc", at_value=12, stall_s=60.0,
                     session_s=900.0):
    """Start ``participant``'s session (simulated, ``seed``) in ``results``, interrupt its first adjustment trial
    ``how`` once the knob is at ``at_value`` or above, Resume, and wait for its end; returns an ``Outcome``."""
    assert how in INTERRUPTS, how
    c = console.controller
    errors = []

    def on_message(text, level, topic):
        if level == "error":
            errors.append(text)

    c.events.message.connect(on_message)
    restarts = 0
    try:
        console.setup.participant.setText(participant)
        console.setup.results.setText(str(results))
        console.setup.resume.setChecked(False)
        console.setup.simulated.setChecked(True)
        session = console.start_session(seed=seed)
        console.setup.simulated.setChecked(False)
        assert session is not None, console.setup.error.text()
        log = Path(session.folder) / "events.jsonl"
        assert _wait(app, lambda: _first_adjustment_turned_up(c, at_value) or c.state in ("finished", "aborted"),
                     session_s), f"no adjustment trial reached knob {at_value}: state {c.state}"
        assert c.state not in ("finished", "aborted"), c.state
        _interrupt(console, app, how)
        restarts += how == "watchdog"
        end = time.monotonic() + session_s
        size, changed = log.stat().st_size, time.monotonic()
        stalled = ""
        while c.state not in ("finished", "aborted"):
            app.processEvents()
            time.sleep(0.01)
            now = time.monotonic()
            if c.state == "engine_lost":  # an unplanned trip (a loaded machine): the experimenter resumes
                console.pause_button.click()
                restarts += 1
            if log.stat().st_size != size:
                size, changed = log.stat().st_size, now
            elif c.state == "running" and now - changed > stall_s:
                stalled = f"nothing logged for {stall_s:g} s in state running"
                break
            if now > end:
                stalled = f"not finished within {session_s:g} s (state {c.state})"
                break
        state = str(c.state)
        if stalled:
            console.abort_session()
        events = [json.loads(line) for line in log.read_text().splitlines()]
    finally:
        c.events.message.disconnect(on_message)
    heard = heard_in_attempts(events)
    responses = [e for e in events if e["type"] == "response" and e["task"] == "adjustment"]
    above = [r for r in responses if r["fmax"] > heard.get(r["step"], 0.0) * (1 + 1e-9)]
    return Outcome(state=state, stalled=stalled, above_heard=above, responses=len(responses), errors=errors,
                   restarts=restarts, events=events)

"""A whole session as a participant lives it: the real console and participant window (offscreen Qt), a
real engine on the dummy JACK server, and every knob turn and pad press a real JACK MIDI message from
another process.

The protocol has every phase of a session: welcome, the headphone level check (the experimenter's
confirm), instructions, practice and "practice is over", both tasks with a transition between them, a
break, goodbye. The rating task's bow is the participant's (space bar, Bow button), the adjustment's is
put on the string by the protocol (``bow = "auto"``); both ask for ``min_listen_s`` of listening before a
confirm. Every wait is on a state the controller or the engine reports, never on a fixed sleep alone.
"""

import csv
import json
import math
import subprocess
import sys
import textwrap
import wave

import pytest
from PySide6.QtCore import Qt

from studyapp.experiment.export import export_responses
from studyapp.model.fmax_knob import fmax_from_knob
from studyapp.live.controller import PAGE_SETTLE_S
from tests.gui.conftest import ENGINE_START, line_within, wait_until

pytest.importorskip("pytestqt")

pytestmark = [pytest.mark.gui, pytest.mark.jack]

MIN_LISTEN_S = 0.3
CEILING, DECADES = 40.0, 2.0
PROTOCOL = f"""
[study]
name = "e2e"
title = "End to end"
tasks = ["rating", "adjustment"]
seed = 5

[apparatus]
rate = 5000.0

[rating]
conditions = ["LVT", "LOWPASS"]
fmax = 1.0
instructions = "Rate the two dials."
practice = 1
min_listen_s = {MIN_LISTEN_S}
bow = "participant"

[adjustment]
conditions = ["LVT", "LOWPASS"]
trials = 2
ceiling = {CEILING}
decades = {DECADES}
instructions = "Turn up until it breaks, then press the pad."
practice = 1
break_every = 2
min_listen_s = {MIN_LISTEN_S}
bow = "auto"

[[pages]]
kind = "welcome"
text = "Welcome, **reader**."

[[pages]]
kind = "calibration"
text = "Listen to the tone."
tone_hz = 440.0
level_dbfs = -20.0

[[pages]]
kind = "goodbye"
text = "That is all."
"""
# welcome, calibration, instructions, practice, practice over, rating, transition, instructions, practice,
# practice over, 2 trials, break, 2 trials, goodbye
STEPS = 16

# The participant's MIDI controller: an LPD8 (engine/midi.py ControlMap.lpd8: knob k on CC k, pad k on note
# 35 + k, channel 1) in another process, one command per stdin line, "ok" on stdout once it is sent.
CONTROLLER = textwrap.dedent("""
    import sys, time
    import rtmidi
    out = rtmidi.MidiOut(rtmidi.API_UNIX_JACK, "lpd8")
    for line in sys.stdin:
        word, *args = line.split()
        if word == "connect":   # the engine's virtual port (a replaced engine's may still be closing;
            # another console's engine waiting for a controller has a port of its own, "studyapp-PID:...")
            end = time.monotonic() + 30
            while True:
                ports = [i for i, name in enumerate(out.get_ports()) if name == "studyapp:studyapp MIDI in"]
                if len(ports) == 1 or time.monotonic() > end:
                    break
                time.sleep(0.05)
            if len(ports) != 1:
                sys.exit("not one studyapp port among " + repr(out.get_ports()))
            out.open_port(ports[0])
            time.sleep(0.2)
        elif word == "cc":
            out.send_message([0xB0, int(args[0]), int(args[1])])
        elif word == "pad":
            out.send_message([0x90, 35 + int(args[0]), 100])
            out.send_message([0x80, 35 + int(args[0]), 0])
        print("ok", flush=True)
    out.close_port()
    out.delete()
""")


# seconds from a knob message the engine has counted to the value in the task: the GUI reads the engine's events
# on its timer, which a loaded clean clone (load 8, 2026-11-28) kept from doing so within 10 s
KNOB_S = 30


class Lpd8:
    """The MIDI controller process; each message waits until the engine has counted it, so no two
    share a block (control changes in one block are coalesced: the participant turns, then turns again)."""

    def __init__(self, controller, app):
        self.controller, self.app = controller, app
        self.proc = subprocess.Popen([sys.executable, "-c", CONTROLLER], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.sent = 0

    def _command(self, line, messages):
        before = self.controller.engine.status()["midi_messages"]
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        assert line_within(self.proc, 60).strip() == "ok", self.proc.stderr.read()[-2000:]
        self.sent += messages
        wait_until(self.app, lambda: self.controller.engine.status()["midi_messages"] >= before + messages, 10)

    def connect(self):
        self.proc.stdin.write("connect\n")
        self.proc.stdin.flush()
        assert line_within(self.proc, 60).strip() == "ok", self.proc.stderr.read()[-2000:]

    def turn(self, knob, value):
        self._command(f"cc {knob + 1} {value}", 1)

    def press(self, pad):
        self._command(f"pad {pad + 1}", 2)  # note on, note off

    def close(self):
        if self.proc.poll() is None:
            self.proc.stdin.close()
            self.proc.wait(10)


def step_of(c):
    return c.runner.trial.step if c.runner is not None and c.runner.trial is not None else None


def wait_for_next_step(c, app, step):
    wait_until(app, lambda: c.state == "finished" or (c.playing and step_of(c) not in (None, step)), 10)


def listen(c, app, condition):
    """Bowing, with this condition selected, until the task has heard it for min_listen_s."""
    wait_until(app, lambda: c.runner.task.heard[condition] >= MIN_LISTEN_S, 10)


@pytest.fixture
def session_console(qapp, jack_server):
    from studyapp.gui.console import Console
    from studyapp.live.controller import SessionController

    controller = SessionController(audio="device", midi="virtual", hang_timeout=0.5)
    window = Console(controller)
    window.resize(1366, 768)
    window.show()
    window.participant_window.show()
    yield window
    window.shut_down()  # close() mid-session would ask (Console.confirm)


def test_a_participant_runs_a_whole_session_with_a_midi_controller(session_console, qapp, qtbot, tmp_path):
    console, c = session_console, session_console.controller
    participant = console.participant_window
    protocol = tmp_path / "e2e.toml"
    protocol.write_text(PROTOCOL)
    results = tmp_path / "results"
    assert console.choose_protocol(str(protocol)), console.setup.error.text()
    wait_until(qapp, lambda: c.engine is not None or c.host.state == "failed", ENGINE_START)
    assert "JACK" in c.engine.info["audio"] and "JACK" in c.engine.info["midi"]
    console.setup.participant.setText("P07")
    console.setup.results.setText(str(results))
    console.setup.experimenter.setText("A. Lead")
    console.setup.session_number.setValue(3)
    qtbot.mouseClick(console.start_button, Qt.MouseButton.LeftButton)
    assert c.state == "starting", console.setup.error.text()
    wait_until(qapp, lambda: c.playing or c.state == "aborted", ENGINE_START)
    assert c.playing, console.log.toPlainText()[-1000:]
    lpd8 = Lpd8(c, qapp)
    try:
        lpd8.connect()
        adjusted, rated, pages = {}, [], []
        while c.state != "finished":
            trial, task = c.runner.trial, c.runner.task
            step = trial.step
            if trial.page is not None:
                pages.append(trial.page.kind)
                assert not participant.page_view.isHidden() and participant.knobs.isHidden()
                if trial.page.by == "experimenter":
                    assert participant.page_view.continue_button.isHidden()
                    qtbot.mouseClick(console.page_controls.confirm_button, Qt.MouseButton.LeftButton)
                else:
                    wait_until(qapp, lambda: c.page_age() >= PAGE_SETTLE_S, 5)
                    if len(pages) % 2:  # every other page by the pad, the rest by the Continue button
                        lpd8.press(trial.page.pad)
                    else:
                        qtbot.mouseClick(participant.page_view.continue_button, Qt.MouseButton.LeftButton)
            elif trial.task == "rating":
                assert participant.page_view.isHidden() and not c.runner.bowing  # bow = "participant"
                # the best at the top, the worst at the bottom, each heard with the bow on
                for knob, value in enumerate((100, 20)):
                    condition = task.conditions[knob]
                    lpd8.turn(knob, value)
                    wait_until(qapp, lambda: task.values[condition] == value, KNOB_S)
                    if not c.runner.bowing:
                        if trial.practice:
                            qtbot.keyClick(participant, Qt.Key.Key_Space)
                        else:
                            qtbot.mouseClick(participant.bow_button, Qt.MouseButton.LeftButton)
                        assert c.runner.bowing and participant.bow_state.text() == "Bowing"
                    listen(c, qapp, condition)
                rated.append((trial.practice, dict(task.values)))
                lpd8.press(task.confirm_pad)
            else:
                assert trial.task == "adjustment" and c.runner.bowing  # bow = "auto"
                value = 25 + step
                lpd8.turn(0, 0)  # the knob, left up by the last trial, down through F_max 0: picked up
                lpd8.turn(0, value)
                wait_until(qapp, lambda: task.value == value, KNOB_S)
                listen(c, qapp, task.condition)
                adjusted[step] = value
                lpd8.press(task.confirm_pad)
            wait_for_next_step(c, qapp, step)
        assert lpd8.sent == c.engine.status()["midi_messages"]  # each one reached the engine, none else
    finally:
        lpd8.close()
    assert pages == ["welcome", "calibration", "instructions", "transition", "transition", "instructions",
                     "transition", "break", "goodbye"]
    assert "Thank you" in participant.notice.text()

    rows = export_responses(results)
    assert set(rows.task) == {"rating", "adjustment"}  # pages make no rows
    rating, adjustment = rows[rows.task == "rating"], rows[rows.task == "adjustment"]
    assert len(rating) == 2 * 2 and len(adjustment) == 1 + 2 * 2
    assert rating.practice.tolist() == [True, True, False, False]
    assert adjustment.practice.tolist() == [True, False, False, False, False]
    assert sorted(rows[~rows.practice & (rows.task == "adjustment")].groupby("condition").size()) == [2, 2]
    for (practice, values), (_, rows_of) in zip(rated, rating.groupby("step")):
        by_condition = rows_of.set_index("condition")
        for condition, value in values.items():
            assert by_condition.loc[condition, "value"] == value
            assert by_condition.loc[condition, "rating"] == (0.0 if value == 100 else 1.0)
    assert dict(zip(adjustment.step, adjustment.value)) == adjusted
    for value, fmax in zip(adjustment.value, adjustment.fmax):
        assert fmax == pytest.approx(fmax_from_knob(int(value), CEILING, DECADES))
    # timing: how long each trial took (at least the listening asked for), and the engine's health while it ran
    for column in ("duration", "deadline_misses", "underruns", "faults", "events_dropped"):
        assert rows[column].notna().all() and all(math.isfinite(v) and v >= 0 for v in rows[column]), column
    assert (rating.duration >= 2 * MIN_LISTEN_S).all() and (adjustment.duration >= MIN_LISTEN_S).all()
    assert set(rows.experimenter) == {"A. Lead"} and set(rows.session_number) == {3}
    assert set(rows.participant) == {"P07"}

    (folder,) = {path.parent for path in results.glob("*/*/*/events.jsonl")}
    events = [json.loads(line) for line in (folder / "events.jsonl").read_text().splitlines()]
    latencies = [e for e in events if e["type"] == "knob_latency"]
    assert latencies and all(e["midi"] == e["controls"] for e in latencies)  # every control came by MIDI
    assert all(0 < e["median"] <= e["max"] < 5.0 for e in latencies)
    acknowledged = [(e["kind"], e["by"]) for e in events if e["type"] == "response" and e["task"] == "page"]
    assert ("calibration", "experimenter") in acknowledged and len(acknowledged) == len(pages)
    with wave.open(str(folder / "audio.wav")) as wav:
        assert wav.getframerate() == 48000 and wav.getnframes() > 48000
    with open(folder / "audio_cues.csv", newline="") as f:
        cues = list(csv.DictReader(f))
    assert {int(row["step"]) for row in cues if row["event"] == "start"} == set(range(STEPS))

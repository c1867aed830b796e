"""events.jsonl stays byte-for-byte what it was: every record kind, its keys and their order.

One scripted session through the controller (a fake engine host, a stepping
clock) touches every kind of record the live session and its tasks write:
pages, practice, rating, adjustment, pickup, pause, emergency stop, a lost
engine, notes, volume, mute, the bow on the surface (hand_trace), an abort and
a resume that repairs a torn log. Its log, with the values that differ from run
to run (times, folders, the version) replaced by "*", is compared line by line
with ``golden/events.jsonl``, made by this test from the code before
experiment/records.py existed (``REGENERATE=1`` writes it again).
"""

import json
import os
from pathlib import Path

from studyapp.live.controller import SessionController
from tests.live.fakes import FakeHost, SteppingClock

GOLDEN = Path(__file__).parent / "golden" / "events.jsonl"
VARYING = {"mono", "wall", "crc", "app_version", "copy", "description", "median", "max", "when"}

PROTOCOL = """
[study]
name = "golden"
tasks = ["rating", "adjustment", "listen"]
seed = 3

[apparatus]
rate = 5000.0

[rating]
conditions = ["LVT", "LOWPASS"]
fmax = 1.0
instructions = "Rate the knobs."
practice = 1

[adjustment]
conditions = ["LVT"]
trials = 1
ceiling = 40.0
decades = 2.0
instructions = "Turn up until it breaks, then press the pad."
bow = "auto"

[listen]
conditions = ["LOWPASS"]
fmax = 2.0
duration_s = 0.2
instructions = "Listen."

[[pages]]
kind = "welcome"
text = "Welcome."

[[pages]]
kind = "calibration"
text = "Listen to the tone."
tone_hz = 440.0
level_dbfs = -20.0
"""


def normalised(path):
    lines = []
    for line in path.read_text().splitlines():
        record = json.loads(line)
        lines.append(json.dumps({k: "*" if k in VARYING else v for k, v in record.items()}))
    return lines


def up(c):
    c.host.state = "running"
    c.poll()


def through_pages(c):
    while c.runner is not None and c.runner.trial is not None and c.runner.trial.page is not None:
        c.acknowledge_page("experimenter")


def scripted_session(tmp_path):
    path = tmp_path / "golden.toml"
    path.write_text(PROTOCOL)
    results = tmp_path / "results"
    clock = SteppingClock(step=0.0)  # time stands still until the first page is on screen
    c = SessionController(audio="null", midi="none", make_host=FakeHost, clock=clock)
    c.load_protocol(str(path))
    up(c)
    c.start_session("P01", results)
    up(c)
    c.pad(0)  # too soon after the page appeared: taken as a double press
    c.poll()
    clock.step = 1.0
    c.pad(0)  # the welcome page, by the participant's pad
    c.poll()
    through_pages(c)  # the level check, the instructions
    c.set_volume(-6.0)
    c.set_mute(True)
    c.set_mute(False)
    c.add_note("a note")
    c.knob(0, 100), c.knob(1, 20), c.pad(0), c.poll()  # the practice rating
    through_pages(c)
    c.pause()
    c.resume()
    c.knob(0, 90), c.poll()
    c.bow_press(0.01)
    c.host.play(0.05)
    c.poll()
    c.bow_move(0.02)
    c.host.play(0.05)
    c.poll()
    c.bow_release()
    c.set_gesture("strokes")
    c.knob(1, 10), c.pad(0), c.poll()  # the rating trial
    through_pages(c)
    engine = c.host.engine
    engine.pending("knob1", 90 / 127, 0.0)
    c.poll()
    c.host.play(0.1)
    c.poll()
    engine.control("knob1", 0.0)
    engine.control("knob1", 30 / 127)
    c.poll()
    engine.broken = 1.0  # the worker's verdict: broken, then a latched fault
    c.host.play(0.05)
    c.poll()
    engine.latched = True
    c.host.play(0.05)
    c.poll()
    engine.latched, engine.broken = False, 0.0  # the fault stopped the session (issue 41, item 7): cleared
    c.clear_emergency()
    c.poll()
    engine.counters.update(deadline_misses=2, audio_underruns=1, audio_limited=3)
    c.emergency_stop()
    c.host.engine.latched = True
    c.clear_emergency()
    c.host.engine.latched = False
    c.poll()
    c.host.state = "failed"
    c.poll()
    c.restart_engine()
    up(c)
    c.abort()
    log = next(results.glob("*/*/*/events.jsonl"))
    with open(log, "a") as f:
        f.write('{"torn": ')  # a torn last line: the resume repairs it
    c.start_session("P01", results, resume=True)
    up(c)
    through_pages(c)
    for _ in range(40):  # the adjustment trial again, then listening
        if c.runner is None:
            break
        task = c.runner.trial.task
        if task == "adjustment":  # turned up, heard (the bow is the protocol's), confirmed
            c.knob(0, 30), c.poll()
            c.host.play(0.1)
            c.poll()
            c.pad(0), c.poll()
        else:
            c.host.play(0.1)
            c.poll()
            c.pad(0)
            c.poll()
        through_pages(c)
    c.start_session("P02", results)  # closing the console aborts it
    up(c)
    c.close()
    second = next(path for path in results.glob("*/*/*/events.jsonl") if path != log)
    return normalised(log) + normalised(second)


def test_the_log_of_a_scripted_session_is_the_golden_one(tmp_path):
    lines = scripted_session(tmp_path)
    if os.environ.get("REGENERATE"):
        GOLDEN.write_text("\n".join(lines) + "\n")
    kinds = {json.loads(line)["type"] for line in lines}
    assert len(kinds) >= 25, sorted(kinds)
    assert lines == GOLDEN.read_text().splitlines()

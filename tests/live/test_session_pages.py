"""Pages, the headphone level check, practice counts, bow auto and listening time in the session controller
(a fake engine host: no Qt, no worker process)."""

from pathlib import Path

import pytest

from studyapp.engine import commands as cmd
from studyapp.experiment.session_log import read_events
from studyapp.live.controller import PAGE_SETTLE_S, SessionController, State
from tests.live.fakes import FakeHost, SteppingClock

PROTOCOL = """
[study]
name = "pages"
tasks = ["rating", "adjustment"]
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
trials = 2
ceiling = 40.0
decades = 2.0
instructions = "Turn up until it breaks, then press the pad."
bow = "auto"
min_listen_s = 0.5
break_every = 1

[[pages]]
kind = "welcome"
text = "Welcome, **reader**."

[[pages]]
kind = "calibration"
text = "Listen to the tone."
tone_hz = 440.0
level_dbfs = -20.0
"""


@pytest.fixture
def c(tmp_path):
    path = tmp_path / "pages.toml"
    path.write_text(PROTOCOL)
    controller = SessionController(audio="null", midi="none", make_host=FakeHost, clock=SteppingClock())
    controller.load_protocol(str(path))
    controller.results = tmp_path / "results"
    up(controller)
    controller.seen = {name: [] for name in ("trial", "page", "refused", "bowing", "message")}
    for name, got in controller.seen.items():
        getattr(controller.events, name).connect(lambda got=got, **fields: got.append(fields))
    yield controller
    controller.close()


def up(c):
    c.host.state = "running"
    c.poll()


def start(c, resume=False):
    c.start_session("P01", c.results, resume=resume)
    up(c)


def log(c):
    (path,) = Path(c.results).glob("*/*/*/events.jsonl")
    return [{k: v for k, v in e.items() if k not in ("seq", "mono", "wall")} for e in read_events(path)]


def page(c):
    trial = c.runner.trial
    return trial.page.kind if trial is not None and trial.page is not None else None


def tones(engine):
    return engine.sent_of(cmd.ReferenceTone)


def test_a_page_holds_the_loop_silent_and_the_pad_acknowledges_it(c):
    start(c)
    engine = c.host.engine
    assert page(c) == "welcome" and c.runner.loop is None
    assert engine.sent[-4:] == [cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}, trial=c.trial_serial),
                                cmd.AudioCue(0, "page", 1, "start")]  # the page's span in the recording
    assert c.seen["page"] == [{"kind": "welcome", "title": "Welcome", "text": "Welcome, **reader**.",
                               "by": "participant", "step": 0, "tone_hz": None, "level_dbfs": None}]
    assert {k: c.seen["trial"][-1][k] for k in ("phase", "number", "of")} == {"phase": "page", "number": 1, "of": 7}
    c.set_bowing(True)  # nothing to bow on a page
    assert engine.sent_of(cmd.SetBowing)[-1] == cmd.SetBowing(False) and c.seen["bowing"][-1] == {"on": False}
    c.knob(0, 100)
    c.pad(1)  # not its pad
    c.poll()
    assert page(c) == "welcome" and engine.fmax == 0.0
    c.pad(0)
    c.poll()
    assert page(c) == "calibration"
    acknowledged = [e for e in log(c) if e["type"] == "response"]
    assert acknowledged == [{"step": 0, "task": "page", "type": "response", "trial": 1, "fmax": 0.0,
                             "kind": "welcome", "title": "Welcome", "by": "participant", "simulated": False}]


def test_the_level_check_plays_its_tone_until_the_experimenter_confirms_it(c):
    start(c)
    c.acknowledge_page("participant")  # the welcome page's Continue
    engine = c.host.engine
    assert page(c) == "calibration" and tones(engine) == [cmd.ReferenceTone(440.0, -20.0)]
    assert c.seen["page"][-1]["by"] == "experimenter" and c.seen["page"][-1]["tone_hz"] == 440.0
    c.pad(0)
    c.poll()
    c.acknowledge_page("participant")
    assert page(c) == "calibration"
    assert c.seen["refused"] == [{"reason": "the experimenter confirms this page"}] * 2
    assert "confirm refused: the experimenter confirms this page" in [m["text"] for m in c.seen["message"]]
    c.set_volume(-10.0)  # the experimenter turns the headphones down during the check
    c.acknowledge_page("experimenter")
    assert tones(engine) == [cmd.ReferenceTone(440.0, -20.0), cmd.ReferenceTone(level_dbfs=None)]
    assert page(c) == "instructions"
    (confirmed,) = [e for e in log(c) if e["type"] == "response" and e["kind"] == "calibration"]
    assert (confirmed["by"], confirmed["tone_hz"], confirmed["level_dbfs"]) == ("experimenter", 440.0, -20.0)
    assert confirmed["volume_db"] == -10.0  # the record keeps both: the tone's level and the volume in force


def test_the_tone_stops_on_pause_and_at_an_abort_and_resume_skips_acknowledged_pages(c):
    start(c)
    c.acknowledge_page("participant")
    engine = c.host.engine
    c.pause()
    assert tones(engine)[-1] == cmd.ReferenceTone(level_dbfs=None) and engine.trial == -c.trial_serial
    c.acknowledge_page("experimenter")  # paused: nothing happens
    assert page(c) == "calibration"
    c.resume()
    assert tones(engine)[-1] == cmd.ReferenceTone(440.0, -20.0) and engine.trial == c.trial_serial
    c.abort()
    assert c.state == State.ABORTED and tones(engine)[-1] == cmd.ReferenceTone(level_dbfs=None)
    start(c, resume=True)
    assert page(c) == "calibration" and c.runner.trial.step == 1  # not the welcome page again
    assert tones(c.host.engine) == [cmd.ReferenceTone(440.0, -20.0)]


def through_pages(c):
    while page(c) is not None:
        c.acknowledge_page("experimenter")


def test_trials_are_counted_by_phase_and_task_and_bow_auto_and_listening_time_hold(c):
    start(c)
    through_pages(c)
    c.knob(0, 100), c.knob(1, 20), c.pad(0), c.poll()  # the rating practice trial
    through_pages(c)
    c.knob(0, 90), c.knob(1, 10), c.pad(0), c.poll()  # the rating trial
    through_pages(c)
    counted = [(t["trial"].task, t["phase"], t["number"], t["of"]) for t in c.seen["trial"]
               if t["phase"] != "page"]
    assert counted == [("rating", "practice", 1, 1), ("rating", "trial", 1, 1), ("adjustment", "trial", 1, 2)]
    # bow = "auto": the adjustment trial starts with the bow on, logged
    engine = c.host.engine
    assert c.runner.bowing and engine.sent_of(cmd.SetBowing)[-1] == cmd.SetBowing(True)
    assert c.seen["bowing"][-1] == {"on": True}
    started = [e["type"] for e in log(c) if e.get("step") == c.runner.trial.step]
    assert started[:2] == ["trial_start", "bowing"]
    # min_listen_s = 0.5: 0.2 s heard with F_max above 0 is not enough
    c.knob(0, 30)
    c.poll()
    c.host.play(0.2)
    c.poll()
    c.pad(0)
    c.poll()
    assert c.seen["refused"][-1] == {"reason": "listen longer with the bow on: the string needs 0.3 s more"}
    assert page(c) is None
    c.host.play(0.3)
    c.poll()
    c.pad(0)
    c.poll()
    assert page(c) == "break"
    practice = [e for e in log(c) if e.get("practice")]
    assert practice and {e["step"] for e in practice} == {3}


def test_a_press_just_after_a_page_appears_is_taken_as_a_double_press(c):
    c.clock = SteppingClock(step=0.0)  # time stands still: every press comes at once
    start(c)
    assert page(c) == "welcome"
    c.pad(0)  # the second press of a double press
    c.poll()
    c.acknowledge_page("participant")
    assert page(c) == "welcome"
    refused = [e for e in log(c) if e["type"] == "acknowledge"]
    assert [(e["control"], e["accepted"]) for e in refused] == [("pad1", False), ("continue", False)]
    c.clock.now += PAGE_SETTLE_S
    c.acknowledge_page("participant")
    assert page(c) == "calibration"

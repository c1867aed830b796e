"""The session controller's state machine, driven with a fake engine host: no Qt, no worker process."""

import json
from pathlib import Path

import pytest

from studyapp.engine import commands as cmd
from studyapp.errors import UserError
from studyapp.experiment.session_log import read_events
from studyapp.model.fmax_knob import fmax_from_knob
from studyapp.live.controller import TRANSITIONS, SessionController, State
from studyapp.live.status_watch import CLEAR_TIMEOUT
from tests.live.fakes import LATENCY, LINK_INFO, FakeHost

PROTOCOL = """
[study]
name = "machine"
title = "State machine"
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

S = State
# What each transition must lead to (the spec; TRANSITIONS must list exactly these pairs).
EXPECTED = {
    **{(rest, "open"): S.STARTING for rest in (S.IDLE, S.FINISHED, S.ABORTED)},
    (S.STARTING, "engine_up"): S.RUNNING,
    (S.STARTING, "engine_failed"): S.ABORTED,
    (S.STARTING, "abort"): S.ABORTED,
    (S.RUNNING, "pause"): S.PAUSED,
    (S.PAUSED, "resume"): S.RUNNING,
    (S.RUNNING, "done"): S.FINISHED,
    (S.PAUSED, "done"): S.FINISHED,
    (S.EMERGENCY, "done"): S.EMERGENCY,  # the session ends; the stop holds until cleared
    **{(state, "abort"): S.ABORTED
       for state in (S.RUNNING, S.PAUSED, S.ENGINE_LOST, S.RESTARTING, S.CLEARING)},
    (S.EMERGENCY, "abort"): S.EMERGENCY,
    (S.RUNNING, "engine_failed"): S.ENGINE_LOST,
    (S.PAUSED, "engine_failed"): S.ENGINE_LOST,
    (S.ENGINE_LOST, "restart"): S.RESTARTING,
    (S.RESTARTING, "engine_up"): S.RUNNING,
    (S.RESTARTING, "engine_failed"): S.ENGINE_LOST,
    **{(state, "emergency"): S.EMERGENCY for state in S},
    (S.EMERGENCY, "engine_up"): S.EMERGENCY,
    (S.EMERGENCY, "clear"): S.CLEARING,
    (S.CLEARING, "cleared"): S.RUNNING,
    (S.CLEARING, "clear_timeout"): S.EMERGENCY,  # the worker never confirmed: the stop holds again
    (S.CLEARING, "engine_failed"): S.ENGINE_LOST,
    (S.RUNNING, "fault"): S.EMERGENCY,  # the engine latched a fault of its own (a device's): the session stops
    (S.PAUSED, "fault"): S.EMERGENCY,
    **{(rest, "fault"): S.EMERGENCY for rest in (S.IDLE, S.FINISHED, S.ABORTED)},  # the preview's fault too
}


@pytest.fixture
def controller(tmp_path):
    FakeHost.made.clear()
    path = tmp_path / "machine.toml"
    path.write_text(PROTOCOL)
    c = SessionController(audio="null", midi="none", make_host=FakeHost)
    c.load_protocol(str(path))
    c.results = tmp_path / "results"
    up(c)
    yield c
    c.close()


def up(c):
    c.host.state = "running"
    c.poll()


def fail(c):
    c.host.state = "failed"
    c.poll()


def start(c):
    """A new session, each with its own participant (one may not have two)."""
    c.participants = getattr(c, "participants", 0) + 1
    c.start_session(f"P{c.participants:02d}", c.results)


def log(c):
    """The session log, without each record's stamp (sequence number and times)."""
    (path,) = Path(c.results).glob("*/*/*/events.jsonl")
    stamps = ("seq", "mono", "wall")
    return [{k: v for k, v in event.items() if k not in stamps} for event in read_events(path)]


def play_rating(c):
    """Rate the two conditions (knob 1 high, knob 2 low) and confirm: the rating trial ends."""
    c.knob(0, 100)
    c.knob(1, 20)
    c.pad(0)
    c.poll()


def heard(c):
    """Bow at the setting in force for a moment: a confirm is taken only for what was heard."""
    c.poll()  # the worker's report of the knob: the setting in force
    c.set_bowing(True)
    c.host.play(0.05)
    c.poll()


def reach(c, state):
    """Drive the controller into ``state`` through its public methods and the engine's states."""
    if state == S.IDLE:
        return
    if state in (S.FINISHED, S.ABORTED):
        reach(c, S.RUNNING)
        if state == S.ABORTED:
            c.abort()
        else:
            play_rating(c)
            c.knob(0, 30)
            heard(c)
            c.pad(0)
            c.poll()
        return
    start(c)
    if state == S.STARTING:
        return
    up(c)
    if state == S.RUNNING:
        return
    if state == S.PAUSED:
        c.pause()
    elif state in (S.EMERGENCY, S.CLEARING):
        c.emergency_stop()
        if state == S.CLEARING:
            c.host.engine.latched = True  # the worker latched the stop; clearing waits for it
            c.clear_emergency()
    elif state in (S.ENGINE_LOST, S.RESTARTING):
        fail(c)
        if state == S.RESTARTING:
            c.restart_engine()


def take(c, state, event):
    """Make ``event`` happen in ``state`` the way it happens in use."""
    if event == "open":
        start(c)
    elif event == "engine_up":
        if state == S.EMERGENCY:
            reach_emergency_while_starting(c)
        up(c)
    elif event == "engine_failed":
        fail(c)
    elif event == "cleared":
        c.host.engine.latched = False
        c.poll()
    elif event == "fault":  # the worker latches a fault, its force word still set: not a stop
        c.host.engine.latched = True
        c.status_watch.next_status = 0.0
        c.poll()
    elif event == "clear_timeout":
        c.host.engine.latched = True  # the worker never confirms the clear
        started = c.clock()
        c.clock = lambda: started + CLEAR_TIMEOUT + 1.0  # still latched, past the wait
        c.poll()
    else:
        {"abort": c.abort, "pause": c.pause, "resume": c.resume, "emergency": c.emergency_stop,
         "clear": c.clear_emergency, "restart": c.restart_engine, "done": lambda: c.fire("done")}[event]()


def test_a_fault_of_the_engines_own_stops_the_session_says_so_and_resume_repeats_the_trial(controller):
    # issue 41, item 7: on main a device fault left the session "Running" with no force
    c = controller
    messages = []
    c.events.message.connect(lambda text, level, topic: messages.append((level, text)))
    start(c)
    up(c)
    c.host.engine.latched = True
    c.status_watch.next_status = 0.0
    c.poll()
    assert c.state == S.EMERGENCY and c.stopped_by == "fault"
    assert c.stop_text.startswith("Stopped by a fault:") and "press Resume" in c.stop_text
    assert ("error", c.stop_text) in messages
    assert not c.accepting  # no knob or pad is taken against a force that is off
    c.clear_emergency()
    assert c.state == S.CLEARING
    c.host.engine.latched = False
    c.poll()
    assert c.state == S.RUNNING
    c.emergency_stop()  # the operator's stop afterwards reads as the operator's
    assert c.stop_text.startswith("Emergency stop (operator)")


def test_a_clear_the_worker_never_confirms_gives_the_stop_back_instead_of_clearing_for_good(controller):
    # on main a worker that refused the clear (its loop latched its own fault) left the console Clearing for good
    c = controller
    now = [100.0]
    c.clock = lambda: now[0]
    messages = []
    c.events.message.connect(lambda text, level, topic: messages.append((level, text)))
    start(c)
    up(c)
    engine = c.host.engine
    c.emergency_stop()
    c.clear_emergency()
    engine.latched = True  # the worker's fault stays latched (the clear lost, or latched again)
    now[0] += CLEAR_TIMEOUT - 0.1
    c.poll()
    assert c.state == S.CLEARING and engine.status_block.force_enable
    now[0] += 0.2
    c.poll()
    assert c.state == S.EMERGENCY and engine.status_block.force_enable is False
    assert any(level == "error" and "did not confirm the clear" in text and "fault latched: True" in text
               for level, text in messages)
    assert [e["type"] for e in log(c)].count("emergency_stop") == 2  # the stop holds again, logged
    engine.latched = False  # Resume again: this time the worker confirms
    c.clear_emergency()
    c.poll()
    assert c.state == S.RUNNING


def reach_emergency_while_starting(c):
    c.clear_emergency()
    c.abort()
    c.poll()
    start(c)
    c.emergency_stop()


def test_the_table_is_the_spec():
    assert set(TRANSITIONS) == set(EXPECTED)


@pytest.mark.parametrize(("state", "event"), sorted(EXPECTED), ids=lambda x: str(x))
def test_every_transition(controller, state, event):
    c = controller
    reach(c, state)
    assert c.state == state
    take(c, state, event)
    assert c.state == EXPECTED[(state, event)]


def test_events_a_state_does_not_list_are_ignored(controller):
    c = controller
    c.resume()
    c.pause()
    c.restart_engine()
    assert c.state == S.IDLE and not c.fire("cleared")


def test_a_knob_acts_in_the_worker_once_and_reaches_the_task(controller):
    c = controller
    start(c)
    up(c)
    engine = c.host.engine
    before = len(engine.sent_of(cmd.SetFmax))
    c.knob(0, 100)  # rating knob 1: the worker selects its condition at the rating F_max
    c.poll()
    assert engine.fmax == 1.0 and c.runner.task.values[c.runner.task.conditions[0]] == 100
    # one SetFmax, by the worker's own action: the runner's wish for the same F_max is not sent again
    assert len(engine.sent_of(cmd.SetFmax)) == before + 1
    assert c.latency.last == LATENCY
    c.knob(1, 20)
    c.pad(0)
    c.poll()
    # the adjustment trial: knob 1 sets F_max on the protocol's logarithmic scale, in the worker
    c.knob(0, 30)
    c.poll()
    assert engine.fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))
    assert c.runner.task.fmax == engine.fmax
    records = [e for e in log(c) if e["type"] == "knob_latency"]
    assert records == [{"step": 0, "task": "rating", "type": "knob_latency", "controls": 2, "midi": 0,
                        "median": LATENCY, "max": LATENCY}]


def test_midi_and_controls_of_an_old_or_held_trial_do_not_reach_the_task(controller):
    c = controller
    start(c)
    up(c)
    engine = c.host.engine
    engine.control("knob1", 64 / 127)  # a MIDI knob
    c.poll()
    task = c.runner.task
    assert task.values[task.conditions[0]] == 64
    c.pause()
    c.knob(1, 10)  # on screen while paused: refused
    engine.control("knob2", 10 / 127)  # MIDI while paused: the worker holds no mapping, the task ignores it
    c.poll()
    assert task.values[task.conditions[1]] is None
    assert engine.trial == -c.trial_serial and engine.actions == {}
    c.resume()
    assert engine.fmax == 1.0 and engine.trial == c.trial_serial


def test_samples_reach_the_trial_only_while_it_plays_and_the_verdict_is_the_workers(controller):
    c = controller
    start(c)
    up(c)
    c.knob(0, 100)
    c.poll()
    task = c.runner.task
    c.host.play(0.1)
    c.poll()
    assert task.elapsed == pytest.approx(0.1)
    c.pause()
    c.host.play(0.2)
    c.poll()
    c.resume()
    c.host.engine.broken = 1.0
    c.host.play(0.05)  # resumed: this block counts, and the worker calls it broken
    c.poll()
    assert task.elapsed == pytest.approx(0.15)
    stability = [e for e in log(c) if e["type"] == "stability"]
    assert stability == [{"step": 0, "task": "rating", "type": "stability", "broken": True, "score": 0.002,
                          "fmax": 1.0}]


def test_emergency_stop_zeroes_at_once_and_the_trial_starts_again_when_cleared(controller):
    c = controller
    start(c)
    up(c)
    play_rating(c)
    engine = c.host.engine
    c.knob(0, 60)
    c.poll()
    c.emergency_stop()
    assert c.state == S.EMERGENCY and engine.status_block.force_enable is False
    assert engine.sent[-3:] == [cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}, trial=-2)]
    assert not c.accepting
    c.knob(0, 90)  # refused
    engine.latched = True
    c.clear_emergency()
    assert c.state == S.CLEARING and engine.status_block.force_enable and engine.sent[-1] == cmd.ClearFault()
    c.poll()
    assert c.state == S.RUNNING and c.runner.task.value == 0 and engine.fmax == 0.0
    events = log(c)
    # the interrupted attempt's fault counts, then the trial again
    assert [e["type"] for e in events][-6:] == ["emergency_stop", "emergency_clear", "resume", "knob_latency",
                                                "trial_health", "trial_start"]
    assert [e["value"] for e in events if e["type"] == "knob" and e["task"] == "adjustment"] == [60]
    assert [e["restart"] for e in events if e["type"] == "trial_start" and e["task"] == "adjustment"] == [
        False, True]


def test_an_emergency_stop_while_the_engine_starts_holds_the_new_engine(controller):
    c = controller
    start(c)
    c.emergency_stop()
    up(c)
    engine = c.host.engine
    assert c.state == S.EMERGENCY and engine.status_block.force_enable is False
    assert engine.fmax == 0.0 and engine.actions == {}
    engine.latched = True
    c.clear_emergency()
    engine.latched = False
    c.poll()
    assert c.state == S.RUNNING and c.runner.trial.step == 0


def test_a_lost_engine_is_replaced_and_the_trial_starts_again(controller):
    c = controller
    start(c)
    up(c)
    c.knob(0, 100)
    c.poll()
    lost = c.host
    fail(c)
    assert c.state == S.ENGINE_LOST and c.engine is None
    c.restart_engine()
    assert c.state == S.RESTARTING and c.host is not lost and lost.stopped
    assert c.host.config == lost.config  # the same seed and scene
    up(c)
    assert c.state == S.RUNNING and c.runner.loop.engine is c.host.engine
    events = log(c)
    assert [e["type"] for e in events if e["type"] in ("engine", "engine_failed")] == [
        "engine", "engine_failed", "engine"]
    assert [e["restart"] for e in events if e["type"] == "trial_start"] == [False, True]
    assert events[-1]["restored_knobs"] == 1  # the rating knob turned before the loss comes back


def test_after_a_session_the_engine_is_the_preview_again(controller):
    c = controller
    reach(c, S.FINISHED)
    engine = c.host.engine
    assert engine.actions == cmd.default_actions(["LVT", "LOWPASS"])
    c.knob(0, 127)  # the live knob 1: F_max over the live range
    c.poll()
    assert engine.fmax == 20.0
    events = log(c)
    assert events[-2]["type"] == "session_end" and events[-1] == {"type": "run_stop", "reason": "done"}


def test_what_a_resume_repaired_reaches_the_console_as_a_warning(controller):
    c = controller
    start(c)
    up(c)
    c.abort()
    (described,) = Path(c.results).glob("*/*/*/session.json")
    described.write_text(described.read_text()[:20])  # truncated, as by a crash mid-write
    said = []
    c.events.message.connect(lambda text, level, topic: said.append((level, text)))
    c.start_session("P01", c.results, resume=True)
    warnings = [text for level, text in said if level == "warning"]
    assert any("rebuilt from events.jsonl" in text for text in warnings), said
    assert json.loads(described.read_text())["participant"] == "P01"


def test_a_knob_waiting_for_pickup_is_announced_kept_from_the_task_and_its_pickup_logged(controller):
    c = controller
    start(c)
    up(c)
    c.knob(0, 100)
    c.knob(1, 20)
    c.pad(0)
    c.poll()  # the rating done: the adjustment trial starts at F_max 0
    shown = []
    c.events.pickup.connect(lambda **fields: shown.append(fields))
    engine = c.host.engine
    engine.pending("knob1", 90 / 127, 0.0)  # the physical knob still high
    engine.pending("knob1", 60 / 127, 0.0)
    c.poll()
    assert shown == [{"control": "knob1", "index": 0, "pending": True, "text": "turn the knob down to pick up"}]
    assert c.runner.task.value == 0 and engine.fmax == 0.0
    c.host.play(0.2)
    c.poll()
    engine.control("knob1", 0.0)  # through 0: picked up
    engine.control("knob1", 30 / 127)
    c.poll()
    assert shown[-1] == {"control": "knob1", "index": 0, "pending": False, "text": ""}
    assert c.runner.task.value == 30 and engine.fmax == pytest.approx(fmax_from_knob(30, 40.0, 2.0))
    (pickup,) = [e for e in log(c) if e["type"] == "pickup"]
    assert pickup == {"step": 1, "task": "adjustment", "type": "pickup", "control": "knob1", "trial": 1,
                      "when": pytest.approx(0.2), "ignored": 2}


def test_each_trial_logs_the_engine_faults_counted_while_it_ran(controller):
    c = controller
    start(c)
    engine = c.host.engine
    engine.counters.update(deadline_misses=5, audio_underruns=1, faults=0, events_dropped=7, audio_limited=4)  # before
    up(c)
    c.knob(0, 100)
    c.knob(1, 20)
    engine.counters.update(deadline_misses=8, audio_underruns=3, events_dropped=7, audio_limited=10)
    c.pad(0)
    c.poll()
    engine.counters.update(deadline_misses=9, faults=1, events_dropped=10, audio_limited=12)
    c.abort()
    health = [e for e in log(c) if e["type"] == "trial_health"]
    assert health == [
        {"step": 0, "task": "rating", "type": "trial_health", "trial": 1,
         "deadline_misses": 3, "underruns": 2, "faults": 0, "events_dropped": 0, "limited": 6},
        {"step": 1, "task": "adjustment", "type": "trial_health", "trial": 1,
         "deadline_misses": 1, "underruns": 0, "faults": 1, "events_dropped": 3, "limited": 2},
    ]


def test_each_session_engine_records_the_audio_with_a_cue_at_each_trial_start_and_end(controller):
    c = controller
    start(c)
    folder = c.session.folder
    up(c)
    first = c.host.engine
    recording = (cmd.RecordAudio, cmd.AudioCue, cmd.InstallActions)
    sent = [x for x in first.sent if isinstance(x, recording)]
    # recording starts as the engine comes up; the trial's cue follows its mapping, at the same block
    assert sent[0] == cmd.RecordAudio(str(folder / "audio.wav"))
    assert isinstance(sent[1], cmd.InstallActions) and sent[1].trial == 1
    assert sent[2:] == [cmd.AudioCue(0, "rating", 1, "start")]
    play_rating(c)  # the rating trial ends, the adjustment trial starts
    fail(c)
    c.restart_engine()
    up(c)  # a new engine: a new recording (the worker picks audio-2.wav), the trial starts again
    second = c.host.engine
    c.knob(0, 30)
    heard(c)
    c.pad(0)
    c.poll()
    assert c.state == S.FINISHED
    cues = [(x.step, x.task, x.trial, x.event) for x in first.sent_of(cmd.AudioCue)]
    assert cues == [(0, "rating", 1, "start"), (0, "rating", 1, "end"), (1, "adjustment", 1, "start")]
    assert first.sent_of(cmd.RecordAudio) == [cmd.RecordAudio(str(folder / "audio.wav"))]
    assert [x for x in second.sent if isinstance(x, (cmd.RecordAudio, cmd.AudioCue))] == [
        cmd.RecordAudio(str(folder / "audio.wav")), cmd.AudioCue(1, "adjustment", 1, "start"),
        cmd.AudioCue(1, "adjustment", 1, "end"), cmd.RecordAudio(None)]


def test_a_turn_the_worker_applied_before_an_emergency_stop_is_logged_but_not_given_to_the_new_attempt(controller):
    c = controller
    start(c)
    up(c)
    play_rating(c)
    engine = c.host.engine
    c.knob(0, 60)  # the worker applies it at once ...
    report = engine.controls()  # ... and its report is late (a loaded machine)
    c.emergency_stop()
    c.clear_emergency()
    c.poll()
    assert c.state == S.RUNNING and c.trial_serial == report[0].trial + 1
    engine._controls.extend(report)  # it arrives while the next attempt runs
    c.poll()
    assert c.runner.task.value == 0
    events = log(c)
    late = [e for e in events if e["type"] == "late_control"]
    assert late == [{"step": 1, "task": "adjustment", "type": "late_control", "control": "knob1", "value": 60}]
    assert not any(e["type"] == "knob" and e["task"] == "adjustment" for e in events)
    assert engine.fmax == 0.0


def test_a_session_resumed_on_another_rig_is_asked_about_and_logged(controller):
    # issue 41, item 9: P01 started on the emulator, aborted, resumed on the simulated device with no question
    c = controller
    c.apparatus.device, c.devices.info = "/tmp/emulator", dict(LINK_INFO)  # the console runs on a link device
    start(c)
    up(c)  # its engine record carries the device (the fake engine reports the console's device below)
    c.abort()
    c.apparatus.device, c.devices.info = None, None  # now the simulated device
    asked = []

    def refuse(question):
        asked.append(question)
        return False

    with pytest.raises(UserError, match="last ran on studyapp emulator \\(serial EMU-0000\\)"):
        c.start_session("P01", c.results, resume=True, confirm_rig=refuse)
    assert not c.in_session and "the simulated device" in asked[0]
    c.start_session("P01", c.results, resume=True, confirm_rig=lambda question: True)
    up(c)
    changes = [e for e in log(c) if e["type"] == "rig_change"]
    assert [change["accepted"] for change in changes] == [False, True]  # the refusal logged too
    assert changes[1]["now"] == {"kind": "simulated", "latency_ms": 0.0}
    assert changes[1]["before"]["info"]["serial"] == "EMU-0000"
    c.abort()
    c.start_session("P01", c.results, resume=True, confirm_rig=lambda question: pytest.fail("asked again"))
    up(c)  # the last run was on the simulated device already: nothing to ask

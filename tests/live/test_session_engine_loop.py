"""``EngineLoop``: the runner's loop played by the engine (no Qt, no worker: the engine is a recording fake)."""

import numpy as np
import pytest

from studyapp.engine import commands as cmd
from studyapp.errors import ParameterError
from studyapp.live.engine_loop import EngineLoop

RATE = 5000.0
RATING = {"knob1": ("select", "KALLEV", 1.0)}


class RecordingEngine:
    """The parts of ``Engine`` that EngineLoop uses; commands are recorded, status is settable."""

    def __init__(self, names):
        self.names = list(names)
        self.config = type("Config", (), {"rate": RATE})()
        self.sent = []
        self.fault = ""
        self.latched = False

    def send(self, command):
        self.sent.append(command)

    def status(self):
        return {"fault": self.fault, "fault_latched": self.latched}


def block(trials, broken, score, start=0):
    n = len(trials)
    return {"force": np.arange(n, dtype=float), "trial": np.asarray(trials, dtype=float),
            "broken": np.asarray(broken, dtype=float), "stability_score": np.asarray(score, dtype=float),
            "estimates": {"KALLEV": np.arange(n, dtype=float) + 100}, "start": start, "end": start + n}


def test_a_trial_starts_silent_at_rest_and_tags_its_samples_with_its_number():
    engine = RecordingEngine(["KALLEV"])
    EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "hold", trial=4, actions=RATING)
    assert engine.sent == [cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.ResetString(),
                                         cmd.SetGesture("hold"), cmd.SetSource("KALLEV"),
                                         cmd.InstallActions(RATING, trial=4, positions={})]


def test_what_the_worker_applied_from_a_knob_is_not_sent_again():
    engine = RecordingEngine(["KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "hold", trial=1, actions=RATING)
    engine.sent.clear()
    loop.applied((cmd.SetSource("KALLEV"), cmd.SetFmax(1.0)))  # the worker ran knob 1's action
    loop.set_source("KALLEV")
    loop.set_fmax(1.0)
    assert engine.sent == []
    loop.set_fmax(2.0)
    assert engine.sent == [cmd.SetFmax(2.0)]


def test_hold_zeroes_takes_the_knobs_away_and_gives_the_settings_back():
    engine = RecordingEngine(["KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "hold", trial=2, actions=RATING)
    loop.set_fmax(2.5)
    loop.set_bowing(True)
    engine.sent.clear()
    loop.hold(True)
    loop.set_fmax(4.0)  # the runner moves on while held: nothing reaches the device
    assert engine.sent == [cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.InstallActions({}, trial=-2)]
    engine.sent.clear()
    loop.hold(False)
    assert engine.sent == [cmd.SetFmax(4.0), cmd.SetBowing(True), cmd.InstallActions(RATING, trial=2)]


def test_consume_keeps_only_this_trials_samples_and_the_workers_verdict():
    engine = RecordingEngine(["KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "strokes", trial=3)
    assert loop.consume(block([2, 2, -3], [1, 1, 1], [0.1, 0.1, 0.1])) == 0  # an older trial's, a held one's
    with pytest.raises(RuntimeError, match="consumed 0"):
        loop.run(3)
    got = block([-3, -3, 3, 3, 3], [0, 0, 0, 1, 1], [0.0, 0.0, 0.001, 0.002, 0.004], start=10)
    assert loop.consume(got) == 3
    out = loop.run(3)
    np.testing.assert_array_equal(out["force"], [2.0, 3.0, 4.0])
    np.testing.assert_array_equal(out["estimates"]["KALLEV"], [102.0, 103.0, 104.0])
    assert (out["start"], out["end"]) == (12, 15)
    assert loop.monitor.broken is True and loop.monitor.score == 0.004
    assert loop.fault is None


def test_fault_is_the_engines_latched_fault():
    engine = RecordingEngine(["KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "strokes", trial=1)
    engine.latched, engine.fault = True, "runaway: motor saturated"
    loop.consume(block([1, 1], [0, 0], [0, 0]))
    loop.run(2)
    assert loop.fault == "runaway: motor saturated"


def test_refuses_a_condition_the_engine_does_not_run():
    with pytest.raises(ParameterError, match="KALLEV"):
        EngineLoop(RecordingEngine(["LVT"]), {"KALLEV": {}}, "KALLEV", "strokes")


def test_what_the_worker_applied_is_the_setting_a_hold_gives_back():
    """One record per setting: the worker's knob action is in force, so resuming gives it back, not an older wish."""
    engine = RecordingEngine(["KALLEV"])
    loop = EngineLoop(engine, {"KALLEV": {}}, "KALLEV", "hold", trial=3, actions=RATING)
    loop.applied((cmd.SetSource("KALLEV"), cmd.SetFmax(1.0)))  # knob 1's action, run by the worker
    loop.hold(True)
    engine.sent.clear()
    loop.hold(False)
    assert engine.sent[0] == cmd.SetFmax(1.0)
    assert (loop.source, loop.fmax) == ("KALLEV", 1.0)

"""No thump at a trial's start in the live engine: a trial starts as EngineLoop starts it (F_max 0, the bow lifted,
the string reset, the gesture and source set, the mapping) right after a loud one ended, and the recording is
silent from the start cue on while the bow is lifted; it never passes the ceiling. (Before: a transient of
-41 to -18 dBFS for ~60 ms after each start, the bow lifted, and 0 dBFS at 40 N.)"""

import time

import pytest

from studyapp.engine import commands as cmd
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.signal_chain import CEILING_DBFS
from tests import audio_checks as checks


def _start(engine, trial, source):
    for command in (cmd.SetFmax(0.0), cmd.SetBowing(False), cmd.ResetString(), cmd.SetGesture("strokes"),
                    cmd.SetSource(source), cmd.InstallActions({}, trial=trial)):
        engine.send(command)
    engine.send(cmd.AudioCue(trial, "adjustment", trial, "start"))


def test_trial_starts_after_loud_trials_are_silent_with_the_bow_lifted(tmp_path):
    config = EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LVT", fmax=0.0, audio="discard",
                          midi="none", realtime=False, seed=1)
    with Engine(config) as engine:
        engine.send(cmd.RecordAudio(str(tmp_path / "audio.wav")))
        for trial, (source, fmax) in enumerate([("LOWPASS", 40.0), ("LVT", 20.0), ("LOWPASS", 40.0)], start=1):
            _start(engine, trial, source)
            time.sleep(0.3)  # the bow lifted, F_max 0: silence
            engine.send(cmd.SetGesture("hold"))
            engine.send(cmd.SetBowing(True))
            engine.send(cmd.SetFmax(fmax))  # loud: the loop breaks down
            time.sleep(0.8)
            engine.send(cmd.SetBowing(False))  # the response lifts the bow; the next trial starts at once
            engine.send(cmd.AudioCue(trial, "adjustment", trial, "end"))
        _start(engine, 4, "LVT")
        time.sleep(0.3)
        engine.send(cmd.RecordAudio(None))
        time.sleep(0.2)
    archive = checks.read_archive(tmp_path)
    assert checks.check_peak(archive) <= CEILING_DBFS + 0.01
    starts = [c["sample"] for c in archive.cues if c["event"] == "start"]
    bows = [c["sample"] for c in archive.cues if c["event"] == "bow_on"] + [archive.x.size]
    assert len(starts) == 4 and len(bows) == 4
    for at, bow in zip(starts, bows):  # from the start cue to the bow: the string reset, the bow lifted
        assert bow > at  # (the engine's timer catches up after a stall: no span length is guaranteed)
        guard = int(checks.GUARD_S * archive.rate)  # the resampler's filter spans the boundaries
        assert checks.peak_dbfs(archive.x[at + guard:bow - guard]) <= checks.SILENCE_DBFS
    n = int(0.25 * archive.rate)
    loud = [checks.peak_dbfs(archive.x[s - n:s]) for s in starts[1:]]
    assert max(loud) > -20  # the trials before were loud (a breakdown), up to their ends
    assert checks.check_silences(archive)[1] > 0.5
    with pytest.raises(AssertionError):  # the check itself catches a burst in a silence
        archive.x[starts[0] + 2000] = 0.01
        checks.check_silences(archive)

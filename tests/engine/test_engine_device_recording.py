"""A device sink's recording is what reached the device, sample for sample: the engine late (the FIFO short of a
period) is silence in the file at that place, marked as an underrun in the cues, and a cue still lands on the
frame where its block is heard. PortAudio is replaced by a fake whose callback the test calls."""

import csv

import numpy as np
import pytest
from scipy.io import wavfile

from studyapp.engine.audio import sinks as device_sink
from studyapp.engine.audio.recorder import AudioRecorder
from studyapp.engine.audio.wav import pcm16
from studyapp.engine.audio.sinks import DeviceSink
from studyapp.model.stimulus_level import STIMULUS_GAIN

PERIOD = 256  # frames per device callback


class FakeSd:
    """Just enough of python-sounddevice for DeviceSink: one output, a stream that never runs by itself."""

    class PortAudioError(Exception):
        pass

    class default:  # noqa: N801 - sounddevice's name
        device = (None, 0)

    DEVICE = {"index": 0, "name": "fake out", "max_output_channels": 2, "default_samplerate": 48000.0, "hostapi": 0}

    @classmethod
    def query_devices(cls, index=None):
        return [cls.DEVICE] if index is None else cls.DEVICE

    @staticmethod
    def query_hostapis(index):
        return {"name": "fake"}

    class OutputStream:
        def __init__(self, **kwargs):
            pass

        def start(self):
            pass

        def abort(self):
            pass

        def close(self):
            pass


def _cues(folder):
    with open(folder / "audio_cues.csv", newline="", encoding="utf-8") as f:
        return [{**r, "sample": int(r["sample"])} for r in csv.DictReader(f)]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_recording_holds_the_gaps_the_device_played_and_cues_where_blocks_are_heard(tmp_path, monkeypatch, seed):
    monkeypatch.setattr(device_sink, "load_sounddevice", lambda: FakeSd)
    sink = DeviceSink(5000.0)
    recorder = sink.recorder = AudioRecorder(tmp_path / "audio.wav", sink.rate)
    rng = np.random.default_rng(seed)
    played, short, cue_block = [], [], 150
    blocks = 0
    t = 0.0
    for _ in range(200):
        # on average the engine keeps up (2.67 blocks of 96 frames per 256-frame period), now and then it is late
        for _ in range(int(rng.choice([0, 1, 3, 4, 5], p=[0.15, 0.15, 0.3, 0.2, 0.2]))):
            if blocks == cue_block:
                recorder.cue(7, "adjustment", 1, "start", at=sink.next_frame())
            sounding = blocks >= cue_block  # silence until the cued block, then a tone: its onset shows where
            # 0.05 full scale once through the chain's stimulus gain (under the limiter's knee)
            sink.push(0.05 / STIMULUS_GAIN * np.sin(2 * np.pi * 440.0 * (t + np.arange(10) / 5000.0)), sounding=sounding)
            t += 10 / 5000.0
            blocks += 1
        level = sink.fifo.level
        played.append(sink.play(PERIOD).copy())
        if level < PERIOD:
            short.append(len(played) * PERIOD - PERIOD + level)  # the frame where this period's gap begins
    recorder.stop()
    assert recorder.join(10)
    _, pcm = wavfile.read(tmp_path / "audio.wav")
    heard = np.concatenate(played)
    np.testing.assert_array_equal(pcm, np.frombuffer(pcm16(heard), dtype="<i2"))  # exactly what was played
    assert short and sink.underruns == len(short)  # the engine was late now and then ...
    for frame in short:  # ... and each gap is silence in the file, marked where it begins
        assert np.all(pcm[frame:(frame // PERIOD + 1) * PERIOD] == 0)
    cues = _cues(tmp_path)
    assert [c["sample"] for c in cues if c["event"] == "underrun"] == short
    (start,) = [c for c in cues if c["event"] == "start"]
    assert all(c["step"] == "7" for c in cues if c["event"] == "underrun" and c["sample"] > start["sample"])
    onset = np.flatnonzero(np.abs(pcm) > 2)[0]
    assert onset == pytest.approx(start["sample"], abs=10)  # the resampler lets a trace through a little early
    assert sum(1 for frame in short if frame < start["sample"]) > 0  # gaps before it moved it on, as they moved the sound

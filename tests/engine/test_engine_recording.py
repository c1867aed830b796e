"""What the participant heard, kept: the recorder writes exactly the sink's output, cues trial starts at the
engine's block boundaries, drops rather than waits, and neither it nor a WAV sink ever overwrites a file."""

import csv
import time

import numpy as np
import pytest
from numpy.lib.stride_tricks import sliding_window_view
from scipy.io import wavfile

from studyapp.engine import commands as cmd
from studyapp.engine.audio.recorder import CUE_COLUMNS, AudioRecorder
from studyapp.engine.audio.sinks import open_sink
from studyapp.engine.audio.wav import pcm16
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.resampler import Resampler
from studyapp.engine.signal_chain import FADE_S

FS = 48000.0


def _cues(folder):
    with open(folder / "audio_cues.csv", newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == CUE_COLUMNS
        return list(reader)


def test_the_recorder_writes_every_block_as_16_bit_pcm_and_the_cues_at_their_frames(tmp_path):
    x = np.random.default_rng(4).uniform(-1.2, 1.2, 30000)  # beyond full scale too: clipped like the sink
    recorder = AudioRecorder(tmp_path / "audio.wav", FS)
    recorder.cue(0, "rating", 1, "start")
    recorder.write(x[:10000])
    recorder.cue(0, "rating", 1, "end")
    recorder.cue(1, "adjustment", 1, "start")
    recorder.write(x[10000:])
    recorder.stop()
    assert recorder.join(10)
    fs, pcm = wavfile.read(tmp_path / "audio.wav")
    expected = np.frombuffer(pcm16(x), dtype="<i2")
    assert fs == 48000 and pcm.dtype == np.int16
    np.testing.assert_array_equal(pcm, expected)
    assert np.array_equal(expected, np.round(np.clip(x, -1, 1) * 32767).astype(np.int16))
    assert [(r["file"], int(r["sample"]), float(r["seconds"]), r["step"], r["task"], r["trial"], r["event"])
            for r in _cues(tmp_path)] == [
        ("audio.wav", 0, 0.0, "0", "rating", "1", "start"), ("audio.wav", 10000, round(10000 / FS, 6), "0", "rating", "1", "end"),
        ("audio.wav", 10000, round(10000 / FS, 6), "1", "adjustment", "1", "start")]


def test_a_recorder_that_falls_behind_drops_blocks_and_writes_them_as_silence(tmp_path, monkeypatch):
    import threading

    import studyapp.engine.audio.recorder as module
    from tests.engine.waiting import wait_for

    gate = threading.Event()
    convert = module.pcm16
    monkeypatch.setattr(module, "pcm16", lambda samples: gate.wait(10) and convert(samples))  # a stalled disk
    monkeypatch.setattr(module, "QUEUE_SECONDS", 1000 / FS)  # room for 1000 frames
    recorder = AudioRecorder(tmp_path / "audio.wav", FS)
    recorder.write(np.full(400, 0.25))
    recorder.write(np.full(700, 0.5))  # 400 + 700 > 1000 frames behind: dropped, never waited for
    gate.set()
    wait_for(lambda: recorder._taken == 400)
    recorder.write(np.full(300, 0.75))
    recorder.stop()
    assert recorder.join(10)
    _, pcm = wavfile.read(tmp_path / "audio.wav")
    assert recorder.dropped == 700 and recorder.frames == 1400 and pcm.size == 1400  # the timeline is kept
    assert np.all(pcm[:400] == round(0.25 * 32767)) and np.all(pcm[400:1100] == 0)
    assert np.all(pcm[1100:] == round(0.75 * 32767))


def test_two_wav_sinks_on_one_file_both_keep_their_take_and_say_which_file(tmp_path):
    path = tmp_path / "take.wav"
    said = []
    preview = open_sink(f"wav:{path}", 5000.0, say=said.append)
    session = open_sink(f"wav:{path}", 5000.0, say=said.append)  # open while the preview still writes
    preview.push(np.full(500, 0.5))
    session.push(np.full(1000, -0.5))
    preview.close()
    session.close()  # its name was taken meanwhile: the next free one
    third = open_sink(f"wav:{path}", 5000.0, say=said.append)
    third.push(np.zeros(100))
    third.close()
    lengths = {p.name: wavfile.read(p)[1].size for p in sorted(tmp_path.iterdir())}
    tail = round(FADE_S * 5000.0) * 48 // 5  # the fades' lookahead, played out (faded) when the sink closes
    assert lengths == {"take.wav": 4800 + tail, "take-2.wav": 9600 + tail, "take-3.wav": 960 + tail}
    assert wavfile.read(path)[1][1000] > 0  # the first take intact
    assert said == [f"audio: {path} appeared meanwhile; wrote {tmp_path / 'take-2.wav'} (never over an earlier file)",
                    f"audio: {path} exists; writing {tmp_path / 'take-3.wav'} (never over an earlier file)"]


def _run(path, record):
    """An engine run writing the sink to ``path`` and recording to ``record``: two cued trials; returns what it did."""
    notices = []
    config = EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=2.0,
                          audio=f"wav:{path}", midi="none", realtime=False)
    with Engine(config, on_notice=notices.append) as engine:
        engine.send(cmd.SetBowing(True))
        for trial in (1, 2):
            if trial == 1:
                engine.send(cmd.RecordAudio(str(record)))
            engine.send(cmd.InstallActions({}, trial=trial))
            engine.send(cmd.AudioCue(trial - 1, "listen", trial, "start"))
            time.sleep(0.6)
        tags = engine.telemetry(since=0)
    first = {trial: tags["start"] + int(np.argmax(tags["trial"] == trial)) for trial in (1, 2)}
    assert all(tags["trial"][first[t] - tags["start"]] == t for t in (1, 2))
    return engine.summary, first, [n.text for n in notices]


def test_the_engine_records_what_is_heard_with_cues_at_the_trials_first_samples(tmp_path):
    record = tmp_path / "session" / "audio.wav"
    record.parent.mkdir()
    ratio = FS / 5000.0
    summary, first, notices = _run(tmp_path / "heard.wav", record)
    _, heard = wavfile.read(tmp_path / "heard.wav")
    _, recorded = wavfile.read(record)
    block = 10 * ratio  # 96 frames: commands sent one after another may reach the worker a block apart
    # as long as the engine ran from trial 1's first block to the end, give or take a block
    assert recorded.size == pytest.approx((summary["samples"] - first[1]) * ratio, abs=block + 1)
    assert summary["audio_recordings"] == [{"file": str(record), "frames": recorded.size, "dropped": 0, "error": None}]
    # exactly what the sink played, from the frame where trial 1 began
    windows = sliding_window_view(heard, 64)
    offset = np.flatnonzero(np.all(windows == recorded[1000:1064], axis=1))
    assert offset.size == 1 and np.array_equal(heard[offset[0] - 1000:][:recorded.size], recorded)
    assert np.std(recorded) > 10  # the bowed string (at the stimulus gain, -33 dB), not silence
    cues = _cues(record.parent)
    assert [(r["file"], r["trial"], r["event"]) for r in cues] == [("audio.wav", "1", "start"), ("audio.wav", "2", "start")]
    # each cue sits where the telemetry says its trial's first sample is heard, give or take a block: the
    # recording ends with the resampler's last available output (its filter delay before the newest input)
    # and a sample is heard the fades' lookahead after it was computed
    lag = Resampler(5000.0, FS).latency * ratio + round(FADE_S * 5000.0) * ratio
    start = recorded.size - (summary["samples"] - first[1]) * ratio + lag  # frame of trial 1's first sample
    for cue, trial in zip(cues, (1, 2)):
        assert int(cue["sample"]) == pytest.approx(start + (first[trial] - first[1]) * ratio, abs=block + 1)
    assert any(f"recording what is heard to {record}" in n for n in notices)

    before = record.read_bytes()
    summary, _, notices = _run(tmp_path / "heard.wav", record)  # a second engine run of the session
    assert record.read_bytes() == before  # the first file intact
    second = record.with_name("audio-2.wav")
    assert summary["audio_recordings"][0]["file"] == str(second) and wavfile.read(second)[1].size > 0
    assert [r["file"] for r in _cues(record.parent)] == ["audio.wav"] * 2 + ["audio-2.wav"] * 2
    assert f"audio: {tmp_path / 'heard.wav'} exists; writing {tmp_path / 'heard-2.wav'} (never over an earlier file)" in notices


def test_recording_needs_a_sink_that_renders(tmp_path):
    notices = []
    config = EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LOWPASS", audio="null", midi="none",
                          realtime=False)
    with Engine(config, on_notice=notices.append) as engine:
        engine.send(cmd.RecordAudio(str(tmp_path / "audio.wav")))
        engine.send(cmd.AudioCue(0, "listen", 1, "start"))
        time.sleep(0.2)
    assert not (tmp_path / "audio.wav").exists() and not (tmp_path / "audio_cues.csv").exists()
    assert any("null sink renders no audio: nothing to record" in n.text for n in notices)


def test_an_engine_started_with_the_bow_lifted_is_silent_from_its_first_sample(tmp_path):
    """A session's engine starts with the bow lifted (issue 22 item 4): before, the first blocks sounded
    (about 30 ms at -17 dBFS peak in a GUI session's audio.wav) until the session's SetBowing(False) came."""
    path = tmp_path / "start.wav"
    config = EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=0.0, bowing=False,
                          audio=f"wav:{path}", midi="none", realtime=False)
    with Engine(config) as engine:
        time.sleep(0.5)
    rate, pcm = wavfile.read(path)
    assert pcm.size > 0.2 * rate and np.max(np.abs(pcm)) == 0
    loud = tmp_path / "bowed.wav"
    with Engine(EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=0.0,
                             audio=f"wav:{loud}", midi="none", realtime=False)):
        time.sleep(0.5)
    assert np.max(np.abs(wavfile.read(loud)[1])) > 0  # the default (studyapp live): bowing from the start


def test_each_cue_row_counts_the_samples_the_limiter_bent_since_the_row_before(tmp_path):
    from studyapp.engine.signal_chain import KNEE

    x = np.random.default_rng(7).uniform(-0.3, 0.3, 30000)  # some above the knee (0.126), most not
    recorder = AudioRecorder(tmp_path / "audio.wav", FS)
    recorder.cue(0, "rating", 1, "start")
    recorder.write(x[:10000])
    recorder.cue(0, "rating", 1, "end")
    recorder.cue(1, "adjustment", 1, "start")
    recorder.cue(None, None, None, "bow_off", at=20000)  # inside the next write
    recorder.write(x[10000:])
    recorder.cue(1, "adjustment", 1, "end")
    recorder.stop()
    assert recorder.join(10)
    rows = _cues(tmp_path)
    above = np.abs(x) > KNEE
    expected = [0, above[:10000].sum(), 0, above[10000:20000].sum(), above[20000:].sum()]
    assert [int(r["sample"]) for r in rows] == [0, 10000, 10000, 20000, 30000]
    assert [int(r["limited"]) for r in rows] == expected and sum(expected) == above.sum() > 1000

"""Nothing left behind by a kill, nothing written through a link (issue 33, items 3 and 5).

On main an early kill left a 0-byte, unreadable audio.wav (the header came with
the first audio), a killed ``live --audio wav:take.wav`` left a
``.take.wav.XXXXXXXX.wav`` that no run removed, and an audio_cues.csv planted
as a link had rows appended to its target."""

import os
import signal
import subprocess
import sys
import wave
from pathlib import Path

import numpy as np

from studyapp.engine.audio.recorder import AudioRecorder
from studyapp.engine.audio.sinks import WavSink

ROOT = Path(__file__).resolve().parents[2]


def test_a_recording_has_a_readable_header_from_the_moment_it_has_a_name(tmp_path):
    recorder = AudioRecorder(tmp_path / "audio.wav", 48000.0)
    try:
        with wave.open(str(recorder.path)) as wav:  # what a kill right now would leave
            assert (wav.getnchannels(), wav.getsampwidth(), wav.getnframes()) == (1, 2, 0)
    finally:
        recorder.stop()
        recorder.join(5)


def test_a_killed_recording_leaves_a_readable_file(tmp_path):
    code = ("import sys, time, numpy as np\n"
            "from studyapp.engine.audio.recorder import AudioRecorder\n"
            "r = AudioRecorder(sys.argv[1], 48000.0)\n"
            "r.write(np.zeros(480)); print('ready', flush=True); time.sleep(60)\n")
    child = subprocess.Popen([sys.executable, "-c", code, str(tmp_path / "audio.wav")], cwd=ROOT,
                             stdout=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "ready"
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait(30)
    files = sorted(p.name for p in tmp_path.iterdir())
    assert files == ["audio.wav"]
    with wave.open(str(tmp_path / "audio.wav")) as wav:
        assert wav.getframerate() == 48000


def test_a_planted_cues_link_is_not_written_through(tmp_path):
    target = tmp_path / "precious.csv"
    target.write_text("keep me\n")
    (tmp_path / "audio_cues.csv").symlink_to(target)
    (tmp_path / "audio.wav").symlink_to(tmp_path / "other.wav")
    recorder = AudioRecorder(tmp_path / "audio.wav", 48000.0)
    recorder.cue(0, "rating", 1, "start", at=0)
    recorder.write(np.zeros(480), start=0)
    recorder.stop()
    assert recorder.join(5)
    assert target.read_text() == "keep me\n" and not (tmp_path / "other.wav").exists()
    assert recorder.path.name == "audio-2.wav" and "symbolic link" in recorder.cues_refused


def test_a_wav_sink_leaves_no_temporary_and_removes_one_a_killed_run_left(tmp_path):
    stale = tmp_path / ".take.wav.abcd1234.wav"
    stale.write_bytes(b"")
    sink = WavSink(tmp_path / "take.wav", 48000.0, rate=48000.0, say=lambda text: None)
    assert sorted(os.listdir(tmp_path)) == []  # the stale temporary removed, ours has no name
    sink.close()
    assert sorted(os.listdir(tmp_path)) == ["take.wav"]
    with wave.open(str(tmp_path / "take.wav")) as wav:
        assert wav.getnchannels() == 1

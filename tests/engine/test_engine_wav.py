"""engine/audio/wav.py: one WAV format for every file of what is heard, one way to a name never written over."""

import os
import stat
import threading

import numpy as np
from scipy.io import wavfile

from studyapp.engine.audio.recorder import AudioRecorder
from studyapp.engine.audio.sinks import WavSink
from studyapp.engine.audio.wav import open_wav, pcm16
from studyapp.io.free_names import claim, first_free, numbered_names


def test_pcm16_is_round_32767_x_clipped_to_full_scale():
    x = np.array([-2.0, -1.0, -0.5, 0.0, 1e-5, 0.25, 1.0, 1.5])
    expected = np.array([-32767, -32767, -16384, 0, 0, 8192, 32767, 32767], dtype="<i2")  # -16383.5 rounds even
    assert np.frombuffer(pcm16(x), dtype="<i2").tolist() == expected.tolist()


def test_open_wav_writes_16_bit_mono_at_the_rate(tmp_path):
    with open_wav(str(tmp_path / "a.wav"), 44100.4) as wav:
        wav.writeframes(pcm16(np.full(10, 0.5)))
    fs, pcm = wavfile.read(tmp_path / "a.wav")
    assert fs == 44100 and pcm.dtype == np.int16 and pcm.ndim == 1 and pcm.tolist() == [16384] * 10


def test_numbered_names_and_claims_never_take_an_existing_name(tmp_path):
    names = numbered_names(tmp_path / "take.wav")
    assert [next(names).name for _ in range(3)] == ["take.wav", "take-2.wav", "take-3.wav"]
    assert first_free(tmp_path / "take.wav") == tmp_path / "take.wav"
    (tmp_path / "take.wav").write_bytes(b"earlier")
    (tmp_path / "take-3.wav").write_bytes(b"earlier too")
    assert first_free(tmp_path / "take.wav") == tmp_path / "take-2.wav"
    (tmp_path / "2026-11-25T15-00-00").mkdir()  # a session's folder: a name without a suffix
    assert first_free(tmp_path / "2026-11-25T15-00-00").name == "2026-11-25T15-00-00-2"
    claimed = []
    for _ in range(3):
        fd, name = claim(tmp_path / "take.wav", 0o640)
        os.close(fd)
        claimed.append(name.name)
        assert stat.S_IMODE(os.stat(name).st_mode) == 0o640  # whatever the umask
    assert claimed == ["take-2.wav", "take-4.wav", "take-5.wav"]
    assert (tmp_path / "take.wav").read_bytes() == b"earlier"


def test_claims_racing_for_one_name_each_get_their_own(tmp_path):
    got, start = [], threading.Event()

    def one():
        start.wait()
        fd, name = claim(tmp_path / "audio.wav")
        os.close(fd)
        got.append(name.name)

    threads = [threading.Thread(target=one) for _ in range(8)]
    for t in threads:
        t.start()
    start.set()
    for t in threads:
        t.join(10)
    assert sorted(got) == sorted(["audio.wav"] + [f"audio-{n}.wav" for n in range(2, 9)])


def test_the_wav_sink_and_the_recorder_write_the_same_format(tmp_path):
    x = 0.3 * np.sin(2 * np.pi * 440 * np.arange(4800) / 48000.0)
    recorder = AudioRecorder(tmp_path / "recorded.wav", 48000.0)
    recorder.write(x)
    recorder.stop()
    assert recorder.join(10)
    sink = WavSink(tmp_path / "sink.wav", 48000.0, rate=48000.0, say=lambda text: None)
    sink._write(x)  # the file writer alone, without the signal chain's fades
    sink.close()
    a, b = wavfile.read(tmp_path / "recorded.wav"), wavfile.read(tmp_path / "sink.wav")
    assert a[0] == b[0] == 48000
    assert a[1][:4800].tolist() == np.frombuffer(pcm16(x), dtype="<i2").tolist()
    assert b[1][:4800].tolist() == a[1][:4800].tolist()

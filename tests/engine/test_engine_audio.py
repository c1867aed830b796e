"""Audio sinks: the WAV file holds exactly the signal chain's output (the stream faded in and out, delayed by the
fades' lookahead, resampled, gained); volume changes ramp; without PortAudio or a device, one line and a null sink."""

import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from scipy.io import wavfile
from scipy.signal import resample_poly

from studyapp.engine.audio.fifo import Fifo
from studyapp.engine.audio.sinks import Gain, Sink, WavSink, open_sink, parse
from studyapp.engine.signal_chain import FADE_S
from studyapp.errors import ParameterError
from studyapp.model.stimulus_level import STIMULUS_GAIN


def test_wav_sink_writes_the_resampled_stream_whole_and_only_on_close(tmp_path):
    rate = 5000.0
    t = np.arange(5000) / rate
    # the loop's audio, scaled so that after the stimulus gain it is well above one LSB and under the limiter's knee
    x = (0.08 * np.sin(2 * np.pi * 196 * t) + 0.01 * np.sin(2 * np.pi * 1200 * t)) / STIMULUS_GAIN
    path = tmp_path / "string.wav"
    sink = open_sink(f"wav:{path}", rate)
    assert isinstance(sink, WavSink) and sink.render and not sink.paced
    sink.set_volume(0.5)
    for start in range(0, x.size, 37):
        sink.push(x[start:start + 37])
        assert not path.exists()
    sink.close()
    fs, pcm = wavfile.read(path)
    assert fs == 48000 and pcm.dtype == np.int16
    f = round(FADE_S * rate)  # the fades' lookahead delays the stream; it fades in at the start, out at the end
    fade = (1 - np.cos(np.pi * np.arange(1, f + 1) / (f + 1))) / 2
    window = np.ones(x.size)
    window[:f], window[-f:] = fade, fade[::-1]
    heard = np.concatenate([np.zeros(f), STIMULUS_GAIN * x * window])  # the chain's fixed stimulus gain first
    expected = np.round(0.5 * resample_poly(heard, 48, 5) * 32767).astype(np.int16)
    assert pcm.shape == expected.shape
    assert np.max(np.abs(pcm.astype(int) - expected.astype(int))) <= 1
    assert [p.name for p in tmp_path.iterdir()] == ["string.wav"]


def test_volume_and_mute_ramp_over_one_block_instead_of_clicking():
    gain = Gain(1.0)
    ones = np.ones(8)
    np.testing.assert_array_equal(gain.apply(ones.copy()), ones)
    gain.volume = 0.5
    np.testing.assert_allclose(gain.apply(ones.copy()), np.linspace(1.0, 0.5, 9)[1:])
    np.testing.assert_array_equal(gain.apply(ones.copy()), 0.5 * ones)
    gain.muted = True
    np.testing.assert_allclose(gain.apply(ones.copy()), np.linspace(0.5, 0.0, 9)[1:])
    np.testing.assert_array_equal(gain.apply(ones.copy()), 0 * ones)
    with pytest.raises(ParameterError, match="volume"):
        Sink().set_volume(7)


def test_fifo_keeps_order_across_its_wrap_and_refuses_overflow():
    fifo = Fifo(10)
    out = np.zeros(4, dtype=np.float32)
    got = []
    for start in range(0, 40, 6):
        fifo.write(np.arange(start, start + 6, dtype=np.float32))
        while fifo.level >= 4:
            fifo.read_into(out)
            got.extend(out)
    assert got == list(range(len(got)))
    room = 10 - fifo.level
    assert fifo.write(np.zeros(20, dtype=np.float32)) == room and fifo.level == 10


@pytest.mark.parametrize("spec, kind", [("null", "null"), ("device", "device"), ("device:USB", "device")])
def test_sink_specs(spec, kind, tmp_path):
    assert parse(spec)[0] == kind
    assert parse(f"wav:{tmp_path}/a.wav") == ("wav", f"{tmp_path}/a.wav")
    for bad in ("speaker", "wav:", f"wav:{tmp_path}/missing/a.wav"):
        with pytest.raises(ParameterError, match="--audio"):
            parse(bad)


PROBE = textwrap.dedent("""
    from studyapp.engine.audio.sinks import open_sink
    lines = []
    sink = open_sink("device", 5000.0, say=lines.append)
    print(type(sink).__name__)
    print(len(lines))
    print(lines[0] if lines else "")
""")


def _probe(tmp_path, extra_path=None):
    env = dict(os.environ, JACK_DEFAULT_SERVER=f"nobody-{os.getpid()}", JACK_NO_START_SERVER="1")
    if extra_path:
        env["PYTHONPATH"] = os.pathsep.join([str(extra_path), env.get("PYTHONPATH", "")])
    result = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, env=env,
                            cwd=tmp_path, timeout=120)
    assert result.returncode == 0, result.stderr
    return result.stdout.splitlines(), result.stderr


def test_without_an_output_device_one_line_and_a_null_sink(tmp_path):
    (kind, count, line), stderr = _probe(tmp_path)
    assert kind == "Sink" and count == "1"
    assert line.startswith("audio: no usable output device") and line.endswith("(null sink)")
    assert stderr == ""  # ALSA's and JACK's chatter stays out of the user's way


def test_without_portaudio_one_line_and_a_null_sink(tmp_path):
    fake = tmp_path / "fake"
    fake.mkdir()
    (fake / "sounddevice.py").write_text("raise OSError('PortAudio library not found')\n")
    (kind, count, line), stderr = _probe(tmp_path, extra_path=fake)
    assert kind == "Sink" and count == "1"
    assert "PortAudio not found" in line and "libportaudio2" in line
    assert stderr == ""

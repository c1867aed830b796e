"""The headphone check's reference tone: a sine of the asked frequency and peak level in place of the string,
phase-continuous across blocks, ramped on and off, scaled by the volume in force like the string; checked
against closed forms."""

import time

import numpy as np
import pytest
from scipy.io import wavfile

from studyapp.engine import commands as cmd
from studyapp.engine.audio.sinks import Sink, open_sink
from studyapp.engine.config import EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.reference_tone import RAMP, ReferenceTone
from studyapp.errors import ParameterError
from tests.engine.fake_worker import fake_worker

FS = 48000.0


def _blocks(total, seed):
    """Index arrays of consecutive blocks of random sizes (1 to 299) covering 0..total-1."""
    edges = np.cumsum(np.random.default_rng(seed).integers(1, 300, size=total))
    return np.split(np.arange(total), edges[edges < total])


def test_the_tone_is_one_sine_across_blocks_of_any_size_with_a_linear_ramp_in():
    tone = ReferenceTone(FS)
    tone.set(997.0, -20.0)
    string = np.random.default_rng(1).uniform(-0.5, 0.5, 20000)
    out = np.concatenate([tone.mix(string[idx].copy()) for idx in _blocks(20000, seed=2)])
    j = np.arange(out.size)
    ramp = int(round(RAMP * FS))
    envelope = np.minimum((j + 1) / ramp, 1.0)  # a linear ramp over RAMP seconds, from the first sample
    expected = (1 - envelope) * string[:out.size] + 0.1 * envelope * np.sin(2 * np.pi * 997.0 * j / FS)
    np.testing.assert_allclose(out, expected, atol=1e-9)


def test_off_ramps_the_string_back_and_then_leaves_it_untouched():
    tone = ReferenceTone(FS)
    tone.set(500.0, -18.0)
    tone.mix(np.zeros(5000))
    tone.set(500.0, None)
    faded = tone.mix(np.ones(1000))
    j = np.arange(1000)
    fade = np.maximum(1 - (j + 1) / int(round(RAMP * FS)), 0.0)  # the tone's share, ramped down linearly
    amplitude = 10 ** (-18 / 20)
    expected = (1 - fade) + amplitude * fade * np.sin(2 * np.pi * 500.0 * (5000 + j) / FS)
    np.testing.assert_allclose(faded, expected, atol=1e-9)
    block = np.ones(10)
    assert tone.mix(block) is block and np.all(block == 1.0)


def test_mute_silences_the_tone_with_a_ramp():
    tone = ReferenceTone(FS)
    tone.set(1000.0, -18.0)
    tone.mix(np.zeros(1000))
    tone.set_muted(True)
    out = tone.mix(np.ones(1000))
    assert np.max(np.abs(out[int(RAMP * FS):])) == 0.0
    assert np.max(np.abs(np.diff(out))) < 2 * np.pi * 1000 / FS + 1 / (RAMP * FS)  # no faster than the sine


@pytest.mark.parametrize("hz, level, words", [
    (5.0, -20.0, "20 to 20000 Hz"), (30000.0, -20.0, "20 to 20000 Hz"), (1000.0, -12.0, "-96 to -18 dBFS"),
    (float("nan"), -20.0, "Hz"), (1000.0, float("inf"), "dBFS")])
def test_a_tone_the_sink_cannot_play_is_refused_in_one_line(hz, level, words):
    with pytest.raises(ParameterError, match=words) as info:
        ReferenceTone(FS).set(hz, level)
    assert "\n" not in str(info.value)


def test_the_null_sink_refuses_the_tone_and_the_worker_says_so():
    with pytest.raises(ParameterError, match="null sink plays no sound"):
        Sink().set_reference_tone(1000.0, -20.0)
    worker = fake_worker()
    try:
        worker.sink = Sink()
        assert worker.apply(cmd.ReferenceTone(1000.0, -20.0)) is None
        assert "no sound" in worker.events[-1].text and worker.events[-1].level == "warning"
    finally:
        worker.status.close()


def test_the_wav_sink_replaces_the_string_and_plays_the_tone_at_the_volume_in_force(tmp_path):
    path = tmp_path / "tone.wav"
    sink = open_sink(f"wav:{path}", 5000.0)
    sink.set_volume(0.25)
    sink.set_reference_tone(1000.0, -20.0)
    string = 0.9 * np.sin(2 * np.pi * 196.0 * np.arange(10000) / 5000.0)
    for start in range(0, string.size, 10):
        sink.push(string[start:start + 10])
    sink.close()
    fs, pcm = wavfile.read(path)
    steady = pcm[int(0.1 * fs):int(1.9 * fs)] / 32767.0
    assert np.max(np.abs(steady)) == pytest.approx(0.25 * 10 ** (-20 / 20), abs=2e-4)  # the level asked, x 0.25
    spectrum = np.abs(np.fft.rfft(steady * np.hanning(steady.size)))
    freqs = np.fft.rfftfreq(steady.size, 1 / fs)
    assert spectrum[np.argmin(np.abs(freqs - 196.0))] < 1e-4 * spectrum.max()  # the string is gone


def _peak_hz(x, fs, pad=16):
    spectrum = np.abs(np.fft.rfft(x * np.hanning(x.size), n=pad * x.size))
    return np.argmax(spectrum) * fs / (pad * x.size)


def test_the_engine_plays_the_tone_at_the_asked_frequency_and_level(tmp_path):
    path = tmp_path / "check.wav"
    config = EngineConfig(rate=5000.0, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=2.0,
                          audio=f"wav:{path}", midi="none", realtime=False)
    with Engine(config) as engine:
        engine.send(cmd.SetVolume(0.3))
        engine.send(cmd.SetBowing(True))
        engine.send(cmd.ReferenceTone(440.0, -20.0))
        time.sleep(1.2)
        engine.send(cmd.ReferenceTone(level_dbfs=None))
        time.sleep(0.2)
    fs, pcm = wavfile.read(path)
    x = pcm / 32767.0
    # the tone's middle second: after its ramp, before it was turned off
    envelope = np.convolve(np.abs(x), np.ones(480) / 480, mode="same")
    on = np.abs(envelope - 0.3 * 0.1 * 2 / np.pi) < 0.0006  # a sine's mean |x| is 2/pi of its peak (x the volume)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
    starts, ends = edges[::2], edges[1::2]
    longest = np.argmax(ends - starts)
    assert ends[longest] - starts[longest] > 0.8 * fs
    middle = x[starts[longest] + 2400:ends[longest] - 2400]
    peak_db = 20 * np.log10(np.max(np.abs(middle)))
    assert peak_db == pytest.approx(-20.0 + 20 * np.log10(0.3), abs=0.1)  # the level asked, at the volume in force
    assert _peak_hz(middle, fs) == pytest.approx(440.0, abs=1.0)

"""The signal chain: silence with the bow lifted, raised-cosine fades at every start, stop and cut (ending at
the boundary, thanks to the lookahead), a soft limiter that no input can push above the ceiling, and the level
of the bowed string kept through the chain; checked against closed forms and scipy."""

import math

import numpy as np
import pytest
from scipy.signal import resample_poly

from studyapp.engine.signal_chain import CEILING, CEILING_DBFS, FADE_S, KNEE_DB, Gate, SignalChain, soft_limit
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.stimulus_level import STIMULUS_GAIN, short_term_rms_dbfs, typical_rms_dbfs

RATE = 5000.0
FS = 48000.0
F = round(FADE_S * RATE)


def _rise(n):
    return (1 - np.cos(np.pi * np.arange(1, n + 1) / (n + 1))) / 2


def _gate(x, plan, block=10):
    """Run ``x`` through a Gate in blocks; ``plan(k)`` gives (sounding, cut) for the block starting at sample k."""
    gate = Gate(RATE)
    out = [gate.process(x[k:k + block], *plan(k)) for k in range(0, x.size, block)]
    return np.concatenate(out + [gate.process(np.zeros(F), False)])


def test_the_bow_lifted_is_silence_from_the_lift_on_and_the_fades_are_raised_cosines_ending_there():
    x = np.ones(1000)  # a DC "string": the gains themselves show
    on, off = 200, 600
    y = _gate(x, lambda k: (on <= k < off, False))
    assert y.size == x.size + F and np.all(y[:F] == 0)  # the lookahead: the output lags by F samples
    heard = y[F:]
    np.testing.assert_allclose(heard[on:on + F], _rise(F))  # fade in from the bow's start ...
    np.testing.assert_allclose(heard[off - F:off], _rise(F)[::-1])  # ... fade out ending at the lift
    assert np.all(heard[on + F:off - F] == 1.0)
    assert np.all(heard[:on] == 0) and np.all(heard[off:] == 0)  # silent while lifted: exactly 0


@pytest.mark.parametrize("block", [1, 7, 10, 64])
def test_a_cut_dips_to_zero_at_the_boundary_whatever_the_block_size(block):
    cut_at = 500 - 500 % block
    x = np.concatenate([np.full(cut_at, 0.8), np.full(1000 - cut_at, -0.8)])  # the worst jump, at the cut
    y = _gate(x, lambda k: (True, k == cut_at), block=block)[F:]
    np.testing.assert_allclose(y[cut_at - F:cut_at], x[cut_at - F:cut_at] * _rise(F)[::-1])
    np.testing.assert_allclose(y[cut_at:cut_at + F], x[cut_at:cut_at + F] * _rise(F))
    assert np.max(np.abs(np.diff(y[F:]))) < 0.8 * np.pi / (F + 1)  # no step: at most the fade's own slope


def test_the_limiter_never_reaches_the_ceiling_and_leaves_the_stimulus_alone():
    rng = np.random.default_rng(7)
    loud = rng.normal(0, 1, 100000) * 10.0 ** rng.uniform(-3, 2, 100000)  # up to 40 dB over full scale
    assert np.max(np.abs(soft_limit(loud.copy()))) <= CEILING
    knee = CEILING * 10 ** (-KNEE_DB / 20)
    quiet = rng.uniform(-knee, knee, 10000)
    np.testing.assert_array_equal(soft_limit(quiet.copy()), quiet)  # below the knee: untouched
    a = np.array([knee - 1e-9, knee + 1e-9])
    assert np.all(np.abs(np.diff(soft_limit(a.copy()))) < 1e-8)  # continuous, slope 1, at the knee
    assert CEILING_DBFS == pytest.approx(20 * math.log10(CEILING))


def test_the_chain_is_the_faded_stream_resampled_gained_and_limited():
    t = np.arange(5000) / RATE
    x = 0.05 * np.sin(2 * np.pi * 196 * t)
    chain = SignalChain(RATE, FS)
    chain.gain.set_volume(2.0)
    out = np.concatenate([chain.process(x[k:k + 10]) for k in range(0, x.size, 10)] + [chain.flush()])
    window = np.ones(x.size)
    window[:F] = _rise(F)
    window[-F:] = _rise(F)[::-1]
    expected = 2.0 * STIMULUS_GAIN * resample_poly(np.concatenate([np.zeros(F), x * window]), 48, 5)
    np.testing.assert_allclose(out, expected, atol=1e-12)


def test_a_block_is_heard_at_the_frame_the_chain_names():
    chain = SignalChain(RATE, FS, gain=1.0)
    out = [chain.process(np.zeros(10), False) for _ in range(20)]
    at = chain.next_frame()
    out += [chain.process(np.full(10, 0.1), True) for _ in range(20)]
    y = np.concatenate(out)
    first = np.flatnonzero(np.abs(y) > 1e-3 * 0.1)[0]
    # the fade starts at the named frame; the resampler's filter lets a trace through a few frames early
    assert abs(first - at) <= 10


@pytest.mark.parametrize("gesture, source", [("strokes", "KALLEV"), ("hold", "LOWPASS"), ("strokes", "LVT")])
def test_40_newtons_at_full_volume_stays_under_the_ceiling_without_a_sample_at_full_scale(gesture, source):
    estimators = {} if source == "LVT" else {source: {}}
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source=source, fmax=40.0, gesture=gesture, seed=3))
    chain = SignalChain(RATE, FS)
    chain.gain.set_volume(4.0)  # the volume knob's top
    raw, heard = [], []
    for _ in range(1500):
        audio = loop.run(10)["audio"]
        raw.append(4.0 * audio)
        heard.append(chain.process(audio))
    raw, heard = np.concatenate(raw), np.concatenate(heard)
    assert np.sum(np.abs(raw) >= 1.0) > 100  # what the old chain clipped at full scale
    pcm = np.round(heard * 32767)
    assert np.max(np.abs(pcm)) <= round(CEILING * 32767) and np.sum(np.abs(heard) >= 1.0) == 0


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_chain_keeps_the_bowed_strings_typical_rms(seed):
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={"LOWPASS": {}}, source="LOWPASS", fmax=1.0, seed=seed))
    audio = loop.run(int(6 * RATE))["audio"]
    chain = SignalChain(RATE, FS)
    heard = np.concatenate([chain.process(audio[k:k + 10]) for k in range(0, audio.size, 10)])
    model = typical_rms_dbfs(RATE, "strokes", 1.0, ["LOWPASS"], seed=seed)
    assert short_term_rms_dbfs(heard[int(1.0 * FS) + 240:], FS) == pytest.approx(model, abs=0.3)

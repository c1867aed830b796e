"""Shared helpers for the model tests: steady bowing strokes and slip detection."""

import numpy as np
import pytest

from studyapp.model.loop import ClosedLoop, LoopConfig


def steady_stroke(rate, duration=0.5, speed=0.04, start=-0.009, ramp=0.03):
    """A bow stroke trajectory (m): a raised-cosine start, then constant ``speed``."""
    t = np.arange(int(duration * rate)) / rate
    vel = np.where(t < ramp, speed * 0.5 * (1.0 - np.cos(np.pi * t / ramp)), speed)
    return start + np.cumsum(vel) / rate


def bow(rate, fmax, source="TRUE", duration=0.45, speed=0.04, estimators=None, **config):
    """Run one steady stroke from -9 mm; returns (loop, block)."""
    traj = steady_stroke(rate, duration, speed=speed)
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators or {}, source=source, fmax=fmax,
                                 gesture="playback", trajectory=traj, **config))
    return loop, loop.run(traj.size)


def slip_onsets(stick, min_length):
    """Starts of the runs of non-sticking samples at least ``min_length`` long."""
    stick = np.asarray(stick) > 0.5
    edges = np.flatnonzero(np.diff(stick.astype(int))) + 1
    starts = np.r_[0, edges]
    lengths = np.diff(np.r_[0, edges, stick.size])
    return np.array([a for a, n in zip(starts, lengths) if a > 0 and not stick[a] and n >= min_length])


@pytest.fixture(scope="session")
def fft_peak():
    def peak(x, rate, fmin=30.0):
        """Frequency of the largest spectral peak above ``fmin`` (Hann window, zero padding, parabolic)."""
        x = np.asarray(x) - np.mean(x)
        n = 1 << int(np.ceil(np.log2(x.size * 16)))
        spec = np.abs(np.fft.rfft(x * np.hanning(x.size), n))
        f = np.fft.rfftfreq(n, 1.0 / rate)
        spec[f < fmin] = 0.0
        i = int(np.argmax(spec))
        a, b, c = np.log(spec[i - 1:i + 2])
        return f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0])

    return peak

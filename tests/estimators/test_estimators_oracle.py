"""LOWPASS and LEVANT against the figures the paper's first author published for his own estimators.

The test (facts of the published run, not its code): the noise-free velocity

    v(t) = (0.5 + sin(50 t) 2^(-d t)) + (0.2 + 0.2 sin(500 t) 2^(-d t)),   t = k T in [0, 1),

the position x = cumsum(v) T, and the error as the root-sum-square of the
estimate minus v over the samples k >= len / 5. Butterworth is a 2nd-order
300 Hz low-pass on the backward difference (our LOWPASS); Levant is the Euler
discretisation (our LEVANT) with C = max_k |v_k - v_(k-1)| / T, the signal's
own Lipschitz constant at that rate, and the observer starting at 0 (the
authors' start, our default ``start = "zero"``).

Measured 2026-11-25: ours agree to 1e-13 relative. With ``start = "first"``
LEVANT reads 4.48334 at 1 kHz (0.5 % off), so these figures pin the start.
The Kalman filters' oracle is filterpy (test_estimators_kalman.py).
"""

import numpy as np
import pytest

from studyapp.estimators import create

# (rate Hz, d, Butterworth 300 Hz, Levant (Euler)): the published root-sum-square errors
FIGURES = [
    (1000.0, 10.0, 0.08699625570268, 4.4593133224054),
    (10000.0, 10.0, 0.39571444629082, 1.5266958665074),
    (1000.0, 1.0, 0.793323393906604, 5.35325926513294),
]


def published_signal(rate, d):
    t = np.arange(int(rate)) / rate
    decay = 2.0 ** (-d * t)
    v = (0.5 + np.sin(50.0 * t) * decay) + (0.2 + 0.2 * np.sin(500.0 * t) * decay)
    return v, np.cumsum(v) / rate


def rss_error(estimate, v):
    start = len(v) // 5
    return float(np.sqrt(np.sum((estimate[start:] - v[start:]) ** 2)))


@pytest.mark.parametrize("rate, d, butterworth, levant", FIGURES)
def test_lowpass_gives_the_published_butterworth_figure(rate, d, butterworth, levant):
    v, x = published_signal(rate, d)
    got = rss_error(create("LOWPASS", rate, cutoff_hz=300.0).process(x), v)
    assert got == pytest.approx(butterworth, rel=1e-9)


@pytest.mark.parametrize("rate, d, butterworth, levant", FIGURES)
def test_levant_gives_the_published_euler_figure(rate, d, butterworth, levant):
    v, x = published_signal(rate, d)
    c = float(np.max(np.abs(np.diff(v)))) * rate
    got = rss_error(create("LEVANT", rate, c=c).process(x), v)
    assert got == pytest.approx(levant, rel=1e-9)


def test_levant_started_at_the_first_sample_misses_the_figure():
    """The start matters: the other start is 0.5 % off at 1 kHz, far outside 1e-9."""
    rate, d, _, levant = FIGURES[0]
    v, x = published_signal(rate, d)
    c = float(np.max(np.abs(np.diff(v)))) * rate
    got = rss_error(create("LEVANT", rate, c=c, start="first").process(x), v)
    assert got == pytest.approx(4.48334, rel=1e-5)
    assert abs(got / levant - 1.0) > 4e-3

"""The normalised delay against closed forms, and eq. 22's defect on the same signals (issue 12).

The signal is what the issue describes: a velocity dominated by a slow stroke
(50 mm/s, nearly constant over the recording) with a band-limited ripple of
1 mm/s RMS on top (white noise through a 50-500 Hz band-pass). An estimate that
is the same signal k samples later (a slice of one longer sequence, so exact at
every sample) has delay k by construction.
"""

import numpy as np
import pytest
from scipy import signal

from studyapp.evaluation import delay_and_error
from studyapp.evaluation.metric import Reference
from studyapp.synthetic import stick_slip

RATE = 5000.0
MAX_LAG = 100  # 20 ms at 5 kHz, the commands' default


def stroke_and_ripple(n, margin, seed=0):
    """n + 2 margin samples: a slow stroke plus a band-limited ripple."""
    rng = np.random.default_rng(seed)
    total = n + 2 * margin
    band = signal.butter(4, [50.0, 500.0], btype="bandpass", fs=RATE, output="sos")
    ripple = signal.sosfilt(band, rng.normal(size=total + 2000))[2000:]  # past the filter's start-up
    ripple *= 1e-3 / np.std(ripple)
    t = (np.arange(total) - total / 2) / RATE
    return 0.05 * np.cos(2 * np.pi * 0.05 * t) + ripple


def delayed_pair(k, n=5000, margin=20):
    x = stroke_and_ripple(n, margin)
    return x[margin: margin + n], x[margin - k: margin - k + n]


@pytest.mark.parametrize("k", range(-5, 16))
def test_normalised_delay_reads_an_exact_delay_exactly(k):
    v, w = delayed_pair(k)
    assert delay_and_error(v, w, MAX_LAG) == (k, pytest.approx(0.0, abs=1e-15))
    assert Reference(v, MAX_LAG).measure(w) == (k, pytest.approx(0.0, abs=1e-15))


def test_paper_delay_reads_zero_on_the_same_signal():
    # Eq. 22's sum loses one stroke-sized product per sample of lag, more than the ripple's
    # alignment gains: every lagging copy reads 0, and so does every leading one.
    readings = {k: delay_and_error(*delayed_pair(k), MAX_LAG, method="paper")[0] for k in range(-5, 16)}
    assert readings == {k: 0 for k in range(-5, 16)}
    v, w = delayed_pair(7)
    assert Reference(v, MAX_LAG, "paper").measure(w)[0] == 0


@pytest.mark.parametrize("cutoff", [250.0, 400.0, 800.0, 1200.0])
def test_butterworth_low_pass_reads_its_group_delay_at_the_ripple_frequency(cutoff):
    # Stick-slip at f0 = 110 Hz on a slow stroke. Cut-offs from about 2 f0 up: there the
    # filter's phase and group delays at f0 agree, so "the" delay of the ripple is defined.
    f0 = 110.0
    v = stick_slip(RATE, 1.0, f0=f0, f_stroke=0.7)["velocity_true"]
    b, a = signal.butter(2, cutoff, fs=RATE)
    _, (group_delay,) = signal.group_delay((b, a), w=[f0], fs=RATE)
    d, _ = delay_and_error(v, signal.lfilter(b, a, v), int(RATE / f0 / 2) - 1)
    assert abs(d - group_delay) <= 1


@pytest.mark.parametrize("method,k,expected", [("normalised", -4, -4), ("normalised", 9, 9), ("paper", 9, 0)])
def test_error_is_the_rmse_over_the_shifted_overlap(method, k, expected):
    rng = np.random.default_rng(5)
    v, w = delayed_pair(k)
    w = 0.9 * w + rng.normal(0.0, 2e-4, w.shape[0])
    d, e = delay_and_error(v, w, MAX_LAG, method)
    assert d == expected
    n = v.shape[0]
    shared = np.arange(max(0, -d), n - max(0, d))  # n with both v[n] and w[n + d]
    assert e == pytest.approx(np.sqrt(np.mean((v[shared] - w[shared + d]) ** 2)), rel=1e-12)

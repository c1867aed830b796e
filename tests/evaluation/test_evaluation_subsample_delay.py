"""The sub-sample delay (issue 30) against closed forms: a pure fractional delay and a one-pole low-pass.

A pure delay of d samples is made in the frequency domain (X(f) e^{-2 pi i f d}),
independently of the correlation that measures it; a one-pole low-pass
y[n] = y[n-1] + a (x[n] - y[n-1]) delays a signal far below its cut-off by
its group delay at DC, (1 - a) / a samples. Whole-sample D reads 0 on every
delay under half a sample, so it cannot tell such estimates apart.
"""

import numpy as np
import pytest
from scipy import signal

from studyapp.evaluation import delay_and_error
from studyapp.evaluation.subsample_delay import subsample_delay
from studyapp.evaluation.findings import DELAY_RESOLUTION

RATE = 5000.0
MAX_LAG = 100


def band_limited(n, high, seed=0):
    x = np.random.default_rng(seed).normal(size=n + 4000)
    return signal.sosfilt(signal.butter(6, high, fs=RATE, output="sos"), x)[2000:-2000]


def delayed(x, d):
    spectrum = np.fft.rfft(x)
    return np.fft.irfft(spectrum * np.exp(-2j * np.pi * np.fft.rfftfreq(x.size) * d), x.size)


@pytest.mark.parametrize("high", [200.0, 500.0, 1000.0])
def test_a_pure_fractional_delay_reads_within_the_resolution(high):
    x = band_limited(20000, high)
    for d in np.arange(-2.0, 3.01, 0.1):
        assert subsample_delay(x, delayed(x, d), MAX_LAG) == pytest.approx(d, abs=DELAY_RESOLUTION / 2)


def test_whole_sample_delay_cannot_tell_small_delays_apart_the_sub_sample_one_can():
    x = band_limited(20000, 500.0)
    whole = {d: delay_and_error(x, delayed(x, d), MAX_LAG)[0] for d in (0.1, 0.2, 0.3, 0.4)}
    assert set(whole.values()) == {0}
    readings = [subsample_delay(x, delayed(x, d), MAX_LAG) for d in (0.1, 0.2, 0.3, 0.4)]
    assert np.all(np.diff(readings) > DELAY_RESOLUTION)


@pytest.mark.parametrize("cutoff", [100.0, 300.0, 1000.0])
def test_a_one_pole_low_pass_reads_its_group_delay(cutoff):
    a = 1.0 - np.exp(-2.0 * np.pi * cutoff / RATE)
    x = band_limited(35000, cutoff / 10.0, seed=3)
    y = signal.lfilter([a], [1.0, a - 1.0], x)
    assert subsample_delay(x, y, MAX_LAG) == pytest.approx((1.0 - a) / a, abs=DELAY_RESOLUTION / 2)


def test_the_whole_part_is_the_whole_sample_delay_and_the_paper_method_too():
    x = band_limited(20000, 500.0)
    for d in (-3.3, 0.45, 7.2):
        whole = delay_and_error(x, delayed(x, d), MAX_LAG)[0]
        assert abs(subsample_delay(x, delayed(x, d), MAX_LAG) - whole) <= 0.5
    assert subsample_delay(x, delayed(x, 2.3), MAX_LAG, "paper") == pytest.approx(2.3, abs=0.05)


def test_the_peak_at_the_end_of_the_range_and_a_non_finite_estimate():
    x = band_limited(20000, 500.0)
    assert subsample_delay(x, delayed(x, 6.0), 3) == 3.0
    assert np.isnan(subsample_delay(x, np.full_like(x, np.nan), MAX_LAG))

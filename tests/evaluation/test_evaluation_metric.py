"""Delay D and delay-corrected error E (eqs. 22-24), against known delays, filters and noise.

Both methods: ``normalised`` (the default) and ``paper`` (eq. 22 as printed).
"""

import numpy as np
import pytest
from scipy import signal

from studyapp.errors import InputDataError, UserError
from studyapp.evaluation import delay_and_error
from studyapp.evaluation.metric import Reference
from tests.evaluation.conftest import stick_slip


def _delayed(v, d):
    """v delayed by d samples (the first d samples repeat v[0], as a causal filter at rest would)."""
    return np.concatenate((np.full(d, v[0]), v[: v.shape[0] - d]))


@pytest.mark.parametrize("delay", [0, 1, 2, 3, 7, 19])
def test_delay_exact_for_integer_delays_noise_free(delay):
    # Delays under half the stick-slip period (45 samples at 110 Hz, 5 kHz): a periodic
    # signal cannot tell a delay from a delay plus one period.
    v = stick_slip(5000.0, 1.0)["velocity_true"]
    d, e = delay_and_error(v, _delayed(v, delay), 60)
    assert d == delay
    assert e == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("delay", [33, 64, 99])
def test_delay_exact_for_long_delays_of_an_aperiodic_signal(delay):
    rng = np.random.default_rng(3)
    v = signal.sosfilt(signal.butter(2, 300.0, fs=5000.0, output="sos"), rng.normal(size=20_000))
    d, e = delay_and_error(v, _delayed(v, delay), 100)
    assert d == delay
    assert e == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("delay", [0, 4, 11])
def test_error_equals_added_noise_rms(delay):
    rng = np.random.default_rng(1)
    v = stick_slip(10_000.0, 10.0)["velocity_true"]  # 10^5 samples
    assert v.shape[0] == 100_000
    sigma = 2e-3
    noise = rng.normal(0.0, sigma, v.shape[0])
    d, e = delay_and_error(v, _delayed(v, delay) + noise, 100)
    assert d == delay
    rms = np.sqrt(np.mean(noise[delay:] ** 2))
    assert e == pytest.approx(rms, rel=0.05)
    assert e == pytest.approx(sigma, rel=0.05)


@pytest.mark.parametrize("length", [5, 9, 21])
def test_delay_of_a_linear_phase_filter_is_its_group_delay(length):
    # A symmetric FIR of odd length delays every frequency by (length - 1) / 2 samples.
    v = stick_slip(5000.0, 2.0)["velocity_true"]
    taps = signal.windows.hann(length + 2)[1:-1]
    estimate = signal.lfilter(taps / taps.sum(), 1.0, v)
    d, _ = delay_and_error(v, estimate, 40)
    assert d == (length - 1) // 2


def test_delay_of_a_butterworth_low_pass_is_near_its_low_frequency_group_delay():
    # 2nd-order Butterworth: group delay at DC is sqrt(2) / (2 pi fc) seconds.
    rate, fc = 5000.0, 100.0
    v = stick_slip(rate, 2.0, f0=20.0)["velocity_true"]
    estimate = signal.sosfilt(signal.butter(2, fc, fs=rate, output="sos"), v)
    d, _ = delay_and_error(v, estimate, 100)
    expected = np.sqrt(2) / (2 * np.pi * fc) * rate  # 11.25 samples
    assert abs(d - expected) <= 2


def _brute_force(v, w, max_lag, method):
    """(D, E) straight from the module docstring's sums, one lag at a time."""
    n = v.shape[0]
    ks = range(-max_lag, max_lag + 1) if method == "normalised" else range(max_lag + 1)
    best = None
    for k in sorted(ks, key=lambda k: (abs(k), -k)):
        a, b = v[max(0, -k): n - max(0, k)], w[max(0, k): n + min(0, k)]
        r = np.dot(a, b)
        if method == "normalised":
            r /= np.sqrt(np.dot(a, a) * np.dot(b, b))
        if best is None or r > best[0]:
            best = (r, k, np.sqrt(np.mean((a - b) ** 2)))
    return best[1], best[2]


@pytest.mark.parametrize("method", ["normalised", "paper"])
@pytest.mark.parametrize("shift", [-6, 6])
def test_reference_class_equals_brute_force_correlation(method, shift):
    rng = np.random.default_rng(2)
    sig = stick_slip(5000.0, 0.5)
    v = sig["velocity_lvt"]
    w = np.roll(sig["velocity_true"], shift) + rng.normal(0, 1e-3, 2500)
    max_lag = 30
    d, e = _brute_force(v, w, max_lag, method)
    assert delay_and_error(v, w, max_lag, method) == (d, pytest.approx(e, rel=1e-12))
    assert Reference(v, max_lag, method).measure(w) == (d, pytest.approx(e, rel=1e-12))


@pytest.mark.parametrize("method", ["normalised", "paper"])
def test_delay_is_bounded_by_max_lag(method):
    v = stick_slip(5000.0, 1.0)["velocity_true"]
    d, e = delay_and_error(v, _delayed(v, 40), 10, method)
    assert (-10 if method == "normalised" else 0) <= d <= 10
    assert e > 0


def test_bad_inputs():
    v = np.zeros(100)
    with pytest.raises(InputDataError, match="differ in length"):
        delay_and_error(v, np.zeros(99), 5)
    with pytest.raises(InputDataError, match="max_lag"):
        delay_and_error(v, v, 100)
    with pytest.raises(InputDataError, match="1-D"):
        delay_and_error(np.zeros((2, 50)), np.zeros((2, 50)), 5)
    with pytest.raises(UserError, match="normalised or paper"):
        delay_and_error(v, v, 5, method="overlap")
    w = np.ones(100)
    w[5] = np.nan
    assert delay_and_error(np.ones(100), w, 5) == (0, float("inf"))
    assert Reference(np.ones(100), 5).measure(w) == (0, float("inf"))


@pytest.mark.parametrize("method", ["normalised", "paper"])
def test_a_silent_estimate_reads_zero_delay_and_the_reference_rms(method):
    # Every lag correlates as 0 (an overlap of zero energy counts as 0): the tie goes to lag 0.
    v = stick_slip(5000.0, 0.5)["velocity_true"]
    expected = (0, pytest.approx(np.sqrt(np.mean(v ** 2)), rel=1e-12))
    assert delay_and_error(v, np.zeros_like(v), 20, method) == expected
    assert Reference(v, 20, method).measure(np.zeros_like(v)) == expected

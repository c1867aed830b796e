"""LEVANT and LEVANTLP against Levant's Euler recursion, his O(T) accuracy, and scipy's Butterworth."""

import math

import numpy as np
import pytest
from numba import njit
from scipy import signal

from studyapp.estimators import create
from studyapp.estimators.levant import LEVANT_STATE, levant_core


def euler_reference(x, c, rate, start="zero"):
    """Eqs. 10-12 with alpha = 1.1 C, lambda = sqrt(C), written out plainly (DESIGN.md conventions)."""
    alpha, lam, period = 1.1 * c, math.sqrt(c), 1.0 / rate
    w, u1 = (float(x[0]) if start == "first" else 0.0), 0.0
    out = np.empty(len(x))
    for k, xk in enumerate(x.tolist()):
        e = w - xk
        sgn = (e > 0) - (e < 0)
        u = u1 - lam * math.sqrt(abs(e)) * sgn
        out[k] = u
        w += period * u
        u1 += -period * alpha * sgn
    return out


@pytest.fixture(scope="module")
def stick_slip():
    rng = np.random.default_rng(7)
    rate = 5000.0
    t = np.arange(4000) / rate
    x = 0.012 + 0.004 * np.sin(2 * np.pi * 3 * t) + 0.0005 * np.sign(np.sin(2 * np.pi * 40 * t))
    return rate, x + 6.4e-5 * rng.standard_normal(t.size)


@pytest.mark.parametrize("start", ["zero", "first"])
@pytest.mark.parametrize("c", [0.5, 19.7, 1e4])
def test_levant_is_the_euler_recursion_of_eqs_10_to_12(stick_slip, c, start):
    rate, x = stick_slip
    got = create("LEVANT", rate, c=c, start=start).process(x)
    np.testing.assert_allclose(got, euler_reference(x, c, rate, start), rtol=1e-12, atol=1e-12 * c)


def test_levant_starts_at_zero_by_default_as_the_authors():
    """The authors' observer starts at w = 0, u1 = 0: a position away from 0 is a step it must first follow."""
    assert create("LEVANT", 5000.0).params["start"] == "zero"
    out = create("LEVANT", 40_000.0, c=50.0).process(np.full(1000, 0.0137))
    assert out[0] == pytest.approx(math.sqrt(50.0 * 0.0137), rel=1e-15)  # -lambda sqrt|w - x| sgn(w - x), w = 0
    assert np.abs(out).max() > 0.1


def test_levant_can_start_at_the_first_sample():
    out = create("LEVANT", 40_000.0, c=50.0, start="first").process(np.full(1000, 0.0137))
    assert np.all(out == 0.0)


def test_levant_error_shrinks_in_proportion_to_the_time_step():
    """Levant 1998: with sampling step T the derivative error after convergence is O(T)."""
    c = 4.0  # |x''| = |sin t| <= 1 < C: the Lipschitz condition (eq. 13) holds
    errors = []
    for rate in (1000.0, 2000.0, 4000.0, 8000.0):
        t = np.arange(int(20 * rate)) / rate
        u = create("LEVANT", rate, c=c).process(np.sin(t))  # |x| <= 1 m, the position bound (bounds.py)
        late = t >= 10.0  # long after convergence (u1 climbs at alpha = 4.4 m/s^2 towards x' = cos t)
        errors.append(np.max(np.abs(u[late] - np.cos(t[late]))))
        assert errors[-1] < 3 * c / rate
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), ratios


@pytest.mark.parametrize("rate, c, cutoff_hz", [(5000.0, 3.6, 293.0), (40_000.0, 100.0, 1000.0), (1000.0, 1.0, 5.0)])
def test_levantlp_is_levant_then_scipy_butterworth_sos(stick_slip, rate, c, cutoff_hz):
    _, x = stick_slip
    levant = create("LEVANT", rate, c=c).process(x)
    expected = signal.sosfilt(signal.butter(2, cutoff_hz, fs=rate, output="sos"), levant)
    got = create("LEVANTLP", rate, c=c, cutoff_hz=cutoff_hz).process(x)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12 * np.max(np.abs(expected)))


@pytest.mark.parametrize("name", ["LEVANT", "LEVANTLP"])
def test_levant_blocks_continue_the_stream(stick_slip, name):
    rate, x = stick_slip
    whole = create(name, rate).process(x)
    est = create(name, rate)
    parts = np.concatenate([est.process(x[a:b]) for a, b in [(0, 1), (1, 777), (777, 778), (778, len(x))]])
    assert np.array_equal(parts, whole)


@njit
def _double_levant(xs, c, rate):
    s = np.zeros(2 * LEVANT_STATE)
    out = np.empty_like(xs)
    for i in range(xs.shape[0]):
        u = levant_core(s[0:LEVANT_STATE], 1.1 * c, np.sqrt(c), 1.0 / rate, 0.0, xs[i])
        out[i] = levant_core(s[LEVANT_STATE:], 1.1 * c, np.sqrt(c), 1.0 / rate, 0.0, u)
    return out


def test_levant_core_chains_into_a_second_derivative():
    """L(L(x)), as the hybrids use it: on x = sin t the second pass follows x'' = -sin t.

    The second pass sees the first one's O(T) switching noise as measurement noise, so its own
    error is larger (O(sqrt T), Levant 1998 Theorem 1): 10 % of the amplitude at 10 kHz, C = 3.
    """
    rate = 10_000.0
    t = np.arange(int(30 * rate)) / rate
    acc = _double_levant(np.sin(t), 3.0, rate)
    late = t >= 15.0
    assert np.max(np.abs(acc[late] + np.sin(t[late]))) < 0.1

"""FOAW (best-fit) against numpy: backward difference, straight lines, and a brute-force window search.

``window`` is the paper's Size: the most samples a line is fitted to (n + 1 samples span n intervals).
"""

import numpy as np
import pytest
from numba import njit

from studyapp.estimators import create
from studyapp.estimators.dispatch import GUARD
from studyapp.estimators.foaw import CHOSEN, foaw_core, foaw_state_size, window_sizes


def brute_force(y, window, margin, rate):
    """The best-fit rule with numpy.polyfit on every window: (velocity, chosen size = samples in the fit)."""
    hist = np.concatenate((np.full(window, y[0]), y))  # history before the first sample = first sample
    vel = np.empty(len(y))
    chosen = np.empty(len(y), dtype=int)
    for k in range(len(y)):
        newest = k + window
        best, best_n = 0.0, 1
        for n in range(1, window):
            ages = np.arange(n + 1)
            samples = hist[newest - ages]
            slope = np.polyfit(-ages / rate, samples, 1)[0]  # m/s
            line = samples[0] - slope * ages / rate
            if np.any(np.abs(samples[1:n] - line[1:n]) > margin):
                break
            best, best_n = slope, n
        vel[k], chosen[k] = best, best_n + 1
    return vel, chosen


def stepped(est, x):
    """Per-sample velocity and the chosen size: the documented state slot's n intervals, n + 1 samples."""
    vel, chosen = np.empty(len(x)), np.empty(len(x), dtype=int)
    for k, xk in enumerate(x):
        vel[k] = est.step(xk)
        chosen[k] = int(est.state[GUARD + CHOSEN]) + 1
    return vel, chosen


@pytest.mark.parametrize("rate", [1000.0, 5000.0, 96_000.0])
def test_foaw_window_2_is_the_backward_difference(rate):
    x = 0.01 + np.cumsum(np.random.default_rng(3).normal(0.0, 1e-5, 3000))
    got = create("FOAW", rate, window=2, margin=1e-9).process(x)
    assert got[0] == 0.0
    np.testing.assert_allclose(got[1:], np.diff(x) * rate, rtol=1e-13, atol=0.0)


@pytest.mark.parametrize("rate", [1000.0, 96_000.0])
@pytest.mark.parametrize("window", [2, 3, 5, 17, 64])
def test_foaw_is_exact_on_straight_lines(rate, window):
    t = np.arange(-150, 150) / rate  # centred: the lines stay within the 1 m position bound (bounds.py)
    for slope in (-2.0, -1e-3, 0.0, 0.37, 5.0):
        est = create("FOAW", rate, window=window, margin=1e-9)
        vel, chosen = stepped(est, 0.0137 + slope * t)
        settled = slice(window, None)  # the at-rest history has left every window
        np.testing.assert_allclose(vel[settled], slope, rtol=1e-8, atol=1e-12)
        assert np.all(chosen[settled] == window)


def test_foaw_window_is_the_samples_since_a_slope_change():
    """Clean kink at sample K: at K + m the longest window within the margin spans m steps, m + 1 samples."""
    rate, kink, window = 5000.0, 100, 17
    k = np.arange(200)
    x = 0.02 + np.where(k < kink, 0.3 * k, 0.3 * kink - 0.8 * (k - kink)) / rate
    vel, chosen = stepped(create("FOAW", rate, window=window, margin=1e-9), x)
    for m in range(1, window):
        assert chosen[kink + m] == m + 1
        assert vel[kink + m] == pytest.approx(-0.8, rel=1e-9)


@pytest.mark.parametrize(
    "rate, window, noise, margin",
    [(5000.0, 17, 6.4e-5, 1.001e-4), (40_000.0, 12, 2e-6, 3e-6), (1000.0, 40, 1e-6, 1e-4)],
)
def test_foaw_picks_the_longest_window_within_the_margin(rate, window, noise, margin):
    rng = np.random.default_rng(11)
    t = np.arange(1500) / rate
    # a noisy line whose slope changes now and then, so every window length occurs
    slope = np.repeat(rng.uniform(-0.5, 0.5, 15), 100)
    x = 0.011 + np.cumsum(slope) / rate + rng.uniform(-noise, noise, t.size)
    vel, chosen = stepped(create("FOAW", rate, window=window, margin=margin), x)
    ref_vel, ref_chosen = brute_force(x, window, margin, rate)
    np.testing.assert_array_equal(chosen, ref_chosen)
    np.testing.assert_allclose(vel, ref_vel, rtol=1e-7, atol=1e-9)
    assert len(np.unique(chosen)) >= window // 2 and np.any(chosen == window) and np.any(chosen < 4)


def _slopes_over(x, chosen, rate):
    """numpy.polyfit's slope over the ``chosen[k]`` newest samples at every k (history = first sample)."""
    hist = np.concatenate((np.full(chosen.max(), x[0]), x))
    out = np.empty(len(x))
    for k, n in enumerate(chosen):
        ages = np.arange(n)
        out[k] = np.polyfit(-ages / rate, hist[k + chosen.max() - ages], 1)[0]
    return out


def test_window_sizes_are_the_estimators_windows():
    """The windows of ``window_sizes`` are the brute-force search's, and the estimator's output is their slope."""
    rate, window, noise, margin = 5000.0, 17, 6.4e-5, 1.001e-4
    rng = np.random.default_rng(12)
    slope = np.repeat(rng.uniform(-0.5, 0.5, 12), 100)
    x = 0.011 + np.cumsum(slope) / rate + rng.uniform(-noise, noise, slope.size)
    chosen = window_sizes(x, window, margin)
    assert chosen.dtype.kind == "i" and len(np.unique(chosen)) >= window // 2
    np.testing.assert_array_equal(chosen, brute_force(x, window, margin, rate)[1])
    output = create("FOAW", rate, window=window, margin=margin).process(x)
    np.testing.assert_allclose(output, _slopes_over(x, chosen, rate), rtol=1e-7, atol=1e-9)


def test_window_sizes_on_closed_forms_and_bad_samples():
    rate, kink, window = 5000.0, 100, 17
    k = np.arange(200)
    x = 0.02 + np.where(k < kink, 0.3 * k, 0.3 * kink - 0.8 * (k - kink)) / rate
    chosen = window_sizes(x, window, 1e-9)
    assert np.all(chosen[window:kink + 1] == window)  # a straight line: the largest window
    assert list(chosen[kink + 1:kink + window]) == list(range(2, window + 1))  # samples since the kink
    x[[0, 50, 120]] = [np.nan, np.inf, np.nan]  # replaced by the last finite sample, as the estimator does
    _, from_state = stepped(create("FOAW", rate, window=window, margin=1e-4), x)
    np.testing.assert_array_equal(window_sizes(x, window, 1e-4), from_state)
    with pytest.raises(ValueError, match="window"):
        window_sizes(x, 1, 1e-4)


def test_foaw_blocks_continue_the_stream():
    rate = 5000.0
    x = 0.01 + np.cumsum(np.random.default_rng(5).normal(0.0, 3e-5, 2000))
    whole = create("FOAW", rate).process(x)
    est = create("FOAW", rate)
    parts = np.concatenate([est.process(x[a:b]) for a, b in [(0, 3), (3, 4), (4, 1200), (1200, 2000)]])
    assert np.array_equal(parts, whole)
    assert est.state_size == foaw_state_size(16)


@pytest.mark.parametrize("size", [2, 12, 17, 33])
def test_table_1_size_is_the_most_samples_in_the_fit(size):
    """The paper's "Size = 17" is a line fitted to the 17 newest samples (16 intervals), not 18.

    With a margin no residual can exceed, FOAW always takes its longest window, so its output
    is numpy.polyfit's slope over exactly ``size`` samples.
    """
    rate = 5000.0
    x = 0.004 + np.cumsum(np.random.default_rng(size).normal(0.0, 2e-5, 400))
    got = create("FOAW", rate, window=size, margin=0.1).process(x)
    ages = np.arange(size)
    expected = [np.polyfit(-ages / rate, x[k - ages], 1)[0] for k in range(size, len(x))]
    np.testing.assert_allclose(got[size:], expected, rtol=1e-9, atol=1e-12)
    assert np.all(window_sizes(x, size, 0.1)[size:] == size)


@njit
def _double_foaw(xs, longest, margin, margin_vel, rate):
    n = foaw_state_size(longest)
    s = np.zeros(2 * n)
    out = np.empty_like(xs)
    for i in range(xs.shape[0]):
        v = foaw_core(s, 0, longest, margin, rate, xs[i])
        out[i] = foaw_core(s, n, longest, margin_vel, rate, v)
    return out


def test_foaw_core_chains_into_a_second_derivative():
    """F(F(x)), as the hybrids use it: a clean parabola has a constant second derivative."""
    rate = 5000.0
    t = np.arange(2000) / rate
    acc = _double_foaw(0.004 + 0.5 * 3.0 * t**2, 12, 1e-4, 0.5, rate)
    np.testing.assert_allclose(acc[30:], 3.0, rtol=1e-6)

"""BDIFF, LOWPASS, LEASTSQ, COMP1/2 against scipy and closed forms."""

import numpy as np
import pytest
from scipy import signal

from studyapp import estimators

RATES = [1000.0, 5000.0, 40_000.0, 96_000.0]


def noisy_walk(n, seed=0):
    return np.cumsum(np.random.default_rng(seed).normal(size=n)) * 1e-5


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("steps", [1, 3, 10])
def test_bdiff_is_eq3(rate, steps):
    x = noisy_walk(500)
    out = estimators.create("BDIFF", rate, steps=steps).process(x)
    expected = (x[steps:] - x[:-steps]) * rate / steps
    np.testing.assert_allclose(out[steps:], expected, rtol=1e-12, atol=1e-15)
    # history before the first sample is the first sample
    np.testing.assert_allclose(out[:steps], (x[:steps] - x[0]) * rate / steps, atol=1e-15)


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("cutoff", [20.0, 256.0, 400.0])
def test_lowpass_is_bdiff_then_scipy_butterworth(rate, cutoff):
    x = noisy_walk(3000, seed=1)
    out = estimators.create("LOWPASS", rate, cutoff_hz=cutoff).process(x)
    d = np.diff(x, prepend=x[0]) * rate
    sos = signal.butter(2, cutoff, fs=rate, output="sos")
    np.testing.assert_allclose(out, signal.sosfilt(sos, d), rtol=1e-9, atol=1e-12 * np.max(np.abs(d)))


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("order, window", [(1, 2), (2, 33), (3, 17), (2, 101), (4, 9)])
def test_leastsq_equals_savgol(rate, order, window):
    x = noisy_walk(1000, seed=2)
    out = estimators.create("LEASTSQ", rate, order=order, window=window).process(x)
    h = signal.savgol_coeffs(window, order, deriv=1, delta=1 / rate, pos=window - 1, use="conv")
    expected = np.convolve(x, h, mode="full")[: len(x)]
    # from the first full window on, the FIR equals scipy's Savitzky-Golay taps
    scale = np.max(np.abs(expected[window - 1:]))
    np.testing.assert_allclose(out[window - 1:], expected[window - 1:], rtol=0, atol=1e-9 * scale)


def exact_taps_fractions(order, window):
    """LEASTSQ's taps per sample in exact rational arithmetic (fractions): taps[j] multiplies x_{k-j}.

    The degree-``order`` least-squares polynomial through x_{k-j} at t = -j (j = 0 .. M-1) has
    coefficients c = G^-1 A^T x with G = A^T A, A[j, a] = (-j)^a; its derivative at t = 0 is c_1,
    so taps[j] = sum_a (G^-1)[1, a] (-j)^a. G is solved with fractions.Fraction: no rounding at all.
    """
    from fractions import Fraction

    n = order + 1
    rows = [[Fraction(sum((-j) ** (a + b) for j in range(window))) for b in range(n)] + [Fraction(int(a == 1))]
            for a in range(n)]
    for c in range(n):  # Gauss-Jordan; G is positive definite, so no pivot is zero
        for r in range(n):
            if r != c:
                f = rows[r][c] / rows[c][c]
                rows[r] = [x - f * y for x, y in zip(rows[r], rows[c])]
    w = [rows[a][n] / rows[a][a] for a in range(n)]  # row 1 of G^-1 (G is symmetric)
    return [sum(w[a] * (-j) ** a for a in range(n)) for j in range(window)]


def exact_taps(order, window):
    """The exact taps rounded to floats."""
    return np.array([float(t) for t in exact_taps_fractions(order, window)])


@pytest.mark.parametrize("order, window", [(1, 2), (2, 33), (4, 512), (5, 400), (6, 257), (6, 512)])
def test_leastsq_taps_equal_the_exact_rational_taps(order, window):
    """Ours to 1e-13 everywhere in range; scipy's savgol_coeffs is 100 % off at (5, 400), (6, 257), (6, 512)."""
    from studyapp.estimators.leastsq import taps

    exact = exact_taps(order, window)
    scale = np.abs(exact).max()
    np.testing.assert_allclose(taps(order, window, 1.0), exact, rtol=0, atol=1e-13 * scale)


@pytest.mark.parametrize("order, window", [(1, 2), (2, 33), (3, 100), (6, 7), (6, 512)])
def test_leastsq_taps_are_the_exact_taps_correctly_rounded(order, window):
    """Issue 39: each tap is the exact rational tap times the rate, rounded once, so its bits depend on no BLAS."""
    from fractions import Fraction

    from studyapp.estimators.leastsq import taps

    exact = exact_taps_fractions(order, window)
    for rate in (1000.0, 5000.0, 44_100.0, 96_000.0):
        assert taps(order, window, rate).tolist() == [float(t * Fraction(rate)) for t in exact]


@pytest.mark.parametrize("order, window", [(1, 2), (2, 33), (4, 257), (6, 7), (6, 100)])
def test_leastsq_taps_equal_numpys_pseudo_inverse_to_1e_13(order, window):
    """The taps as numpy's pinv of the scaled Vandermonde matrix gives them (the code before issue 39; its bits
    depend on the CPU's BLAS kernels): at most 1.8e-14 of the largest tap apart (measured 2026-11-28)."""
    from studyapp.estimators.leastsq import taps

    h = (window - 1) / 2.0
    a = np.vander((np.arange(window) - h) / h, order + 1, increasing=True)
    pinv = (np.arange(order + 1.0) @ np.linalg.pinv(a))[::-1] * (5000.0 / h)
    ours = taps(order, window, 5000.0)
    assert np.abs(ours - pinv).max() <= 1e-13 * np.abs(pinv).max()


@pytest.mark.parametrize("rate", [1000.0, 96_000.0])
@pytest.mark.parametrize("order, window", [(1, 5), (2, 33), (3, 40), (5, 64)])
def test_leastsq_is_exact_on_polynomials(rate, order, window):
    t = np.arange(400) / rate
    rng = np.random.default_rng(order)
    coeffs = rng.normal(size=order + 1)
    x = np.polyval(coeffs, t)
    dx = np.polyval(np.polyder(coeffs), t)
    out = estimators.create("LEASTSQ", rate, order=order, window=window).process(x)
    np.testing.assert_allclose(out[window:], dx[window:], rtol=1e-6, atol=1e-6 * np.max(np.abs(dx)))


@pytest.mark.parametrize("rate", [5000.0, 48_000.0])
@pytest.mark.parametrize("name, lp, hp", [("COMP1", 317.0, 317.0), ("COMP2", 256.0, 2000.0)])
def test_complementary_is_lp_of_difference_plus_hp_of_trapezoid_integral(rate, name, lp, hp):
    rng = np.random.default_rng(3)
    n = 4000
    x = noisy_walk(n, seed=3)
    a = rng.normal(size=n)
    params = {"cutoff_hz": lp} if name == "COMP1" else {"lpf_hz": lp, "hpf_hz": hp}
    out = estimators.create(name, rate, **params).process(x, a)
    d = np.diff(x, prepend=x[0]) * rate
    integral = signal.lfilter([0.5 / rate, 0.5 / rate], [1.0, -1.0], a)
    expected = signal.sosfilt(signal.butter(2, lp, fs=rate, output="sos"), d) + signal.sosfilt(
        signal.butter(2, hp, btype="high", fs=rate, output="sos"), integral
    )
    np.testing.assert_allclose(out, expected, rtol=1e-7, atol=1e-9 * np.max(np.abs(expected)))


def test_comp1_notches_at_its_cutoff():
    """The documented caveat: Butterworth LP + HP at one cut-off sum to a notch."""
    rate, fc = 5000.0, 317.0
    lp = signal.butter(2, fc, fs=rate, output="sos")
    hp = signal.butter(2, fc, btype="high", fs=rate, output="sos")
    f = np.array([fc / 10, fc, fc * 10])
    total = signal.sosfreqz(lp, f, fs=rate)[1] + signal.sosfreqz(hp, f, fs=rate)[1]
    assert abs(total[1]) < 1e-6 and abs(total[0]) > 0.9 and abs(total[2]) > 0.9


def test_lvt_passes_velocity_through():
    v = np.random.default_rng(4).normal(size=100)
    np.testing.assert_array_equal(estimators.create("LVT", 5000).process(np.zeros(100), velocity=v), v)

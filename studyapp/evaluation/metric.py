"""Delay and delay-corrected error of a velocity estimate (paper Sec. 6.2, eqs. 22-24).

For a reference velocity ``v`` (the LVT tachometer, or the true velocity) and an
estimate ``w`` of it, both N samples at the same instants, two delays are on offer.

``method="normalised"`` (the default): the lag of the peak normalised
cross-correlation, each lag's sum divided by the energies of the samples it
uses (the correlation coefficient over the overlap, without removing means):

    D = argmax_{-max_lag <= k <= max_lag} r[k],
    r[k] = sum_n v[n] w[n + k] / sqrt( sum_n v[n]^2  sum_n w[n + k]^2 )

where every sum runs over the N - |k| samples n that both v[n] and w[n + k] have.

``method="paper"``: eq. 22 as printed, over non-negative lags and unnormalised,

    D = argmax_{0 <= k <= max_lag} c[k],   c[k] = sum_{n=0}^{N-k-1} v[n] w[n + k]    (eq. 22)

In both cases E is the RMSE over the samples the two signals share once the
estimate is shifted back by D (eqs. 23-24, whose index would otherwise run past
the end of the estimate):

    E = sqrt( 1/(N - |D|) sum_n (v[n] - w[n + D])^2 )

Why normalise. c[k] sums N - k products, so each extra sample of lag drops a
term. On a velocity dominated by slow strokes a dropped term is of the order
of the stroke's square, while the gain from lining up the stick-slip ripple is
only of the order of the ripple's curvature: the shrinking overlap outweighs
the correlation peak and eq. 22 reads 0 for estimators that clearly lag
(issue 12: LVT read 0 against the true velocity on 9 of 15 recordings, though
its 500 Hz band lags 2-3 samples at 5 kHz). Dividing by the overlap's length
alone, (1/(N - |k|)) sum_n v[n] w[n + k], removes the count of terms but not
their size: the mean product still moves with the stroke's energy in the few
samples that enter and leave the overlap, which again outweighs the ripple's
curvature on short or weakly rippled recordings and biases D (upwards, for a
low-pass estimate). Dividing by the overlap's energies removes both. By the
Cauchy-Schwarz inequality r[k] <= 1, with equality exactly where w[n + k] is a
positive multiple of v[n]: an exact copy delayed by k samples reads k on any
signal, and a gain error does not move D.

Why negative lags. Against the true velocity a causal estimator cannot lead,
but against the band-limited LVT reference (the paper's, eq. 25) an estimator
with less delay than the tachometer does lead; eq. 22's search from 0 reads
such an estimate as 0, the same as one that matches the LVT. The normalised
method reads a lead as a negative D. (The objective counts |D|: see
``normalisation.py``.)

D is the paper's scalar "global" delay, the shift that lines up the signals as
a whole; a filter's delay depends on frequency, and D follows the frequencies
that carry the correlation's curvature. An overlap of zero energy correlates
as 0. Ties go to the lag of smallest magnitude, then to the positive one.

The products come from one FFT (``scipy.signal.correlate``), O(N log N)
whatever ``max_lag`` is, and the energies from cumulative sums. ``Reference``
keeps the transform of one reference so that many estimates of it (the
optimiser's use) each cost one forward and one inverse real FFT; zero-padding
to at least N + max_lag samples keeps the circular correlation equal to the
linear one at lags -max_lag..max_lag.
"""

import numpy as np
from numba import njit
from scipy import fft, signal

from studyapp.errors import InputDataError, UserError

METHODS = ("normalised", "paper")
DEFAULT_METHOD = "normalised"


def check_method(method):
    if method not in METHODS:
        raise UserError(f"delay method {method!r}: allowed is {' or '.join(METHODS)}")
    return method


def _as_signal(name, values):
    arr = np.asarray(values, dtype=np.float64)
    if arr.ndim != 1:
        raise InputDataError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    return arr


def _check_reference(v, max_lag):
    n = v.shape[0]
    max_lag = int(max_lag)
    if max_lag < 0 or max_lag >= n:
        raise InputDataError(f"max_lag = {max_lag}: allowed is an integer from 0 to {n - 1} (samples)")
    if not np.all(np.isfinite(v)):
        raise InputDataError("reference: contains NaN or inf samples")
    return max_lag


def lags(max_lag, method=DEFAULT_METHOD):
    """The lags searched, in the order of ``cross_correlation``'s values."""
    return np.arange(-max_lag if check_method(method) == "normalised" else 0, max_lag + 1)


def _overlap_energy(x, starts, stops):
    """sum of x[n]^2 over n in [start, stop) for each pair, from one cumulative sum."""
    cumulative = np.concatenate(([0.0], np.cumsum(x * x)))
    return cumulative[stops] - cumulative[starts]


def _scaled(sums, v, w, max_lag, method):
    """The sums of products at ``lags(max_lag, method)``, normalised for the normalised method."""
    if method == "paper":
        return sums
    n = v.shape[0]
    ks = lags(max_lag, method)
    v_start = np.maximum(0, -ks)
    v_stop = n - np.maximum(0, ks)
    energy = _overlap_energy(v, v_start, v_stop) * _overlap_energy(w, v_start + ks, v_stop + ks)
    out = np.zeros_like(sums)
    np.divide(sums, np.sqrt(energy), out=out, where=energy > 0)
    return out


def cross_correlation(reference, estimate, max_lag, method=DEFAULT_METHOD):
    """r[k] (normalised) or eq. 22's c[k] (paper) at ``lags(max_lag, method)``."""
    check_method(method)
    reference, estimate = _as_signal("reference", reference), _as_signal("estimate", estimate)
    full = signal.correlate(estimate, reference, mode="full", method="fft")
    zero = reference.shape[0] - 1  # index of lag 0 in the full correlation
    low = zero - max_lag if method == "normalised" else zero
    return _scaled(full[low:zero + max_lag + 1], reference, estimate, max_lag, method)


def delay_and_error(reference, estimate, max_lag, method=DEFAULT_METHOD):
    """(D, E): the delay in samples (int) and the delay-corrected RMSE (eqs. 22-24).

    ``reference`` and ``estimate`` are equal-length 1-D arrays; ``max_lag``
    (samples) bounds the delay search and must leave at least one shared
    sample. ``method`` is ``"normalised"`` (D in -max_lag..max_lag; an
    estimate that leads the reference reads negative) or ``"paper"`` (eq. 22,
    D in 0..max_lag). A non-finite estimate has no meaningful delay: the
    result is ``(0, inf)``.
    """
    check_method(method)
    v = _as_signal("reference", reference)
    w = _as_signal("estimate", estimate)
    if v.shape != w.shape:
        raise InputDataError(f"reference and estimate differ in length: {v.shape[0]} and {w.shape[0]} samples")
    max_lag = _check_reference(v, max_lag)
    if not np.all(np.isfinite(w)):
        return 0, float("inf")
    return _delay_corrected(v, w, lags(max_lag, method), cross_correlation(v, w, max_lag, method))


def _tie_order(ks):
    # Stable sort by |k|, positive before negative: argmax then takes the first
    # maximum, i.e. the tie rule of the module docstring.
    return np.lexsort((-ks, np.abs(ks)))


@njit(cache=True)
def _overlap_energies(x, starts, stops):
    """``_overlap_energy(x, starts, stops)`` with the same sums in the same order, without temporaries."""
    cumulative = np.empty(x.shape[0] + 1)
    total = 0.0
    cumulative[0] = total
    for i in range(x.shape[0]):
        total = total + x[i] * x[i]
        cumulative[i + 1] = total
    out = np.empty(starts.shape[0])
    for j in range(starts.shape[0]):
        out[j] = cumulative[stops[j]] - cumulative[starts[j]]
    return out


def _delay_corrected(v, w, ks, c, order=None):
    order = _tie_order(ks) if order is None else order
    delay = int(ks[order[np.argmax(c[order])]])
    n = v.shape[0]
    if delay >= 0:
        residual = v[: n - delay] - w[delay:]
    else:
        residual = v[-delay:] - w[: n + delay]
    return delay, float(np.sqrt(np.mean(residual * residual)))


class Reference:
    """One reference velocity, ready to measure many estimates against it.

    ``measure(estimate)`` returns what ``delay_and_error(reference, estimate,
    max_lag, method)`` returns, bit for bit, with everything that depends on
    the reference alone computed once: its transform, its overlap energies and
    the order of the tie rule. (Measured on 35,000 samples, 2026-11-25: the two
    real FFTs are most of what is left, about 0.45 ms of CPU per estimate.)
    """

    def __init__(self, reference, max_lag, method=DEFAULT_METHOD):
        self.method = check_method(method)
        self.v = _as_signal("reference", reference)
        self.max_lag = _check_reference(self.v, max_lag)
        self.lags = lags(self.max_lag, method)
        self.order = _tie_order(self.lags)
        self.size = fft.next_fast_len(self.v.shape[0] + self.max_lag, real=True)
        self.spectrum = np.conj(fft.rfft(self.v, self.size))
        n = self.v.shape[0]
        v_start = np.maximum(0, -self.lags)
        v_stop = n - np.maximum(0, self.lags)
        self.w_start, self.w_stop = v_start + self.lags, v_stop + self.lags
        self.v_energy = _overlap_energy(self.v, v_start, v_stop)

    def measure(self, estimate):
        w = _as_signal("estimate", estimate)
        if w.shape != self.v.shape:
            raise InputDataError(
                f"reference and estimate differ in length: {self.v.shape[0]} and {w.shape[0]} samples")
        if not np.all(np.isfinite(w)):
            return 0, float("inf")
        circular = fft.irfft(fft.rfft(w, self.size) * self.spectrum, self.size)
        sums = circular[self.lags]  # negative lags index from the end: the circular wrap
        if self.method == "normalised":
            energy = self.v_energy * _overlap_energies(w, self.w_start, self.w_stop)
            scaled = np.zeros_like(sums)
            np.divide(sums, np.sqrt(energy), out=scaled, where=energy > 0)
            sums = scaled
        return _delay_corrected(self.v, w, self.lags, sums, self.order)

"""Delay and delay-corrected error of a velocity estimate (paper Sec. 6.2, eqs. 22-24).

For a reference velocity ``v`` (the LVT tachometer, or the true velocity) and an
estimate ``w`` of it, both sampled at the same instants,

    D = argmax_{0 <= k <= max_lag} c[k],   c[k] = sum_n v[n] w[n + k]      (eq. 22)
    E = sqrt( 1/(N - D) sum_{n=0}^{N-D-1} (v[n] - w[n + D])^2 )          (eqs. 23-24)

D is the global delay in samples of the estimate behind the reference: the
lag of the peak cross-correlation, searched over non-negative lags only (an
estimator cannot lead a causal reference). E is the RMSE once that delay is
removed by shifting the estimate back; the sum runs over the N - D samples the
two shifted signals share, since eq. 24's index would otherwise run past the
end of the estimate. Ties in c go to the smallest lag.

The correlation is computed by FFT (``scipy.signal.correlate``), which costs
O(N log N) whatever ``max_lag`` is. ``Reference`` keeps the transform of one
reference so that many estimates of it (the optimiser's use) each cost one
forward and one inverse real FFT; zero-padding to at least N + max_lag samples
keeps the circular correlation equal to the linear one at lags 0..max_lag. A filter's delay depends on frequency; D is
the paper's scalar "global" delay, the shift that lines up impulsive events.
"""

import numpy as np
from scipy import fft, signal

from studyapp.errors import InputDataError


def _as_signal(name, values):
    arr = np.asarray(values, dtype=np.float64)
    if arr.ndim != 1:
        raise InputDataError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    return arr


def cross_correlation(reference, estimate, max_lag):
    """c[k] = sum_n reference[n] * estimate[n + k] for k = 0 .. max_lag (eq. 22's correlation)."""
    full = signal.correlate(estimate, reference, mode="full", method="fft")
    zero = reference.shape[0] - 1  # index of lag 0 in the full correlation
    return full[zero:zero + max_lag + 1]


def delay_and_error(reference, estimate, max_lag):
    """(D, E): the delay in samples (int, 0..max_lag) and the delay-corrected RMSE (eqs. 22-24).

    ``reference`` and ``estimate`` are equal-length 1-D arrays; ``max_lag`` (samples)
    bounds the delay search and must leave at least one shared sample. A
    non-finite estimate has no meaningful delay: the result is ``(0, inf)``.
    """
    v = _as_signal("reference", reference)
    w = _as_signal("estimate", estimate)
    if v.shape != w.shape:
        raise InputDataError(f"reference and estimate differ in length: {v.shape[0]} and {w.shape[0]} samples")
    n = v.shape[0]
    max_lag = int(max_lag)
    if max_lag < 0 or max_lag >= n:
        raise InputDataError(f"max_lag = {max_lag}: allowed is an integer from 0 to {n - 1} (samples)")
    if not np.all(np.isfinite(v)):
        raise InputDataError("reference: contains NaN or inf samples")
    if not np.all(np.isfinite(w)):
        return 0, float("inf")
    return _delay_corrected(v, w, cross_correlation(v, w, max_lag))


def _delay_corrected(v, w, c):
    n = v.shape[0]
    delay = int(np.argmax(c))
    residual = v[: n - delay] - w[delay:]
    return delay, float(np.sqrt(np.mean(residual * residual)))


class Reference:
    """One reference velocity, ready to measure many estimates against it.

    ``measure(estimate)`` returns what ``delay_and_error(reference, estimate,
    max_lag)`` returns, with the reference's transform computed once.
    """

    def __init__(self, reference, max_lag):
        self.v = _as_signal("reference", reference)
        n = self.v.shape[0]
        self.max_lag = int(max_lag)
        if self.max_lag < 0 or self.max_lag >= n:
            raise InputDataError(f"max_lag = {self.max_lag}: allowed is an integer from 0 to {n - 1} (samples)")
        if not np.all(np.isfinite(self.v)):
            raise InputDataError("reference: contains NaN or inf samples")
        self.size = fft.next_fast_len(n + self.max_lag, real=True)
        self.spectrum = np.conj(fft.rfft(self.v, self.size))

    def measure(self, estimate):
        w = _as_signal("estimate", estimate)
        if w.shape != self.v.shape:
            raise InputDataError(
                f"reference and estimate differ in length: {self.v.shape[0]} and {w.shape[0]} samples")
        if not np.all(np.isfinite(w)):
            return 0, float("inf")
        c = fft.irfft(fft.rfft(w, self.size) * self.spectrum, self.size)[: self.max_lag + 1]
        return _delay_corrected(self.v, w, c)

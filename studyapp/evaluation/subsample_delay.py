"""The delay between whole samples (issue 30): the peak of the correlation refined by a parabola.

The delay D of eqs. 22-24 (``metric.py``) is a whole number of samples. The
objective drives every tuned estimator to the LVT reference's own delay, so on
the study's low-force recordings every tuned estimator reads D = 0 and D alone
cannot rank them. Here the peak of the correlation r (normalised, or eq. 22's
c with ``method="paper"``) is refined by the parabola through r at D - 1, D
and D + 1:

    d = D + (r[D-1] - r[D+1]) / (2 (r[D-1] - 2 r[D] + r[D+1]))

exact where r is quadratic about its peak, as the correlation of a signal
whose power lies well below the Nyquist frequency is (checked against pure
fractional delays and a one-pole low-pass's group delay,
tests/evaluation/test_evaluation_subsample_delay.py). At the ends of the lag
range, or where the three points do not bend down, d = D; the offset is
clipped to half a sample. d only reports: the objective, and so the
optimiser, keeps the whole-sample D.
"""

import numpy as np

from studyapp.evaluation.metric import (
    DEFAULT_METHOD, _as_signal, _check_reference, _delay_corrected, check_method, cross_correlation, lags,
)
from studyapp.errors import InputDataError


def parabolic_peak(ks, c, delay):
    """The lag of the peak of the parabola through c at ``delay`` and its two neighbours (``delay`` at an end)."""
    i = int(np.searchsorted(ks, delay))
    if i == 0 or i == ks.shape[0] - 1:
        return float(delay)
    left, centre, right = c[i - 1], c[i], c[i + 1]
    bend = left - 2.0 * centre + right
    if not bend < 0.0:
        return float(delay)
    return float(delay + np.clip(0.5 * (left - right) / bend, -0.5, 0.5))


def subsample_delay(reference, estimate, max_lag, method=DEFAULT_METHOD):
    """The delay in samples (float; NaN for a non-finite estimate), D refined between samples by a parabola."""
    check_method(method)
    v, w = _as_signal("reference", reference), _as_signal("estimate", estimate)
    if v.shape != w.shape:
        raise InputDataError(f"reference and estimate differ in length: {v.shape[0]} and {w.shape[0]} samples")
    max_lag = _check_reference(v, max_lag)
    if not np.all(np.isfinite(w)):
        return float("nan")
    ks, c = lags(max_lag, method), cross_correlation(v, w, max_lag, method)
    delay, _ = _delay_corrected(v, w, ks, c)
    return parabolic_peak(ks, c, delay)

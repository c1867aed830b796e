"""Spearman's rank correlation rho, with its two-sided p-value (paper Sec. 9.1 and 10).

rho is Pearson's correlation of the average ranks (ties share their mean rank):

    rho = sum (r_i - rbar)(s_i - sbar) / sqrt(sum (r_i - rbar)^2 sum (s_i - sbar)^2)

which without ties equals 1 - 6 sum d_i^2 / (n (n^2 - 1)), d_i = r_i - s_i.
The p-value uses t = rho sqrt((n - 2) / (1 - rho^2)) with Student's t on n - 2
degrees of freedom, as ``scipy.stats.spearmanr`` does (an approximation; with
the 8 or 9 conditions of the paper it is rough, so read it as a guide).

rho is undefined (NaN, p NaN) with fewer than 3 pairs or when either variable
is constant: a ranking needs at least two distinct values to compare.
"""

import numpy as np
from scipy.special import stdtr

from studyapp.stats.ranks import average_ranks


def spearman(x, y):
    """(rho, p_value) of paired samples ``x`` and ``y``; (nan, nan) when undefined."""
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size != y.size:
        raise ValueError(f"spearman needs paired samples, got sizes {x.size} and {y.size}")
    n = x.size
    if n < 3:
        return float("nan"), float("nan")
    r = average_ranks(x)
    s = average_ranks(y)
    r -= r.mean()
    s -= s.mean()
    denominator = np.sqrt(np.sum(r * r) * np.sum(s * s))
    if denominator == 0.0:
        return float("nan"), float("nan")
    rho = float(np.clip(np.sum(r * s) / denominator, -1.0, 1.0))
    if abs(rho) == 1.0:
        return rho, 0.0
    t = rho * np.sqrt((n - 2) / (1.0 - rho * rho))
    return rho, float(2.0 * stdtr(n - 2, -abs(t)))

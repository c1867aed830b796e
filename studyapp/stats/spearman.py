"""Spearman's rank correlation rho, with its two-sided p-value (paper Sec. 9.1 and 10).

rho is Pearson's correlation of the average ranks (ties share their mean rank):

    rho = sum (r_i - rbar)(s_i - sbar) / sqrt(sum (r_i - rbar)^2 sum (s_i - sbar)^2)

which without ties equals 1 - 6 sum d_i^2 / (n (n^2 - 1)), d_i = r_i - s_i.
The p-value uses t = rho sqrt((n - 2) / (1 - rho^2)) with Student's t on n - 2
degrees of freedom (an approximation; with the 8 or 9 conditions of the paper it
is rough, so read it as a guide). Both are ``scipy.stats.spearmanr``'s.

rho is undefined (NaN, p NaN) with fewer than 3 pairs or when either variable
is constant: a ranking needs at least two distinct values to compare. The same
or the reversed ranking is rho = +-1 exactly, p = 0. Those guards are this
module's: spearmanr warns on a constant input, gives a p for 2 pairs, and its
rho of two equal rankings can be 1 - 1e-16.
"""

import numpy as np
from scipy import stats


def spearman(x, y):
    """(rho, p_value) of paired samples ``x`` and ``y``; (nan, nan) when undefined."""
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    if x.size != y.size:
        raise ValueError(f"spearman needs paired samples, got sizes {x.size} and {y.size}")
    if x.size < 3 or np.all(x == x[0]) or np.all(y == y[0]):
        return float("nan"), float("nan")
    r, s = stats.rankdata(x), stats.rankdata(y)
    for sign in (1.0, -1.0):
        if np.array_equal(r, s if sign > 0 else s.size + 1 - s):
            return sign, 0.0  # the same (or reversed) ranking: exactly +-1, where spearmanr may give 0.9999999999999999
    result = stats.spearmanr(x, y)
    return float(result.statistic), float(result.pvalue)

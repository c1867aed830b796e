"""Pairwise Wilcoxon rank-sum tests between estimators (paper Sec. 7.2, Fig. 5).

For each pair of estimators and each measure (per-recording objective, error
and delay as percent of LOWPASS) the two samples over a group's recordings are
compared with the two-sided Wilcoxon rank-sum test (rank_sum.py, the one
definition shared with ``studyapp analyse``: statistic z, p exact for small
samples without ties, normal approximation with tie correction otherwise). A
pair differs significantly when p < 0.05, the paper's threshold. Recordings
where a measure is not finite are left out of that measure; pairs with fewer
than two finite values on a side get z = NaN and p = 1 (no evidence of a
difference), as do two identical constant samples (z = 0).
"""

import itertools

import numpy as np

from studyapp.stats.rank_sum import rank_sum_test

ALPHA = 0.05


def rank_sum(a, b):
    """(z statistic, two-sided p) of the rank-sum test of the finite values; p = 1 when there is nothing to test."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if a.size < 2 or b.size < 2:
        return float("nan"), 1.0
    test = rank_sum_test(a, b)
    return test.statistic, test.p_value


def pairwise(samples, alpha=ALPHA):
    """Rows {a, b, n_a, n_b, median_a, median_b, statistic, p, significant} for every pair of ``samples``."""
    rows = []
    for a, b in itertools.combinations(samples, 2):
        z, p = rank_sum(samples[a], samples[b])
        rows.append({
            "a": a, "b": b, "n_a": int(np.isfinite(samples[a]).sum()), "n_b": int(np.isfinite(samples[b]).sum()),
            "median_a": float(np.nanmedian(samples[a])) if np.isfinite(samples[a]).any() else float("nan"),
            "median_b": float(np.nanmedian(samples[b])) if np.isfinite(samples[b]).any() else float("nan"),
            "statistic": z, "p": p, "significant": bool(p < alpha),
        })
    return rows


def not_different_from_best(samples, alpha=ALPHA):
    """The best estimator by median and those not significantly different from it."""
    finite = {n: v for n, v in samples.items() if np.isfinite(v).any()}
    if not finite:
        return set()
    best = min(finite, key=lambda n: np.nanmedian(finite[n]))
    return {best} | {n for n in finite if n != best and rank_sum(finite[best], finite[n])[1] >= alpha}

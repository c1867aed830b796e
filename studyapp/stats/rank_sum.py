"""The Wilcoxon rank-sum test of two independent samples: the one definition (paper Sec. 7.2 and 9, ref. [28]).

The paper judges pairs of estimators (Fig. 5) and pairs of conditions (Figs. 7-8)
with "Wilcoxon's rank-sums test, with p < 0.05 indicating confidence that
distributions are not the same". Both ``studyapp evaluate`` (significance.py) and
``studyapp analyse`` (analysis/rank_sum.py) call ``rank_sum_test`` below. For
samples a (size n1) and b (size n2), N = n1 + n2:

    W     = sum of the ranks of a among the pooled N values (average ranks for ties)
    U     = W - n1 (n1 + 1) / 2        (the pairs (a_i, b_j) with a_i > b_j, ties counting 1/2)
    E[W]  = n1 (N + 1) / 2
    Var W = n1 n2 (N + 1) / 12  -  n1 n2 sum(t^3 - t) / (12 N (N - 1))
    z     = (W - E[W]) / sqrt(Var W)

with t the sizes of the runs of tied values. The statistic reported is z, signed:
positive when a tends to be larger, so one column reads the same in both tables.

The two-sided p:

- exact when the smaller sample has at most 8 values and no value ties: every one
  of the C(N, n1) ways to pick a's ranks is equally likely under the null, and
  p = min(1, 2 P(U' >= max(U, n1 n2 - U))), the distribution of U' counted below.
  A normal approximation is too small there (3 against 3 fully separated gives
  z = 1.96, p = 0.0495, while only 2 of the 20 orderings are as extreme: p = 0.1);
- otherwise p = 2 (1 - Phi(|z|)): the normal approximation with tie correction and
  without continuity correction. Ratings on a knob and F_max values on a log knob
  tie often, which is why the tie correction matters; the continuity correction is
  left out as in the paper's rank-sums z (``scipy.stats.ranksums``).

The p is ``scipy.stats.mannwhitneyu(a, b, method="auto", use_continuity=False)``'s
(scipy chooses "exact" by the same rule; tests/stats/test_rank_sum.py checks it
against the count of orderings above); this module adds z, the statistic both
tables report. Without ties the asymptotic p is ``scipy.stats.ranksums``'
(ranksums has no tie correction: with ties its variance is too large and its p too
big). When every pooled value is equal the variance is zero: there is no evidence
of a difference, so z = 0 and p = 1.
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from studyapp.errors import InputDataError

EXACT_MAX_SMALLER = 8  # scipy's "auto" rule: exact p when the smaller sample has at most 8 values and none tie


@dataclass(frozen=True)
class RankSum:
    """One rank-sum test: z statistic, two-sided p, rank sum W of the first sample, and whether p is exact."""

    statistic: float
    p_value: float
    rank_sum: float
    exact: bool = False


def rank_sum_test(a, b):
    """Two-sided Wilcoxon rank-sum test of samples ``a`` and ``b`` (module docstring)."""
    a = np.asarray(a, dtype=float).ravel()
    b = np.asarray(b, dtype=float).ravel()
    n1, n2 = a.size, b.size
    if n1 == 0 or n2 == 0:
        raise InputDataError(f"rank-sum test needs two non-empty samples, got sizes {n1} and {n2}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise InputDataError("rank-sum test needs finite values (found NaN or infinity)")
    pooled = np.concatenate([a, b])
    n = n1 + n2
    w = float(stats.rankdata(pooled)[:n1].sum())
    t = np.unique(pooled, return_counts=True)[1].astype(float)  # sizes of the runs of tied values
    tie_term = float(np.sum(t**3 - t))
    variance = n1 * n2 * (n + 1) / 12.0 - n1 * n2 * tie_term / (12.0 * n * (n - 1))
    if variance <= 0.0:
        return RankSum(0.0, 1.0, w)
    z = float((w - n1 * (n + 1) / 2.0) / np.sqrt(variance))
    p = float(stats.mannwhitneyu(a, b, method="auto", use_continuity=False).pvalue)
    return RankSum(z, p, w, exact=tie_term == 0.0 and min(n1, n2) <= EXACT_MAX_SMALLER)

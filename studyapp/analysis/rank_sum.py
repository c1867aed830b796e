"""Wilcoxon rank-sum test between two independent samples (paper Sec. 7.2 and 9, ref. [28]).

The paper judges each pair of conditions with "Wilcoxon's rank-sums test, with
p < 0.05 indicating confidence that distributions are not the same". For samples
a (size n1) and b (size n2), N = n1 + n2:

    W     = sum of the ranks of a among the pooled N values (average ranks for ties)
    E[W]  = n1 (N + 1) / 2
    Var W = n1 n2 (N + 1) / 12  -  n1 n2 sum(t^3 - t) / (12 N (N - 1))
    z     = (W - E[W]) / sqrt(Var W),     p = 2 (1 - Phi(|z|))    (two-sided)

with t the sizes of the runs of tied values. This is the normal approximation
with tie correction and without continuity correction. It equals
``scipy.stats.ranksums`` when there are no ties (ranksums has no tie correction,
so with ties its variance is too large and its p too big), and with or without
ties it has the p-value of ``scipy.stats.mannwhitneyu(a, b, method="asymptotic",
use_continuity=False)`` (U = W - n1 (n1 + 1) / 2 has the same z). Ratings on a
knob and F_max values on a log knob tie often, which is why the tie correction
matters here. The statistic reported is z: positive when a tends to be larger.

When every pooled value is equal the variance is zero: there is no evidence of
a difference, so z = 0 and p = 1.

The analysis applies it as the paper did, to every trial of every participant
pooled per condition. The test assumes independent samples, which the trials
of one participant are not (they share that participant's criterion), so its
p-values come out too small: two participants with six trials each give
p ~ 3e-5. Tables and figures label it ``POOLED``; the within-subject tests
(within_subject.py) treat participants as the units.
"""

from dataclasses import dataclass
from itertools import combinations

import numpy as np
import pandas as pd
from scipy.special import ndtr

from studyapp.analysis.holm import holm_adjust
from studyapp.analysis.ranks import average_ranks, tie_sizes
from studyapp.errors import InputDataError

POOLED = "pooled across participants, as the paper did; trials are not independent"
WILCOXON_COLUMNS = ["condition_a", "condition_b", "statistic", "p_value", "significant"]


@dataclass(frozen=True)
class RankSum:
    """One rank-sum test: z statistic, two-sided p, rank sum W of the first sample."""

    statistic: float
    p_value: float
    rank_sum: float


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
    w = float(average_ranks(pooled)[:n1].sum())
    expected = n1 * (n + 1) / 2.0
    t = tie_sizes(pooled).astype(float)
    tie_term = float(np.sum(t**3 - t))
    variance = n1 * n2 * (n + 1) / 12.0
    if n > 1:
        variance -= n1 * n2 * tie_term / (12.0 * n * (n - 1))
    if variance <= 0.0:
        return RankSum(0.0, 1.0, w)
    z = (w - expected) / np.sqrt(variance)
    return RankSum(float(z), float(2.0 * ndtr(-abs(z))), w)


def pairwise_rank_sum(groups, alpha=0.05, holm=False):
    """Rank-sum tests of every unordered pair of ``groups`` ({condition: values}), each pair once.

    Returns a DataFrame with ``WILCOXON_COLUMNS`` plus ``p_raw``; the pairs follow
    the order of ``groups`` (a before b). ``significant`` is ``p_value < alpha``;
    with ``holm`` the ``p_value`` column holds Holm-adjusted p-values over all
    the pairs of this table (``p_raw`` keeps the unadjusted ones).
    """
    rows = []
    for name_a, name_b in combinations(list(groups), 2):
        test = rank_sum_test(groups[name_a], groups[name_b])
        rows.append((name_a, name_b, test.statistic, test.p_value))
    table = pd.DataFrame(rows, columns=["condition_a", "condition_b", "statistic", "p_raw"])
    table["condition_a"] = table["condition_a"].astype(object)
    table["condition_b"] = table["condition_b"].astype(object)
    raw = table["p_raw"].to_numpy(dtype=float)
    table["p_value"] = holm_adjust(raw) if holm else raw
    table["significant"] = table["p_value"] < alpha
    return table[WILCOXON_COLUMNS + ["p_raw"]]

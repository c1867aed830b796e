"""Wilcoxon signed-rank test of two conditions measured on the same participants, with its effect size.

The within-subject counterpart of the paper's rank-sum test (Sec. 9): each
participant contributes one pair (their median in condition a, their median in
condition b), so participants, not trials, are the independent units. With the
differences d_i = a_i - b_i:

- zero differences are dropped (``zero_method="wilcox"``, scipy's default and
  Wilcoxon's own convention), leaving n' non-zero d_i (differences are
  rounded to 12 decimals first, so float noise neither hides a zero nor
  breaks a tie);
- |d_i| are ranked 1..n', ties sharing their average rank;
- T+ = sum of the ranks of the positive d_i, T- = that of the negative ones,
  T+ + T- = n' (n' + 1) / 2. The statistic reported is T = min(T+, T-), as
  ``scipy.stats.wilcoxon`` reports for a two-sided test.

The two-sided p-value, for n' <= 50, is exact: the share of the 2^n' equally
likely sign assignments to the observed ranks whose |T+ - T-| is at least the
observed one.

- Without ties among the |d_i| that is ``scipy.stats.wilcoxon(method="exact")``.
- With ties, scipy's "exact" assumes distinct ranks 1..n' and is off, and its
  enumeration (``method=PermutationMethod(n_resamples=2**n')``) recomputes the
  statistic for each of the 2^n' assignments. The same conditional
  distribution is counted here directly: with every rank doubled to an
  integer q_i, the number of sign assignments giving each doubled T+ is the
  coefficient of the generating function prod_i (1 + x^q_i), built one rank at
  a time (O(n'^3) additions).
- Beyond 50 pairs, scipy's normal approximation with tie correction
  (``method="asymptotic"``).

Effect size: the matched-pairs rank-biserial correlation in Kerby's (2014)
simple-difference form,

    r = (T+ - T-) / (T+ + T-)

in [-1, 1], positive when condition a tends to be larger (the sign of the
rank-sum z). When every difference is zero there is no evidence of a
difference: T = 0, p = 1, r = 0.

Smallest attainable p: without ties the most extreme outcome (every d_i of one
sign) has probability 2 / 2^n' two-sided, so a test on n participants can
never give p below 2^(1 - n): p < 0.05 needs n >= 6; after Holm's correction
over m pairs, m 2^(1 - n) < alpha is needed (36 pairs: n = 9 gives at best
36 x 2^-8 = 0.14, n >= 11 is needed).
"""

from dataclasses import dataclass

import numpy as np
from scipy import stats

from studyapp.errors import InputDataError

ZERO_METHOD = "wilcox"
DECIMALS = 12
EXACT_LIMIT = 50  # pairs up to which p is exact (scipy's own limit for its exact distribution)


@dataclass(frozen=True)
class SignedRank:
    """One signed-rank test: T = min(T+, T-), two-sided p, T+ and T-, rank-biserial r, n' non-zero pairs."""

    statistic: float
    p_value: float
    t_plus: float
    t_minus: float
    effect_size: float
    n_nonzero: int


def signed_rank_test(a, b):
    """Two-sided Wilcoxon signed-rank test of paired samples ``a`` and ``b`` (module docstring)."""
    a = np.asarray(a, dtype=float).ravel()
    b = np.asarray(b, dtype=float).ravel()
    if a.size != b.size or a.size == 0:
        raise InputDataError(f"signed-rank test needs two paired non-empty samples, got sizes {a.size} and {b.size}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise InputDataError("signed-rank test needs finite values (found NaN or infinity)")
    # Float noise (0.3 - 0.1 != 0.2) must neither break a tie nor hide a zero difference.
    d = np.round(a - b, DECIMALS)
    d = d[d != 0.0]
    n = d.size
    if n == 0:
        return SignedRank(0.0, 1.0, 0.0, 0.0, 0.0, 0)
    ranks = stats.rankdata(np.abs(d))  # ties share their mean rank
    t_plus = float(ranks[d > 0].sum())
    t_minus = float(ranks[d < 0].sum())
    if n > EXACT_LIMIT:
        p = float(stats.wilcoxon(d, zero_method=ZERO_METHOD, method="asymptotic").pvalue)
    elif np.unique(np.abs(d)).size < n:
        p = exact_tied_p(ranks, t_plus)
    else:
        p = float(stats.wilcoxon(d, zero_method=ZERO_METHOD, method="exact").pvalue)
    effect = (t_plus - t_minus) / (t_plus + t_minus)
    return SignedRank(min(t_plus, t_minus), min(1.0, p), t_plus, t_minus, effect, n)


def exact_tied_p(ranks, t_plus):
    """Two-sided p of T+ = ``t_plus`` over every sign assignment to ``ranks`` (mid-ranks: halves allowed)."""
    doubled = np.rint(2.0 * np.asarray(ranks, dtype=float)).astype(int)
    # counts[t] = number of sign assignments whose doubled T+ is t; at most 2^50 < 2^53, exact in float64.
    counts = np.zeros(int(doubled.sum()) + 1)
    counts[0] = 1.0
    for q in doubled:
        counts[q:] = counts[q:] + counts[:-q]  # the right side is built before the assignment
    centre = doubled.sum() / 2.0
    extreme = np.abs(np.arange(counts.size) - centre) >= abs(2.0 * t_plus - centre) - 1e-9
    return float(counts[extreme].sum() / counts.sum())


def minimum_p(n):
    """The smallest two-sided p a signed-rank test on ``n`` pairs can give (no ties): 2^(1 - n)."""
    return 2.0 ** (1 - n) if n > 0 else 1.0


def participants_needed(alpha, pairs=1):
    """The fewest participants with which ``pairs`` Holm-corrected tests can reach p < ``alpha``.

    Holm's first step multiplies the smallest p by the number of pairs, so the
    smallest n with pairs x 2^(1 - n) < alpha (counted, not solved with a
    logarithm, so an exact power of two is not lost to rounding).
    """
    if not 0.0 < alpha <= 1.0:
        raise ValueError(f"alpha = {alpha}: allowed is 0 < alpha <= 1")
    n = 1
    while max(pairs, 1) * minimum_p(n) >= alpha:
        n += 1
    return n

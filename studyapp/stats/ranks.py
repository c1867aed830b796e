"""Ranks with ties, the common ground of the rank-sum test and Spearman's rho.

Sorting the pooled values, the k-th smallest gets rank k (1-based). A run of t
equal values that would take ranks r+1 .. r+t all get their average,
r + (t + 1) / 2 (the "average" or "mid-rank" method, as
``scipy.stats.rankdata(method="average")``). The sizes t of those runs give
the tie correction of the rank-sum variance, sum(t^3 - t).
"""

import numpy as np


def average_ranks(values):
    """Ranks 1..n of ``values`` (1-D), ties sharing the average of the ranks they span."""
    x = np.asarray(values, dtype=float).ravel()
    order = np.argsort(x, kind="mergesort")
    sorted_x = x[order]
    # Starts of each run of equal values in sorted order, and one past the end.
    starts = np.flatnonzero(np.r_[True, sorted_x[1:] != sorted_x[:-1]])
    ends = np.r_[starts[1:], x.size]
    run_rank = (starts + 1 + ends) / 2.0
    ranks = np.empty(x.size)
    ranks[order] = np.repeat(run_rank, ends - starts)
    return ranks


def tie_sizes(values):
    """Sizes t of every run of equal values (runs of one included)."""
    x = np.sort(np.asarray(values, dtype=float).ravel())
    if x.size == 0:
        return np.zeros(0, dtype=int)
    starts = np.flatnonzero(np.r_[True, x[1:] != x[:-1]])
    return np.diff(np.r_[starts, x.size])

"""The one rank-sum test (stats/rank_sum.py): hand-computed examples, scipy on the same data, exact p by counting."""

import math

import numpy as np
import pytest
from scipy import stats

from studyapp.errors import InputDataError
from studyapp.stats.rank_sum import EXACT_MAX_SMALLER, rank_sum_test


def u_distribution(n1, n2):
    """Counts of U = 0 .. n1 n2 over the C(n1 + n2, n1) placements of n1 values among n2 (no ties).

    Going through the pooled order, placing the next value in a when k values of a
    and j of b are already placed adds j = (position - k) to U.
    """
    counts = np.zeros((n1 + 1, n1 * n2 + 1))
    counts[0, 0] = 1.0
    for position in range(n1 + n2):
        for k in range(min(position, n1 - 1), -1, -1):
            below = position - k
            if below > n2:
                continue
            counts[k + 1, below:] += counts[k, : counts.shape[1] - below]
    return counts[n1]


def exact_p(a, b):
    """Two-sided exact p of untied samples by counting orderings: 2 P(U' >= max(U, n1 n2 - U)), at most 1."""
    n1, n2 = len(a), len(b)
    u = sum(1 for x in a for y in b if x > y)
    counts = u_distribution(n1, n2)
    return min(1.0, 2.0 * float(counts[max(u, n1 * n2 - u):].sum()) / math.comb(n1 + n2, n1))


def test_average_ranks_with_ties_by_hand():
    # Sorted: 1, 2, 2, 2, 3, 4, 5 -> the three 2s share ranks 2, 3, 4, i.e. 3 (the ranks rank_sum_test sums).
    assert stats.rankdata([2, 5, 1, 2, 4, 2, 3]).tolist() == [3, 7, 1, 3, 6, 3, 5]


def test_rank_sum_with_ties_by_hand():
    # a = 1, 2, 2, 4; b = 2, 3, 5. Ranks of a: 1, 3, 3, 6 -> W = 13; E[W] = 4 * 8 / 2 = 16.
    # Var W = 4 * 3 * 8 / 12 - 4 * 3 * (3^3 - 3) / (12 * 7 * 6) = 8 - 4/7 = 52/7.
    test = rank_sum_test([1, 2, 2, 4], [2, 3, 5])
    z = -3.0 / math.sqrt(52.0 / 7.0)
    assert test.rank_sum == 13.0
    assert test.statistic == pytest.approx(z, rel=1e-12)
    assert test.p_value == pytest.approx(math.erfc(abs(z) / math.sqrt(2.0)), rel=1e-12)


def test_rank_sum_without_ties_by_hand():
    # a = 1, 3; b = 2, 4, 5: W = 1 + 3 = 4, E[W] = 2 * 6 / 2 = 6, Var = 2 * 3 * 6 / 12 = 3.
    test = rank_sum_test([1, 3], [2, 4, 5])
    assert test.statistic == pytest.approx(-2.0 / math.sqrt(3.0), rel=1e-12)


def test_equals_scipy_ranksums_without_ties():
    rng = np.random.default_rng(7)
    a, b = rng.normal(0, 1, 23), rng.normal(0.6, 1.3, 31)
    ours = rank_sum_test(a, b)
    theirs = stats.ranksums(a, b)
    assert ours.statistic == pytest.approx(theirs.statistic, rel=1e-12)
    assert ours.p_value == pytest.approx(theirs.pvalue, rel=1e-10)


def test_equals_scipy_mannwhitneyu_with_ties():
    # Ratings on a coarse knob tie a lot; ranksums ignores ties, mannwhitneyu's
    # asymptotic test without continuity correction has our tie-corrected z.
    rng = np.random.default_rng(11)
    a, b = rng.integers(0, 5, 30), rng.integers(1, 6, 25)
    ours = rank_sum_test(a, b)
    theirs = stats.mannwhitneyu(a, b, method="asymptotic", use_continuity=False)
    assert ours.p_value == pytest.approx(theirs.pvalue, rel=1e-10)
    assert ours.rank_sum - 30 * 31 / 2 == pytest.approx(theirs.statistic)
    # Without the tie correction the variance is larger, so ranksums' |z| is smaller.
    assert abs(stats.ranksums(a, b).statistic) < abs(ours.statistic)


def test_all_values_equal_gives_no_evidence():
    test = rank_sum_test([1.0, 1.0, 1.0], [1.0, 1.0])
    assert (test.statistic, test.p_value) == (0.0, 1.0)


def test_empty_or_nan_samples_are_refused():
    with pytest.raises(InputDataError):
        rank_sum_test([], [1.0])
    with pytest.raises(InputDataError):
        rank_sum_test([np.nan, 1.0], [1.0])

def test_u_distribution_counts_every_placement():
    # 2 values among 2: orders aabb, abab, abba, baab, baba, bbaa have U = 0, 1, 2, 2, 3, 4.
    assert u_distribution(2, 2).tolist() == [1, 1, 2, 1, 1]
    for n1, n2 in ((1, 5), (3, 4), (8, 11)):
        counts = u_distribution(n1, n2)
        assert counts.sum() == math.comb(n1 + n2, n1)
        assert np.array_equal(counts, counts[::-1])  # U and n1 n2 - U are equally likely


@pytest.mark.parametrize("seed", range(5))
def test_exact_p_equals_the_count_of_orderings(seed):
    rng = np.random.default_rng(seed)
    n1, n2 = rng.integers(1, EXACT_MAX_SMALLER + 1), rng.integers(1, 15)
    a, b = rng.normal(0.0, 1.0, n1), rng.normal(0.5, 1.0, n2)
    test = rank_sum_test(a, b)
    assert test.exact and test.p_value == pytest.approx(exact_p(a, b), rel=1e-9)


def test_exact_p_for_separated_samples_by_hand():
    # 3 vs 3 fully separated: 2 of the C(6, 3) = 20 orderings are as extreme, p = 0.1,
    # where the normal approximation would give z = -1.96, p = 0.0495.
    test = rank_sum_test([1, 2, 3], [4, 5, 6])
    assert test.exact and test.p_value == pytest.approx(0.1, rel=1e-12)
    assert test.statistic == pytest.approx(-4.5 / math.sqrt(3 * 3 * 7 / 12), rel=1e-12)
    assert rank_sum_test([1, 2, 3, 4, 5], [6, 7, 8, 9, 10]).p_value == pytest.approx(2 / 252, rel=1e-12)


@pytest.mark.parametrize("n1, n2", [(2, 3), (4, 9), (8, 8), (8, 40), (9, 9), (12, 30)])
def test_p_equals_scipy_mannwhitneyu_auto_without_continuity(n1, n2):
    rng = np.random.default_rng(n1 * 100 + n2)
    a, b = rng.normal(0.0, 1.0, n1), rng.normal(0.7, 1.0, n2)
    ours = rank_sum_test(a, b)
    theirs = stats.mannwhitneyu(a, b, method="auto", use_continuity=False)
    assert ours.exact == (min(n1, n2) <= EXACT_MAX_SMALLER)
    assert ours.p_value == pytest.approx(theirs.pvalue, rel=1e-10)
    assert ours.statistic == pytest.approx(stats.ranksums(a, b).statistic, rel=1e-12)


def test_small_samples_with_ties_use_the_tie_corrected_normal_p():
    a, b = [1, 2, 2, 4], [2, 3, 5, 6]
    ours = rank_sum_test(a, b)
    assert not ours.exact
    assert ours.p_value == pytest.approx(stats.mannwhitneyu(a, b, method="asymptotic", use_continuity=False).pvalue,
                                         rel=1e-12)

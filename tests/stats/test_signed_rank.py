"""Wilcoxon signed-rank test and rank-biserial effect size: by hand, against scipy, ties and zero differences.

Zero differences are dropped (zero_method="wilcox"); the expected p-values are
computed here with scipy.stats.wilcoxon or by enumerating every sign
assignment, the effect sizes from the closed form r = (T+ - T-) / (T+ + T-).
"""

import itertools

import numpy as np
import pytest
from scipy import stats

from studyapp.stats.signed_rank import (
    ZERO_METHOD,
    exact_tied_p,
    minimum_p,
    participants_needed,
    signed_rank_test,
)
from studyapp.errors import InputDataError


def _enumerated_p(d):
    """Two-sided p over all 2^n sign assignments to the mid-ranks of the non-zero |d|."""
    d = np.asarray(d, dtype=float)
    d = d[d != 0]
    ranks = stats.rankdata(np.abs(d))
    centre = ranks.sum() / 2
    observed = abs(ranks[d > 0].sum() - centre)
    extreme = sum(
        abs(ranks[np.array(signs, dtype=bool)].sum() - centre) >= observed - 1e-9
        for signs in itertools.product([0, 1], repeat=d.size)
    )
    return extreme / 2**d.size


def test_zero_method_is_wilcox():
    assert ZERO_METHOD == "wilcox"


def test_without_ties_by_hand_and_against_scipy():
    # d = 1, 3, -2, 5, 4, 6: |d| ranks equal |d|. T+ = 1 + 3 + 5 + 4 + 6 = 19, T- = 2, r = 17/21.
    # T- <= 2 for {}, {1}, {2}: 3 of 64 sign assignments on each side, p = 6/64.
    b = np.array([10.0, 11.0, 12.0, 13.0, 14.0, 15.0])
    a = b + np.array([1, 3, -2, 5, 4, 6])
    test = signed_rank_test(a, b)
    assert (test.t_plus, test.t_minus, test.statistic, test.n_nonzero) == (19.0, 2.0, 2.0, 6)
    assert test.effect_size == pytest.approx(17 / 21, rel=1e-12)
    assert test.p_value == pytest.approx(6 / 64, rel=1e-12)
    reference = stats.wilcoxon(a, b, zero_method="wilcox")
    assert (test.statistic, test.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)
    # Swapping the conditions flips the sign of the effect, not the test.
    swapped = signed_rank_test(b, a)
    assert swapped.effect_size == pytest.approx(-17 / 21) and swapped.p_value == pytest.approx(test.p_value)


def test_ties_and_zero_differences_by_hand():
    # d = 0, 2, -2, 3, 3, 3, -1, 0, 4: the two zeros are dropped, n' = 7. Mid-ranks of |d|:
    # 1 -> 1; 2, 2 -> 2.5; 3, 3, 3 -> 5; 4 -> 7. T+ = 2.5 + 3 * 5 + 7 = 24.5, T- = 2.5 + 1 = 3.5.
    d = np.array([0, 2, -2, 3, 3, 3, -1, 0, 4], dtype=float)
    b = np.full(d.size, 5.0)
    test = signed_rank_test(b + d, b)
    assert (test.t_plus, test.t_minus, test.n_nonzero) == (24.5, 3.5, 7)
    assert test.statistic == 3.5
    assert test.effect_size == pytest.approx((24.5 - 3.5) / 28, rel=1e-12)
    assert test.p_value == pytest.approx(_enumerated_p(d), rel=1e-12)
    # scipy's enumeration of every sign assignment agrees, with zeros dropped (wilcox) ...
    permutation = stats.PermutationMethod(n_resamples=2**d.size)  # every assignment: enumerated, not sampled
    assert test.p_value == pytest.approx(stats.wilcoxon(d, zero_method="wilcox", method=permutation).pvalue, rel=1e-12)
    # ... and the other conventions for zeros give other p-values.
    assert test.p_value != pytest.approx(stats.wilcoxon(d, zero_method="pratt", method="asymptotic").pvalue)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_tied_p_equals_scipy_enumeration(seed):
    d = np.random.default_rng(seed).integers(-3, 6, 9).astype(float)
    test = signed_rank_test(d, np.zeros(d.size))
    nonzero = d[d != 0]
    expected = stats.wilcoxon(nonzero, method=stats.PermutationMethod(n_resamples=2**nonzero.size)).pvalue
    assert test.p_value == pytest.approx(expected, rel=1e-12)


def test_exact_tied_p_without_ties_is_scipy_exact():
    ranks = np.arange(1.0, 13.0)
    for t_plus in (0.0, 10.0, 25.0, 39.0, 78.0):
        d = np.where(np.isin(ranks, _subset_with_sum(ranks, t_plus)), ranks, -ranks)
        assert exact_tied_p(ranks, t_plus) == pytest.approx(stats.wilcoxon(d, method="exact").pvalue, rel=1e-12)


def _subset_with_sum(ranks, total):
    chosen, rest = [], total
    for r in sorted(ranks, reverse=True):
        if r <= rest:
            chosen.append(r)
            rest -= r
    assert rest == 0
    return chosen


def test_large_samples_use_the_normal_approximation():
    rng = np.random.default_rng(4)
    a, b = rng.normal(0.3, 1, 60), rng.normal(0, 1, 60)
    expected = stats.wilcoxon(a, b, zero_method="wilcox", method="asymptotic")
    test = signed_rank_test(a, b)
    assert (test.statistic, test.p_value) == pytest.approx((expected.statistic, expected.pvalue), rel=1e-10)


def test_float_noise_is_neither_a_tie_breaker_nor_a_difference():
    a, b = [0.3, 0.5, 0.9, 0.7], [0.1 + 0.2, 0.2, 0.4, 0.4]
    d = np.subtract(a, b)
    assert d[0] != 0.0 and d[1] != d[3]  # the noise is there
    # Rounded: d = 0, 0.3, 0.5, 0.3 -> n' = 3, mid-ranks 1.5, 3, 1.5, T+ = 6; T+ is 0 or 6 in 2 of 8.
    test = signed_rank_test(a, b)
    assert (test.n_nonzero, test.t_plus, test.t_minus) == (3, 6.0, 0.0)
    assert test.p_value == pytest.approx(_enumerated_p([0.3, 0.5, 0.3])) == 0.25


def test_every_difference_zero_is_no_evidence():
    test = signed_rank_test([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    assert (test.statistic, test.p_value, test.effect_size, test.n_nonzero) == (0.0, 1.0, 0.0, 0)


def test_bad_samples_are_refused():
    with pytest.raises(InputDataError):
        signed_rank_test([1.0, 2.0], [1.0])
    with pytest.raises(InputDataError):
        signed_rank_test([np.nan], [1.0])


@pytest.mark.parametrize("n, p", [(1, 1.0), (2, 0.5), (5, 0.0625), (6, 0.03125), (9, 2 / 512)])
def test_smallest_attainable_p_is_reached_when_every_participant_agrees(n, p):
    assert minimum_p(n) == p
    test = signed_rank_test(np.arange(1.0, n + 1) + 100.0, np.full(n, 100.0))
    assert test.p_value == pytest.approx(p, rel=1e-12) and test.effect_size == 1.0


@pytest.mark.parametrize("alpha, pairs", [(0.05, 1), (0.05, 3), (0.05, 28), (0.05, 36), (0.01, 1), (0.0625, 1)])
def test_participants_needed_by_counting(alpha, pairs):
    n = 1
    while pairs * 2.0 ** (1 - n) >= alpha:
        n += 1
    assert participants_needed(alpha, pairs) == n
    assert participants_needed(0.05) == 6 and participants_needed(0.05, 36) == 11

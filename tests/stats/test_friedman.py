"""Friedman's test: by hand (with and without ties), against scipy, and its smallest attainable p by enumeration."""

import itertools
import math

import numpy as np
import pytest
from scipy import stats

from studyapp.stats.friedman import friedman_test, minimum_p


def test_without_ties_by_hand():
    # Ranks per participant (rows) of A, B, C: 1 2 3 / 1 3 2 / 1 2 3 / 3 2 1 -> R = 6, 9, 9.
    # chi2 = 12 / (4 * 3 * 4) * (36 + 81 + 81) - 3 * 4 * 4 = 1.5; with 2 df, p = exp(-chi2 / 2).
    table = [[10, 20, 30], [10, 30, 20], [5, 6, 7], [3, 2, 1]]
    test = friedman_test(table)
    assert (test.n_participants, test.n_conditions) == (4, 3)
    assert test.statistic == pytest.approx(1.5, rel=1e-12)
    assert test.p_value == pytest.approx(math.exp(-0.75), rel=1e-12)


def test_with_ties_by_hand_and_against_scipy():
    # Ranks: 1.5 1.5 3 / 1 2 3 / 2 2 2 / 2 1 3 -> R = 6.5, 6.5, 11, sum R^2 = 205.5.
    # Uncorrected 12 / 48 * 205.5 - 48 = 3.375; ties: (2^3 - 2) + (3^3 - 3) = 30,
    # C = 1 - 30 / (4 * (27 - 3)) = 0.6875 -> chi2 = 3.375 / 0.6875.
    table = np.array([[10, 10, 30], [1, 2, 3], [4, 4, 4], [2, 1, 3]], dtype=float)
    test = friedman_test(table)
    chi2 = 3.375 / 0.6875
    assert test.statistic == pytest.approx(chi2, rel=1e-12)
    assert test.p_value == pytest.approx(math.exp(-chi2 / 2), rel=1e-12)
    reference = stats.friedmanchisquare(*table.T)
    assert (test.statistic, test.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)


def test_random_table_equals_scipy():
    table = np.random.default_rng(8).normal(size=(9, 8)) + np.arange(8) * 0.3
    reference = stats.friedmanchisquare(*table.T)
    test = friedman_test(table)
    assert (test.statistic, test.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)


def test_not_computed_with_too_few_conditions_or_participants():
    for table in (np.ones((5, 2)), np.ones((1, 4)), np.zeros((0, 0))):
        test = friedman_test(table)
        assert math.isnan(test.statistic) and math.isnan(test.p_value)
    assert friedman_test(np.arange(10.0).reshape(5, 2)).n_participants == 5


def test_identical_conditions_are_no_evidence():
    test = friedman_test([[1, 1, 1], [2, 2, 2]])
    assert (test.statistic, test.p_value) == (0.0, 1.0)


@pytest.mark.parametrize("k, n", [(3, 2), (3, 3), (4, 2)])
def test_smallest_exact_p_by_enumeration(k, n):
    # Every assignment of rankings to the n participants is equally likely; the most extreme
    # chi2 (everyone agrees) has probability k! / (k!)^n.
    rankings = list(itertools.permutations(range(1, k + 1)))
    chi2 = [
        12.0 / (n * k * (k + 1)) * np.sum(np.sum(block, axis=0) ** 2) - 3 * n * (k + 1)
        for block in itertools.product(rankings, repeat=n)
    ]
    largest = max(chi2)
    share = sum(c >= largest - 1e-9 for c in chi2) / len(chi2)
    assert minimum_p(n, k) == pytest.approx(share, rel=1e-12)

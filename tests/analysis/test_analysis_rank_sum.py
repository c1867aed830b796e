"""Wilcoxon rank-sum: hand-computed examples, scipy on the same data, Holm, every pair once."""

import math
from itertools import combinations

import numpy as np
import pytest
from scipy import stats

from studyapp.analysis.holm import holm_adjust
from studyapp.analysis.rank_sum import WILCOXON_COLUMNS, pairwise_rank_sum, rank_sum_test
from studyapp.analysis.ranks import average_ranks, tie_sizes
from studyapp.errors import InputDataError


def test_average_ranks_with_ties_by_hand():
    # Sorted: 1, 2, 2, 2, 3, 4, 5 -> the three 2s share ranks 2, 3, 4, i.e. 3.
    assert average_ranks([2, 5, 1, 2, 4, 2, 3]).tolist() == [3, 7, 1, 3, 6, 3, 5]
    assert sorted(tie_sizes([2, 5, 1, 2, 4, 2, 3]).tolist()) == [1, 1, 1, 1, 3]


def test_average_ranks_equal_scipy_rankdata():
    x = np.random.default_rng(3).integers(0, 6, 40)
    assert np.array_equal(average_ranks(x), stats.rankdata(x, method="average"))


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


def test_every_pair_of_conditions_present_once():
    rng = np.random.default_rng(5)
    groups = {name: rng.normal(k, 1.0, 8) for k, name in enumerate(["A", "B", "C", "D", "E"])}
    table = pairwise_rank_sum(groups)
    assert list(table.columns[:5]) == WILCOXON_COLUMNS
    pairs = [frozenset(p) for p in zip(table["condition_a"], table["condition_b"])]
    assert len(pairs) == len(set(pairs)) == 10
    assert set(pairs) == {frozenset(p) for p in combinations(groups, 2)}
    for row in table.itertuples():
        expected = stats.mannwhitneyu(groups[row.condition_a], groups[row.condition_b], method="asymptotic",
                                      use_continuity=False)
        assert row.p_value == pytest.approx(expected.pvalue, rel=1e-10)
        assert row.significant == (row.p_value < 0.05)


def test_holm_by_hand():
    # Sorted 0.005, 0.01, 0.03, 0.04 -> 4x, 3x, 2x, 1x = 0.02, 0.03, 0.06, 0.04 -> running max.
    assert holm_adjust([0.01, 0.04, 0.03, 0.005]) == pytest.approx([0.03, 0.06, 0.06, 0.02])
    # 2 x 0.5 = 1.0 (capped); then max(1.0, 1 x 0.9): adjusted p never falls below an earlier one.
    assert holm_adjust([0.5, 0.9]) == pytest.approx([1.0, 1.0])


def test_holm_option_adjusts_p_value_and_significance():
    rng = np.random.default_rng(2)
    groups = {name: rng.normal(0.35 * k, 1.0, 12) for k, name in enumerate("ABCD")}
    raw = pairwise_rank_sum(groups)
    holm = pairwise_rank_sum(groups, holm=True)
    assert np.allclose(holm["p_raw"], raw["p_value"])
    assert np.allclose(holm["p_value"], holm_adjust(raw["p_value"]))
    assert (holm["p_value"] >= raw["p_value"]).all()
    assert list(holm["significant"]) == list(holm["p_value"] < 0.05)

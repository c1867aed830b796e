"""The paper's pairwise rank-sum table: every pair once, p from the shared test (scipy's reference), Holm."""

from itertools import combinations

import numpy as np
import pytest
from scipy import stats

from studyapp.stats.holm import holm_adjust
from studyapp.analysis.rank_sum import WILCOXON_COLUMNS, pairwise_rank_sum


def test_every_pair_of_conditions_present_once():
    rng = np.random.default_rng(5)
    groups = {name: rng.normal(k, 1.0, 8) for k, name in enumerate(["A", "B", "C", "D", "E"])}
    table = pairwise_rank_sum(groups)
    assert list(table.columns[:5]) == WILCOXON_COLUMNS
    pairs = [frozenset(p) for p in zip(table["condition_a"], table["condition_b"])]
    assert len(pairs) == len(set(pairs)) == 10
    assert set(pairs) == {frozenset(p) for p in combinations(groups, 2)}
    for row in table.itertuples():
        expected = stats.mannwhitneyu(groups[row.condition_a], groups[row.condition_b], method="auto",
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

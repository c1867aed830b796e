"""Within-subject analysis: per-participant medians, Friedman, Holm-corrected signed-rank tests, small-n warnings."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from studyapp.analysis.within_subject import SIGNED_RANK_COLUMNS, participant_medians, within_subject


def _values(rows):
    return pd.DataFrame(rows, columns=["participant", "condition", "value"])


def _study(n, conditions="ABC", seed=0):
    """One value per participant and condition: condition k is about k higher, no ties."""
    rng = np.random.default_rng(seed)
    return _values([(f"P{p}", c, k + rng.normal(0, 2.0)) for p in range(n) for k, c in enumerate(conditions)])


def test_participant_medians_and_incomplete_participants():
    values = _values([
        ("P1", "A", 1.0), ("P1", "A", 3.0), ("P1", "A", 8.0), ("P1", "B", 2.0),
        ("P2", "A", 4.0), ("P2", "B", 6.0), ("P2", "B", 7.0),
        ("P3", "A", 5.0),  # no B: left out
    ])
    medians, excluded = participant_medians(values, ["B", "A"])
    assert list(medians.columns) == ["B", "A"] and list(medians.index) == ["P1", "P2"]
    assert medians.loc["P1"].tolist() == [2.0, 3.0] and medians.loc["P2"].tolist() == [6.5, 4.0]
    assert excluded == {"P3": ["B"]}
    analysis = within_subject(values, ["B", "A"])
    assert analysis.n_participants == 2
    assert "P3 is left out of the within-subject tests (no response for B)" in analysis.warnings(0.05)


def test_tests_against_scipy_and_holm_by_hand():
    values = _study(8, "ABC", seed=3)
    wide = values.pivot(index="participant", columns="condition", values="value")
    analysis = within_subject(values, ["C", "B", "A"])
    table = analysis.signed_rank
    assert list(table.columns) == SIGNED_RANK_COLUMNS
    assert [tuple(p) for p in table[["condition_a", "condition_b"]].values] == [("C", "B"), ("C", "A"), ("B", "A")]
    raw = []
    for row in table.itertuples():
        a, b = wide[row.condition_a].to_numpy(), wide[row.condition_b].to_numpy()
        reference = stats.wilcoxon(a, b, zero_method="wilcox", method="exact")
        assert (row.statistic, row.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)
        d = a - b
        ranks = stats.rankdata(np.abs(d))
        assert row.effect_size == pytest.approx((ranks[d > 0].sum() - ranks[d < 0].sum()) / ranks.sum(), rel=1e-12)
        raw.append(reference.pvalue)
    # Holm by hand: ascending p(1) <= p(2) <= p(3) -> 3 p(1), max(., 2 p(2)), max(., p(3)), capped at 1.
    order = np.argsort(raw)
    p1, p2, p3 = np.asarray(raw)[order]
    steps = [min(1, 3 * p1), min(1, max(3 * p1, 2 * p2)), min(1, max(3 * p1, 2 * p2, p3))]
    expected = np.empty(3)
    expected[order] = steps
    assert table["p_holm"].to_numpy() == pytest.approx(expected, rel=1e-12)
    assert table["significant"].tolist() == (expected < 0.05).tolist()
    friedman = stats.friedmanchisquare(*(wide[c].to_numpy() for c in "CBA"))
    assert (analysis.friedman.statistic, analysis.friedman.p_value) == pytest.approx(
        (friedman.statistic, friedman.pvalue), rel=1e-12)
    assert analysis.friedman.n_participants == 8


def test_effect_size_is_positive_when_condition_a_is_larger():
    values = _values([(f"P{p}", c, v + p) for p in range(6) for c, v in (("HIGH", 10.0), ("LOW", 1.0))])
    row = within_subject(values, ["HIGH", "LOW"]).signed_rank.iloc[0]
    assert row.effect_size == 1.0 and row.p_value == pytest.approx(2 / 2**6)
    row = within_subject(values, ["LOW", "HIGH"]).signed_rank.iloc[0]
    assert row.effect_size == -1.0


def _warnings(n, conditions="ABC"):
    return " | ".join(within_subject(_study(n, conditions), list(conditions)).warnings(0.05))


def test_warnings_say_what_the_number_of_participants_allows():
    two = _warnings(2)
    assert "Friedman's test with 2 participants" in two and "unreliable below 6" in two
    assert "(smallest p (k!)^(1-n) = 0.167)" in two  # 3! ^ -1: an exact test could not reach 0.05 either
    # the test used is Holm over the 3 pairs, so the count needed is 7 (3 x 2^-6 < 0.05), not 6 (issue 22 item 14)
    assert ("no pair can be significant with 2 participants: the smallest exact two-sided signed-rank p is "
            "2^(1-n) = 0.5, and Holm's correction over the 3 pairs multiplies it by 3: 1.5, not below 0.05; "
            "7 participants are needed") in two
    five = _warnings(5)
    assert "2^(1-n) = 0.0625" in five and "Friedman's test with 5" in five and "(k!)^(1-n)" not in five
    assert "7 participants are needed" in five
    six = _warnings(6)  # 3 pairs: 3 x 2^-5 = 0.094 after Holm
    assert "Friedman" not in six
    assert "no pair can be significant with 6 participants" in six and "multiplies it by 3: 0.0938, not below 0.05" in six
    assert "7 participants are needed" in six
    assert _warnings(7) == ""
    two_conditions = _warnings(5, "AB")  # one pair: no Holm, the plain signed-rank bound (6)
    assert "Friedman's test needs 3 or more conditions (here 2)" in two_conditions
    assert "a signed-rank test on 5 participants cannot reach p < 0.05" in two_conditions
    assert "6 participants are needed" in two_conditions
    assert "Friedman's test needs 3 or more conditions (here 2)" in _warnings(7, "AB")


def test_no_responses_give_empty_tables():
    analysis = within_subject(_values([]), [])
    assert analysis.signed_rank.empty and list(analysis.signed_rank.columns) == SIGNED_RANK_COLUMNS
    assert np.isnan(analysis.friedman.statistic) and analysis.warnings(0.05) == []

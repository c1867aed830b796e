"""The pilot's figures (studyapp.analysis.pilot) against scipy and closed forms (issue 30, item 6)."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from studyapp.analysis.pilot import PAPER_FIG7_RANK, pilot_figures, rho_against_paper, variance_components, within_lower_pct


def test_rho_is_scipys_against_minus_the_papers_rank():
    rng = np.random.default_rng(3)
    for _ in range(20):
        medians = {c: float(v) for c, v in zip(PAPER_FIG7_RANK, rng.lognormal(1.0, 0.4, len(PAPER_FIG7_RANK)))}
        expected = stats.spearmanr([medians[c] for c in PAPER_FIG7_RANK], [-r for r in PAPER_FIG7_RANK.values()]).statistic
        assert rho_against_paper(medians) == pytest.approx(expected, abs=1e-12)


def test_the_papers_own_order_gives_rho_one_and_its_reverse_minus_one():
    assert rho_against_paper({c: 10.0 - r for c, r in PAPER_FIG7_RANK.items()}) == pytest.approx(1.0)
    assert rho_against_paper({c: r for c, r in PAPER_FIG7_RANK.items()}) == pytest.approx(-1.0)


@pytest.mark.parametrize("seed", range(5))
def test_balanced_components_give_scipys_f_and_the_icc_closed_form(seed):
    rng = np.random.default_rng(seed)
    k, n = 6, 6
    groups = [rng.normal(rng.normal(0.0, 0.1), 0.05, n) for _ in range(k)]
    within, between = variance_components(groups)
    f = stats.f_oneway(*groups).statistic  # MS_b / MS_w
    assert (between * n + within) / within == pytest.approx(f, rel=1e-10) if between > 0 else f <= 1.0
    icc = max(0.0, (f - 1.0) / (f - 1.0 + n))  # ICC(1) from F, balanced
    assert within_lower_pct(groups) == pytest.approx(100.0 * icc, rel=1e-10, abs=1e-10)


def test_unbalanced_components_are_the_anova_estimators():
    groups = [np.array([1.0, 2.0, 3.0]), np.array([4.0, 6.0]), np.array([2.0, 2.5, 3.0, 3.5])]
    y = np.concatenate(groups)
    ms_w = (2.0 + 2.0 + 1.25) / (9 - 3)
    ms_b = (3 * (2.0 - y.mean()) ** 2 + 2 * (5.0 - y.mean()) ** 2 + 4 * (2.75 - y.mean()) ** 2) / 2
    n0 = (9 - (9 + 4 + 16) / 9) / 2
    assert variance_components(groups) == pytest.approx((ms_w, (ms_b - ms_w) / n0), rel=1e-12)


def test_no_spread_between_participants_is_zero_and_no_spread_at_all_undefined():
    assert within_lower_pct([[1.0, 2.0], [1.0, 2.0]]) == 0.0
    assert np.isnan(within_lower_pct([[1.0, 1.0], [1.0, 1.0]]))
    assert within_lower_pct([[1.0, 1.0], [2.0, 2.0]]) == 100.0


def test_pilot_figures_pool_the_trials_and_decompose_log_fmax():
    rows = [("P1", "LVT", v) for v in (6.0, 7.0)] + [("P2", "LVT", v) for v in (8.0, 9.0)] \
        + [("P1", "FOAW", v) for v in (2.0, 2.0)] + [("P2", "FOAW", v) for v in (3.0, 3.0)] \
        + [(p, c, 3.0) for p in ("P1", "P2") for c in ("LEVANT",)]
    figures = pilot_figures(pd.DataFrame(rows, columns=["participant", "condition", "fmax"]))
    assert figures["medians"] == {"LVT": 7.5, "LEVANT": 3.0, "FOAW": 2.5}
    assert list(figures["medians"]) == ["LVT", "LEVANT", "FOAW"]
    assert figures["rho"] == pytest.approx(stats.spearmanr([7.5, 3.0, 2.5], [-1, -2, -9]).statistic)
    assert figures["within_lower_pct"]["FOAW"] == 100.0 and np.isnan(figures["within_lower_pct"]["LEVANT"])
    logs = [np.log10([6.0, 7.0]), np.log10([8.0, 9.0])]
    assert figures["within_lower_pct"]["LVT"] == pytest.approx(within_lower_pct(logs))
    assert figures["mean_within_lower_pct"] == pytest.approx((100.0 + within_lower_pct(logs)) / 2)

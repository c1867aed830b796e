"""Per-participant Spearman, intra/inter-subject variance, and the numerical comparison, by hand."""

import json
import math
import re

import pandas as pd
import pytest

from studyapp.analysis.consistency import participant_spearman, variance_decomposition
from studyapp.analysis.numerical import compare_with_numerical, load_evaluation
from studyapp.errors import InputDataError


def _values(rows):
    return pd.DataFrame(rows, columns=["participant", "condition", "value"])


def test_participant_rho_against_global_ranking_by_hand():
    # Global medians: A 4, B 2, C 2.5 (A > C > B). P1 ranks A > B > C: d = 0, 1, -1,
    # rho = 1 - 6 * 2 / (3 * 8) = 0.5; P2 ranks A > C > B: rho = 1.
    values = _values([
        ("P1", "A", 3), ("P1", "B", 2.5), ("P1", "C", 1),
        ("P2", "A", 5), ("P2", "B", 1.5), ("P2", "C", 4),
    ])
    table = participant_spearman(values).set_index("participant")
    assert table.loc["P1", "rho"] == pytest.approx(0.5)
    assert table.loc["P2", "rho"] == pytest.approx(1.0)
    assert table.loc["P1", "conditions"] == 3


def test_variance_decomposition_by_hand():
    # P1: 1, 3 (variance 2); P2: 5, 5, 8 (variance 3) -> intra 2.5. Means 2 and 6 -> inter 8.
    # All five: mean 4.4, sum of squares 27.2 -> total 6.8; intra lower by 1 - 2.5 / 6.8.
    values = _values([("P1", "A", 1), ("P1", "A", 3), ("P2", "A", 5), ("P2", "A", 5), ("P2", "A", 8)])
    row = variance_decomposition(values, ["A"]).iloc[0]
    assert (row.intra_variance, row.inter_variance, row.total_variance) == pytest.approx((2.5, 8.0, 6.8))
    assert row.intra_lower_pct == pytest.approx(100 * (1 - 2.5 / 6.8))


def test_variance_needs_repeated_trials():
    row = variance_decomposition(_values([("P1", "A", 1), ("P2", "A", 2)]), ["A"]).iloc[0]
    assert math.isnan(row.intra_variance) and math.isnan(row.intra_lower_pct)


def _evaluation(tmp_path, estimators):
    path = tmp_path / "evaluation.json"
    path.write_text(json.dumps({"estimators": estimators, "ranking": list(estimators)}))
    return tmp_path


def test_numerical_comparison_by_hand(tmp_path):
    estimators = {
        # studyapp evaluate writes null where a percent is undefined (LOWPASS delay 0): skipped.
        "LOWPASS": {"error": [1, 2], "delay": [9, 9], "error_pct_lowpass": [100, 100], "delay_pct_lowpass": [100, None]},
        "KALLEV": {"error": [1, 1], "delay": [5, 5], "error_pct_lowpass": [60, 80], "delay_pct_lowpass": [50, 60]},
        "LEVANT": {"error": [9, 9], "delay": [1, 1], "error_pct_lowpass": [500, 600], "delay_pct_lowpass": [10, 12]},
        "FOAW": {"error": [3, 3], "delay": [20, 20], "error_pct_lowpass": [90, 95], "delay_pct_lowpass": [150, 170]},
        "KALPOS": {"error": [1, 1], "delay": [1, 1], "error_pct_lowpass": [70, 70], "delay_pct_lowpass": [80, 80]},
    }
    evaluation = load_evaluation(_evaluation(tmp_path, estimators))
    noisiness = pd.Series({"LVT": 0.0, "KALLEV": 0.2, "LOWPASS": 0.4, "FOAW": 0.6, "LEVANT": 1.0})
    fmax = pd.Series({"LVT": 20.0, "LEVANT": 11.0, "LOWPASS": 10.0, "KALLEV": 9.0, "FOAW": 5.0})
    table = compare_with_numerical(evaluation, noisiness, fmax).set_index("comparison")
    # Noisiness (KALLEV, LOWPASS, FOAW, LEVANT) = ranks 1..4; median error % = 70, 100, 92.5, 550
    # -> ranks 1, 3, 2, 4: d^2 sum = 2 -> rho = 1 - 12 / 60 = 0.8. LVT is not evaluated.
    noise = table.loc["noisiness vs error"]
    assert (noise.n, noise.metric, noise.rho) == (4, "error_pct_lowpass", pytest.approx(0.8))
    # F_max best first LEVANT, LOWPASS, KALLEV, FOAW; delay % 11, 100, 55, 160 -> ranks 1, 3, 2, 4 -> 0.8.
    assert table.loc["max F_max vs delay", "rho"] == pytest.approx(0.8)


def test_numerical_delay_ranks_by_magnitude(tmp_path):
    """A lead of the LVT (D < 0) is as far from it as a lag: KALMAN 1 sample ahead ranks with a 1-sample lag."""
    from studyapp.analysis.numerical import numerical_scores

    estimators = {
        "LOWPASS": {"error": [1], "delay": [3], "error_pct_lowpass": [100], "delay_pct_lowpass": [100]},
        "KALMAN": {"error": [1], "delay": [-2], "error_pct_lowpass": [30], "delay_pct_lowpass": [-66.7]},
        "LEASTSQ": {"error": [1], "delay": [0], "error_pct_lowpass": [90], "delay_pct_lowpass": [0]},
        "KALPOS": {"error": [1], "delay": [1], "error_pct_lowpass": [70], "delay_pct_lowpass": [33.3]},
    }
    scores, metric = numerical_scores(load_evaluation(_evaluation(tmp_path, estimators)), "delay")
    assert metric == "delay_pct_lowpass"
    assert list(scores.sort_values().index) == ["LEASTSQ", "KALPOS", "KALMAN", "LOWPASS"]
    assert scores["KALMAN"] == pytest.approx(66.7)


def test_numerical_comparison_falls_back_to_raw_lists(tmp_path):
    estimators = {n: {"error": [e], "delay": [d]} for n, e, d in [("A", 1, 3), ("B", 2, 2), ("C", 3, 1)]}
    evaluation = load_evaluation(_evaluation(tmp_path, estimators) / "evaluation.json")
    table = compare_with_numerical(evaluation, pd.Series({"A": 0.1, "B": 0.5, "C": 0.9}),
                                   pd.Series({"A": 1.0, "B": 2.0, "C": 3.0})).set_index("comparison")
    assert table.loc["noisiness vs error", "metric"] == "error"
    assert table.loc["noisiness vs error", "rho"] == pytest.approx(1.0)
    assert table.loc["max F_max vs delay", "rho"] == pytest.approx(1.0)


@pytest.mark.parametrize("content, field", [
    ("{not json", "not valid JSON"),
    ('{"ranking": []}', "'estimators'"),
    ('{"estimators": {"A": {"error": [1]}}}', "estimators.A.delay"),
    ('{"estimators": {"A": {"error": ["x"], "delay": [1]}}}', "estimators.A.error"),
])
def test_bad_evaluation_names_the_field(tmp_path, content, field):
    (tmp_path / "evaluation.json").write_text(content)
    with pytest.raises(InputDataError, match=field) as info:
        load_evaluation(tmp_path)
    assert "evaluation.json" in str(info.value) and "\n" not in str(info.value)


def test_missing_evaluation_names_the_file(tmp_path):
    with pytest.raises(InputDataError, match="evaluation.json"):
        load_evaluation(tmp_path)


@pytest.mark.parametrize("lower, text", [
    (61.4, "<b>61%</b> lower than"),
    (-2.0, "<b>2%</b> higher than"),
    (-50.0, "<b>50%</b> higher than"),
    (0.3, "<b>about equal to</b> the total"),
    (-0.4, "<b>about equal to</b> the total"),
    (math.nan, "cannot be computed"),
])
def test_intra_variance_headline_says_lower_or_higher(lower, text):
    from studyapp.analysis.report import intra_variance_headline

    headline = intra_variance_headline(lower)
    assert text in headline and not re.search(r"[-\u2212]\s*\d", headline)


def test_report_says_higher_when_intra_subject_variance_exceeds_the_total():
    # Each participant gives 1 then 3 in both conditions: intra = 2, total = var(1, 3, 1, 3) = 4/3,
    # so intra is 50% higher than total; the report used to print "-50% lower".
    from studyapp.analysis.report import report_html
    from studyapp.analysis.responses import check_responses
    from studyapp.analysis.study import analyse

    rows = [(p, "adjustment", c, t, v, None) for p in ("P1", "P2") for c in ("A", "B") for t, v in ((1, 1.0), (2, 3.0))]
    frame = pd.DataFrame(rows, columns=["participant", "task", "condition", "trial", "fmax", "rating"])
    study = analyse(check_responses(frame, "two.csv"))
    assert study.intra_lower_pct() == pytest.approx(-50.0)
    html = report_html(study, {})
    assert "Intra-subject variance is on average <b>50%</b> higher than the total variance" in html
    assert not re.search(r"[-\u2212]\s*\d+%", html)
    assert "intra lower by (%; &lt; 0: higher)" in html

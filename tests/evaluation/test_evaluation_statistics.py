"""Wilcoxon rank-sum tests, the Pareto front and the Fig. 5 report, against hand values and scipy."""

import numpy as np
import pytest
from scipy import stats

from studyapp.evaluation.dataset import Dataset, Take
from studyapp.evaluation.metric import delay_and_error
from studyapp.evaluation.pareto import pareto_front
from studyapp.evaluation.report import evaluate, in_group
from studyapp.evaluation.significance import not_different_from_best, pairwise, rank_sum
from tests.evaluation.conftest import stick_slip


def test_rank_sum_of_recordings_drops_non_finite_values():
    # The finite values 1, 2, 3 against 4, 5, 6: exact p = 2 / C(6, 3), z = -4.5 / sqrt(21 / 4).
    z, p = rank_sum([1, np.nan, 2, 3], [4, 5, np.inf, 6])
    assert p == pytest.approx(0.1, rel=1e-12)
    assert z == pytest.approx(stats.ranksums([1, 2, 3], [4, 5, 6]).statistic, rel=1e-12)
    z, p = rank_sum([1.0, np.nan], [2.0, 3.0])
    assert np.isnan(z) and p == 1.0
    assert rank_sum([2.0, 2.0, 2.0], [2.0, 2.0]) == (0.0, 1.0)


def test_rank_sum_with_ties_is_the_tie_corrected_normal_approximation():
    rng = np.random.default_rng(0)
    a, b = rng.integers(0, 5, 30), rng.integers(1, 6, 30)
    _, p = rank_sum(a, b)
    assert p == pytest.approx(stats.mannwhitneyu(a, b, method="asymptotic", use_continuity=False).pvalue, rel=1e-10)
    assert p < stats.ranksums(a, b).pvalue  # ranksums has no tie correction: larger variance, larger p


def test_pairwise_and_best_group():
    samples = {"A": np.array([1.0, 1.1, 0.9, 1.2, 1.0, 0.95]), "B": np.array([1.05, 1.0, 1.15, 0.9, 1.1, 1.0]),
               "C": np.array([3.0, 3.2, 2.9, 3.1, 3.3, 3.05])}
    rows = {(r["a"], r["b"]): r for r in pairwise(samples)}
    assert not rows[("A", "B")]["significant"]
    assert rows[("A", "C")]["significant"] and rows[("B", "C")]["significant"]
    assert not_different_from_best(samples) == {"A", "B"}


def test_pareto_front():
    points = [[1, 5], [2, 3], [3, 3], [4, 1], [5, 2], [np.inf, 0]]
    assert pareto_front(points).tolist() == [True, True, False, True, False, False]


def test_groups_of_fig_5():
    assert in_group(0.0, "a") and in_group(7.7, "a") and not in_group(9.9, "a")
    assert in_group(2.2, "b") and in_group(12.1, "b") and not in_group(1.9, "b")
    assert in_group(None, "a") and not in_group(None, "b")


def test_report_matches_the_metric_and_lowpass_is_100_percent():
    takes = []
    for i, fmax in enumerate((0.5, 2.2, 9.9)):
        sig = stick_slip(5000.0, 0.6, ripple=0.01 + 0.004 * fmax, seed=i)
        takes.append(Take(f"r{i}", 5000.0, sig["position"], sig["acceleration"], sig["velocity_lvt"],
                          sig["velocity_lvt"], fmax=fmax))
    params = {"LOWPASS": {"cutoff_hz": 256.0}, "BDIFF": {"steps": 4}, "LEASTSQ": {"order": 2, "window": 33}}
    result = evaluate(Dataset(takes, 0.02), params)
    from studyapp.estimators import create

    for r, take in enumerate(takes):
        est = create("BDIFF", 5000.0, steps=4).process(take.position)
        d, e = delay_and_error(take.reference, est, 100)
        assert result.delays["BDIFF"][r] == d and result.errors["BDIFF"][r] == pytest.approx(e)
    assert np.allclose(result.error_pct("LOWPASS"), 100.0)
    assert np.allclose(result.delay_pct("LOWPASS"), 100.0)
    assert np.allclose(result.error_pct("BDIFF"), 100 * result.errors["BDIFF"] / result.errors["LOWPASS"])
    # Eqs. 29-32: each recording's E and |D| are scaled to [0, 1] across the three estimators (min -> 0,
    # max -> 1; all equal -> 0); F_g (eq. 27) is their sum over the recordings.
    def scaled(m):
        spread = m.max(axis=0) - m.min(axis=0)
        return np.where(spread > 0, (m - m.min(axis=0)) / np.where(spread > 0, spread, 1.0), 0.0)

    errors = np.array([result.errors[n] for n in params])
    delays = np.abs(np.array([result.delays[n] for n in params], dtype=float))
    expected = (scaled(errors) + scaled(delays)).sum(axis=1)
    assert [result.objective[n] for n in params] == pytest.approx(expected, rel=1e-12)
    assert result.ranking == sorted(params, key=result.objective.get)
    doc = result.to_json()
    assert set(doc) >= {"estimators", "ranking"}
    assert set(doc["estimators"]["BDIFF"]) == {"error", "delay", "error_pct_lowpass", "delay_pct_lowpass",
                                               "delay_subsample", "delay_subsample_pct_lowpass", "objective"}
    assert result.group_mask("b").tolist() == [False, True, True]


def test_validation_comparison_by_hand():
    from studyapp.evaluation.report import Evaluation
    from studyapp.evaluation.validation import compare

    def ev(errors, delays, fmax):
        return Evaluation(names=["A", "B"], recordings=[f"r{f}" for f in fmax], fmax=list(fmax),
                          rates=[5000.0] * len(fmax), params={"A": {}, "B": {}},
                          errors={k: np.array(v, float) for k, v in errors.items()},
                          delays={k: np.array(v, float) for k, v in delays.items()},
                          baseline_errors=np.ones(len(fmax)), baseline_delays=np.ones(len(fmax)))

    train = ev({"A": [1.0, 2.0], "B": [4.0, 5.0]}, {"A": [2, 3], "B": [5, 5]}, (0.5, 2.2))
    # Validation in another order, with one extra gain that has no match.
    valid = ev({"A": [2.2, 1.1, 9.0], "B": [4.0, 4.0, 9.0]}, {"A": [3, 4, 9], "B": [7, 5, 9]}, (2.2, 0.5, 9.9))
    summary, rows = compare(train, valid)
    assert summary["matched_recordings"] == 2
    # Error differences: A 10 %, 10 %; B 0 %, 20 %. Delay differences: A 2, 0; B 0, 2.
    e = np.array([10.0, 10.0, 0.0, 20.0])
    d = np.array([2.0, 0.0, 0.0, 2.0])
    assert summary["error_difference_pct_mean"] == pytest.approx(e.mean())
    assert summary["error_difference_pct_std"] == pytest.approx(e.std(ddof=1))
    assert summary["delay_difference_mean"] == pytest.approx(d.mean())
    assert summary["delay_difference_std"] == pytest.approx(d.std(ddof=1))
    assert summary["estimators"]["B"]["error_difference_pct_mean"] == pytest.approx(10.0)
    assert [r["delay_difference"] for r in rows] == [2, 0, 0, 2]

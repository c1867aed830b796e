"""findings.csv judged strictly: each rule on hand-made evaluations where it holds and where it fails."""

import numpy as np
import pytest

from studyapp.evaluation import findings as fd
from studyapp.evaluation.report import Evaluation

FMAX = [0.5, 1.0, 1.5, 2.2, 3.3, 4.4, 5.5, 7.7, 9.9, 12.1]  # group a: the first 8; group b: the last 7
N = len(FMAX)


def _evaluation(values):
    """``values``: name -> (E, D), each a number (every recording) or one value per recording."""
    errors = {n: np.broadcast_to(np.asarray(e, dtype=float), (N,)).copy() for n, (e, _) in values.items()}
    delays = {n: np.broadcast_to(np.asarray(d, dtype=float), (N,)).copy() for n, (_, d) in values.items()}
    baseline = values.get("LOWPASS", (1.0, 10.0))
    return Evaluation(
        names=list(values), recordings=[f"fmax_{f}.npz" for f in FMAX], fmax=FMAX, rates=[5000.0] * N,
        params={"FOAW": {"window": 17, "margin": 1e-4}}, errors=errors, delays=delays,
        baseline_errors=np.broadcast_to(np.asarray(baseline[0], dtype=float), (N,)).copy(),
        baseline_delays=np.broadcast_to(np.asarray(baseline[1], dtype=float), (N,)).copy(),
    )


def _noisy(level, seed, spread=0.2):
    """Per-recording values around ``level``: overlapping samples for nearby levels."""
    return level * (1.0 + spread * np.random.default_rng(seed).uniform(-1.0, 1.0, N))


A = _evaluation({"LOWPASS": (1.0, 10.0)}).group_mask("a")
B = _evaluation({"LOWPASS": (1.0, 10.0)}).group_mask("b")


def test_every_row_states_its_rule():
    values = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "KALPOS": (0.9, 9.0), "LEVANT": (5.6, 4.0),
              "FOAW": (0.8, 20.0), "LEASTSQ": (2.0, 3.0), "KALLEV": (0.6, 6.0)}
    rows = fd.findings(_evaluation(values), foaw_fraction=0.99,
                       validation={"error_difference_pct_mean": 12.0, "error_difference_pct_std": 5.0,
                                   "delay_difference_mean": 3.0, "delay_difference_std": 1.0})
    assert all(list(r) == fd.FINDING_COLUMNS and "; rule: " in r["paper"] for r in rows)
    assert [r["finding"].split(" (")[0].split(",")[0] for r in rows] == [
        "KALMAN best on the objective", "third-order Kalman filters best on both criteria",
        "best six not significantly different on both criteria", "no significant gain from the accelerometer",
        "LEVANT error", "FOAW error", "FOAW |delay|", "FOAW window at its maximum", "LEASTSQ |delay|",
        "beat LOWPASS on both error and |delay|", "validation error difference", "validation delay difference"]


def test_kalman_best_is_rank_1():
    assert fd.kalman_best(_evaluation({"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0)}), A)["agrees"]
    row = fd.kalman_best(_evaluation({"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "KALLEV": (0.4, 4.0)}), A)
    assert not row["agrees"] and row["ours"].startswith("KALLEV best") and "KALMAN rank 2 of 3" in row["ours"]


def test_third_order_kalman_filters_hold_the_top_ranks_of_both_criteria():
    holds = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "KALLEV": (0.6, 6.0), "LEASTSQ": (2.0, 7.0)}
    assert fd.third_order_best(_evaluation(holds), A)["agrees"]
    fails = dict(holds, LEASTSQ=(2.0, 3.0))  # the fastest: KALLEV's |delay| rank is 3 of 4
    row = fd.third_order_best(_evaluation(fails), A)
    assert not row["agrees"] and "|delay| ranks KALMAN 2, KALLEV 3" in row["ours"]


def test_a_lead_ranks_by_its_magnitude():
    """A 6-sample lead is as far from the LVT as a 6-sample lag: it ranks behind a 5-sample lag."""
    values = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, -6.0), "KALLEV": (0.6, 5.0), "LEASTSQ": (2.0, 7.0)}
    row = fd.third_order_best(_evaluation(values), A)
    assert "|delay| ranks KALMAN 2, KALLEV 1" in row["ours"] and row["agrees"]


def test_best_six_disagree_when_one_beats_another_on_both_criteria():
    names = ["LOWPASS", "KALMAN", "KALLEV", "KALFOAW", "LEASTSQ", "COMP1", "COMP2"]
    overlapping = {n: (_noisy(1.0, i), _noisy(10.0, 100 + i)) for i, n in enumerate(names)}
    row = fd.best_six_not_different(_evaluation(overlapping), A)
    assert row["agrees"] and "no pair significantly different on both" in row["ours"]
    # KALMAN's samples all below the others' on both: exact two-sided p = 2 / C(16, 8) = 1.6e-4 against each
    dominant = dict(overlapping, KALMAN=(_noisy(0.3, 50), _noisy(3.0, 51)))
    row = fd.best_six_not_different(_evaluation(dominant), A)
    assert not row["agrees"] and "KALMAN over KALLEV (error p 0.00016, |delay| p 0.00016)" in row["ours"]
    # better on error only (LEASTSQ-like delay): not on both at once, so the finding holds
    error_only = dict(overlapping, KALMAN=(_noisy(0.3, 50), _noisy(10.0, 51)))
    assert fd.best_six_not_different(_evaluation(error_only), A)["agrees"]


def test_a_significant_gain_from_the_accelerometer_disagrees():
    same = {"LOWPASS": (1.0, 10.0), "KALPOS": (_noisy(0.5, 1), _noisy(5.0, 2)),
            "KALMAN": (_noisy(0.5, 3), _noisy(5.0, 4))}
    row = fd.accelerometer_gain(_evaluation(same), A)
    assert row["agrees"] and row["ours"].startswith("KALMAN vs KALPOS: error p ")
    gain = dict(same, KALMAN=(_noisy(0.13, 3), _noisy(5.0, 4)))  # 26 % of LOWPASS against KALPOS's 50 %
    row = fd.accelerometer_gain(_evaluation(gain), A)
    assert not row["agrees"] and "error p 0.00016 (gain)" in row["ours"]


@pytest.mark.parametrize("levant, agrees", [(5.6, True), (2.8, True), (11.2, True), (2.7, False), (1.33, False),
                                            (12.0, False)])
def test_levant_error_is_within_a_factor_2_of_560_percent_and_the_highest(levant, agrees):
    values = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "LEVANT": (levant, 4.0), "FOAW": (0.8, 20.0)}
    assert fd.levant_error(_evaluation(values), A)["agrees"] is agrees


def test_levant_within_the_factor_but_not_the_highest_disagrees():
    values = {"LOWPASS": (1.0, 10.0), "LEVANT": (5.6, 4.0), "FOAW": (8.0, 20.0)}
    assert not fd.levant_error(_evaluation(values), A)["agrees"]


def test_foaw_error_and_delay_and_leastsq_delay_by_half_ranks():
    values = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "FOAW": (0.8, 20.0), "LEASTSQ": (2.0, 3.0)}
    ev = _evaluation(values)
    assert fd.foaw_error(ev, A)["agrees"] and fd.foaw_delay(ev, A)["agrees"] and fd.leastsq_delay(ev, A)["agrees"]
    ev = _evaluation(dict(values, FOAW=(1.5, 2.0), LEASTSQ=(2.0, 30.0)))
    assert fd.foaw_error(ev, A)["ours"] == "150 (rank 3 of 4)"
    assert not (fd.foaw_error(ev, A)["agrees"] or fd.foaw_delay(ev, A)["agrees"] or fd.leastsq_delay(ev, A)["agrees"])


def test_beat_lowpass_is_exactly_the_levant_kalman_pair():
    values = {"LOWPASS": (1.0, 10.0), "KALLEV": (0.6, 6.0), "KALMAN": (0.5, [5.0] * 3 + [15.0] * 7)}
    assert fd.beat_lowpass(_evaluation(values), B)["agrees"]
    row = fd.beat_lowpass(_evaluation(dict(values, KALMAN=(0.5, 5.0))), B)
    assert not row["agrees"] and row["ours"] == "KALLEV, KALMAN"


@pytest.mark.parametrize("mean, agrees", [(5.15, True), (20.6, True), (2.88, False), (21.0, False), (None, False)])
def test_validation_error_within_a_factor_2(mean, agrees):
    row = fd.validation_error({"error_difference_pct_mean": mean, "error_difference_pct_std": 1.0})
    assert row["agrees"] is agrees and row["paper"].startswith("10.3 +- 7.76 % (Sec. 7.3); rule: ")


@pytest.mark.parametrize("mean, agrees", [(1.3, True), (5.2, True), (0.969, False), (5.3, False)])
def test_validation_delay_within_a_factor_2(mean, agrees):
    assert fd.validation_delay({"delay_difference_mean": mean, "delay_difference_std": 1.0})["agrees"] is agrees


def test_missing_estimators_leave_their_findings_out():
    values = {"LOWPASS": (1.0, 10.0), "FOAW": (0.8, 10.0), "LEASTSQ": (2.0, 10.0)}
    found = [r["finding"] for r in fd.findings(_evaluation(values))]
    assert not any(f.startswith(("KALMAN best", "third-order", "no significant gain", "LEVANT")) for f in found)
    assert not any(f.startswith("validation") for f in found)


def test_rank_span_of_ties():
    values = {"A": 1.0, "B": 1.0, "C": 2.0, "D": np.nan}
    assert fd.rank_span(values, "A") == (1, 2) and fd.rank_span(values, "C") == (3, 3)
    assert fd.rank_span(values, "D") == (4, 4)
    assert fd.rank_span({"A": 1.0, "B": 1.04, "C": 1.2}, "B", 0.05) == (1, 2)


def test_a_rank_between_ties_is_undecided_never_a_pass():
    """Issue 30: every median |delay| 0 samples; the mean rank of the tie passed or failed by default."""
    values = {"LOWPASS": (1.0, 0.0), "KALMAN": (0.5, 0.0), "KALLEV": (0.6, 0.0), "FOAW": (0.8, 0.0),
              "LEASTSQ": (2.0, 0.0)}
    ev = _evaluation(values)
    for row in (fd.foaw_delay(ev, A), fd.leastsq_delay(ev, A), fd.third_order_best(ev, A)):
        assert row["verdict"] == fd.UNDECIDED and not row["agrees"]
        assert "every median whole-sample |D| is 0: not ranked" in row["ours"]
    assert fd.foaw_error(ev, A)["verdict"] == fd.FAILS  # error rank 3 of 5, no tie: decided
    assert fd.beat_lowpass(ev, B)["verdict"] == fd.UNDECIDED


def test_third_order_fails_when_a_member_is_surely_out_whatever_the_ties():
    values = {"LOWPASS": (1.0, 0.0), "KALMAN": (0.5, 0.0), "KALLEV": (3.0, 0.0), "LEASTSQ": (2.0, 0.0)}
    assert fd.third_order_best(_evaluation(values), A)["verdict"] == fd.FAILS


def test_kalman_tied_for_first_is_undecided():
    values = {"LOWPASS": (1.0, 10.0), "KALMAN": (0.5, 5.0), "KALLEV": (0.5, 5.0)}
    row = fd.kalman_best(_evaluation(values), A)
    assert row["verdict"] == fd.UNDECIDED and "KALMAN rank 1-2 (tied) of 3" in row["ours"]


def test_sub_sample_delays_rank_within_their_resolution():
    values = {"LOWPASS": (1.0, 0.0), "KALMAN": (0.5, 0.0), "FOAW": (0.8, 0.0), "LEASTSQ": (2.0, 0.0)}
    ev = _evaluation(values)
    sub = {"LOWPASS": 0.9, "KALMAN": 0.1, "FOAW": 0.6, "LEASTSQ": 0.63}
    ev.subsample_delays = {n: np.full(N, d) for n, d in sub.items()}
    ev.baseline_subsample_delays = np.full(N, 0.9)
    row = fd.foaw_delay(ev, A)  # FOAW and LEASTSQ 0.03 samples apart: ranks 2-3 of 4
    assert row["verdict"] == fd.UNDECIDED and "rank 2-3 (tied) of 4" in row["ours"]
    assert "ranked by the sub-sample delay" in row["ours"]
    ev.subsample_delays["LEASTSQ"] = np.full(N, 0.7)
    assert fd.foaw_delay(ev, A)["verdict"] == fd.FAILS and fd.leastsq_delay(ev, A)["verdict"] == fd.FAILS

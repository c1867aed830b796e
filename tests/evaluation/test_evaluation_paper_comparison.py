"""``evaluate --compare-paper``: Table 1 beside ours, and the paper's findings decided by their rules."""

import csv

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.evaluation import paper_comparison as pc
from studyapp.evaluation.report import Evaluation
from tests.evaluation.conftest import synthetic_recording

FMAX = [0.5, 2.2, 7.7, 12.1]  # group a: the first three; group b: the last three
A = np.array([True, True, True, False])


def _evaluation(values):
    """An ``Evaluation`` of hand-made (E, D) per estimator, the same on every recording unless a list is given."""
    errors = {n: np.broadcast_to(np.asarray(e, dtype=float), (4,)).copy() for n, (e, _) in values.items()}
    delays = {n: np.broadcast_to(np.asarray(d, dtype=float), (4,)).copy() for n, (_, d) in values.items()}
    return Evaluation(
        names=list(values), recordings=[f"fmax_{f}.npz" for f in FMAX], fmax=FMAX, rates=[5000.0] * 4,
        params={"FOAW": {"window": 17, "margin": 1e-4}}, errors=errors, delays=delays,
        baseline_errors=errors["LOWPASS"], baseline_delays=delays["LOWPASS"],
    )


def _fg_over_a(values, name):
    """F_g over group a by eqs. 29-32, computed here from the raw numbers."""
    e = np.array([np.broadcast_to(v[0], (4,)) for v in values.values()], dtype=float)
    d = np.array([np.broadcast_to(v[1], (4,)) for v in values.values()], dtype=float)
    i = list(values).index(name)
    f = (e[i] - e.min(0)) / np.ptp(e, 0) + (d[i] - d.min(0)) / np.ptp(d, 0)
    return f[A].sum()


# The paper's findings hold: KALLEV best, LEVANT's error 560 % and the highest, FOAW the slowest,
# LEASTSQ the fastest, and in group b only KALLEV beats LOWPASS (KALMAN's delay is 150 % there).
AGREEING = {
    "LOWPASS": (1.0, 10.0),
    "KALMAN": (0.5, [5.0, 5.0, 15.0, 15.0]),
    "LEVANT": (5.6, 4.0),
    "FOAW": (0.8, 20.0),
    "LEASTSQ": (2.0, 3.0),
    "KALLEV": (0.6, 6.0),
}
# ... and none of them does.
DISAGREEING = {
    "LOWPASS": (1.0, 10.0),
    "KALMAN": (3.0, 30.0),
    "LEVANT": (0.9, 4.0),
    "FOAW": (0.8, 2.0),
    "LEASTSQ": (0.5, 40.0),
    "KALLEV": (1.5, 5.0),
}


def _by_finding(rows):
    return {r["finding"].split(" (")[0].split(",")[0]: r for r in rows}


def test_table_1_is_the_papers():
    """Typed from the paper's Table 1 (R_p and the hybrids' inner settings are not in it)."""
    assert pc.table_1() == {
        "LOWPASS": {"cutoff_hz": 256.0}, "LEASTSQ": {"order": 2, "window": 33},
        "FOAW": {"window": 17, "margin": 1.001e-4}, "LEVANT": {"c": 19.7},
        "LEVANTLP": {"c": 3.6, "cutoff_hz": 293.0}, "KALPOS": {"q": 0.191},
        "KALMAN": {"q": 108.0, "r_acc": 6.28e4}, "KALLEV": {"q": 6.38e4, "r_acc": 195.0},
        "KALLEVACC": {"q": 2954.0, "r_acc": 64.6}, "KALFOAW": {"q": 77.7, "r_acc": 8.06},
        "KALFOAWACC": {"q": 88.5, "r_acc": 3.85}, "COMP1": {"cutoff_hz": 317.0},
        "COMP2": {"lpf_hz": 256.0, "hpf_hz": 2254.0},
    }


def test_parameter_rows_put_ours_beside_the_papers():
    rows = pc.parameter_rows({"LEVANT": {"c": 1.7}, "KALLEV": {"q": 0.007, "r_acc": 3.0, "c": 100.0}})
    assert len(rows) == 22 and all(list(r) == pc.PARAMETER_COLUMNS for r in rows)
    got = {(r["estimator"], r["parameter"]): (r["paper"], r["ours"]) for r in rows}
    assert got[("LEVANT", "c")] == (19.7, 1.7)
    assert got[("KALLEV", "q")] == (6.38e4, 0.007) and got[("KALLEV", "r_acc")] == (195.0, 3.0)
    assert got[("FOAW", "window")] == (17, None)  # not evaluated: no value of ours


def test_findings_agree_when_the_papers_hold():
    rows = pc.findings(_evaluation(AGREEING), foaw_fraction=0.99,
                       validation={"error_difference_pct_mean": 12.0, "error_difference_pct_std": 5.0,
                                   "delay_difference_mean": 3.0, "delay_difference_std": 1.0})
    assert all(list(r) == pc.FINDING_COLUMNS for r in rows)
    found = _by_finding(rows)
    assert list(found) == ["best on the objective", "LEVANT error", "FOAW delay", "FOAW window at its maximum",
                           "LEASTSQ delay", "beat LOWPASS on both error and delay",
                           "validation error difference", "validation delay difference"]
    assert all(r["agrees"] is True for r in rows), rows
    assert found["best on the objective"]["ours"] == f"KALLEV (F_g {_fg_over_a(AGREEING, 'KALLEV'):.3g})"
    assert found["LEVANT error"]["ours"] == "560 (rank 6 of 6, 1 = lowest)"
    assert found["FOAW delay"]["ours"] == "200 (rank 6 of 6, 1 = lowest)"
    assert found["LEASTSQ delay"]["ours"] == "30 (rank 1 of 6, 1 = lowest)"
    assert found["FOAW window at its maximum"]["ours"] == "99 (window 17)"
    assert found["beat LOWPASS on both error and delay"]["ours"] == "KALLEV"
    assert found["validation delay difference"]["ours"] == "3 +- 1 samples"


def test_findings_disagree_when_the_papers_do_not_hold():
    rows = pc.findings(_evaluation(DISAGREEING), foaw_fraction=0.5,
                       validation={"error_difference_pct_mean": 25.0, "error_difference_pct_std": 5.0,
                                   "delay_difference_mean": 0.32, "delay_difference_std": 0.61})
    assert len(rows) == 8 and all(r["agrees"] is False for r in rows), rows
    found = _by_finding(rows)
    assert found["best on the objective"]["ours"] == f"FOAW (F_g {_fg_over_a(DISAGREEING, 'FOAW'):.3g})"
    assert found["beat LOWPASS on both error and delay"]["ours"] == "LEVANT, FOAW"
    assert found["LEVANT error"]["ours"] == "90 (rank 3 of 6, 1 = lowest)"


@pytest.mark.parametrize("mean, agrees", [(2.6 - 1.9, True), (2.6 + 1.9, True), (2.6 - 2.1, False),
                                          (2.6 + 2.1, False), (None, False)])
def test_validation_rule_is_the_papers_mean_within_its_sd(mean, agrees):
    row = pc.validation_delay({"delay_difference_mean": mean, "delay_difference_std": None})
    assert row["agrees"] is agrees and row["paper"] == "2.6 +- 2.02 samples"


def test_ties_share_their_rank_and_missing_findings_are_left_out():
    values = {"LOWPASS": (1.0, 10.0), "FOAW": (0.8, 10.0), "LEASTSQ": (2.0, 10.0), "KALMAN": (0.5, 20.0)}
    rows = pc.findings(_evaluation(values))
    found = _by_finding(rows)
    # LOWPASS, FOAW and LEASTSQ tie at 100 %: mean rank 2 of 4, in the faster half, not the slower
    assert found["FOAW delay"]["ours"] == "100 (rank 2 of 4, 1 = lowest)" and not found["FOAW delay"]["agrees"]
    assert found["LEASTSQ delay"]["agrees"]
    assert "LEVANT error" not in found and "FOAW window at its maximum" not in found
    assert "validation error difference" not in found


def test_fraction_at_maximum_on_straight_lines():
    """A line from rest: FOAW's window grows 1, 2, ... after the start, so W - 1 samples fall short of W."""
    window = 9
    lines = [0.01 + 0.2 * np.arange(n) / 5000.0 for n in (100, 250)]
    expected = (100 - (window - 1) + 250 - (window - 1)) / 350
    assert pc.fraction_at_maximum(lines, window, 1e-9) == pytest.approx(expected, rel=1e-12)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    from studyapp.recording import save

    root = tmp_path_factory.mktemp("paper_comparison")
    for folder, seed in (("train", 0), ("valid", 50)):
        (root / folder).mkdir()
        for i, fmax in enumerate((1.0, 4.4, 9.9)):
            save(synthetic_recording(fmax, duration=0.3, seed=seed + i), root / folder / f"fmax_{fmax}.npz")
    (root / "PARAMS.toml").write_text("[LOWPASS]\ncutoff_hz = 300.0\n[FOAW]\nwindow = 12\nmargin = 2e-5\n"
                                      "[LEASTSQ]\norder = 2\nwindow = 20\n")
    return root


def _csv(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def test_evaluate_compare_paper_writes_both_tables(recordings, tmp_path, capsys):
    from studyapp.estimators import create
    from studyapp.estimators.dispatch import GUARD
    from studyapp.estimators.foaw import CHOSEN
    from studyapp.recording import load

    out = tmp_path / "eval"
    assert main(["evaluate", str(recordings / "train"), "--params", str(recordings / "PARAMS.toml"), "-o", str(out),
                 "--validation", str(recordings / "valid"), "--compare-paper"]) == 0
    table = _csv(out / "paper_comparison.csv")
    assert table[0] == ["estimator", "parameter", "paper", "ours"]
    assert ["FOAW", "window", "17", "12"] in table and ["FOAW", "margin", "0.0001001", "2e-05"] in table
    assert ["LEVANT", "c", "19.7", ""] in table
    findings = _csv(out / "findings.csv")
    assert findings[0] == ["finding", "paper", "ours", "agrees"]
    assert all(r[3] in ("True", "False") for r in findings[1:])
    assert len(findings) == 1 + 7  # no LEVANT: best, FOAW twice, LEASTSQ, beat LOWPASS, validation twice

    # FOAW's window at its maximum, counted from the estimator's own state sample by sample
    at_max = total = 0
    for path in sorted((recordings / "train").glob("*.npz")):
        est = create("FOAW", 5000.0, window=12, margin=2e-5)
        for x in load(path)["position"]:
            est.step(x)
            at_max += est.state[GUARD + CHOSEN] == 12
            total += 1
    row = next(r for r in findings if r[0].startswith("FOAW window"))
    assert row[2] == f"{100 * at_max / total:.3g} (window 12)"


def test_compare_paper_needs_an_output_folder(recordings, capsys):
    assert main(["evaluate", str(recordings / "train"), "--compare-paper"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--compare-paper" in err[0] and "-o" in err[0]

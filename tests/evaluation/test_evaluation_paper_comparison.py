"""``evaluate --compare-paper``: Table 1 beside ours, and the findings table written (rules: test_evaluation_findings)."""

import csv

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.evaluation import paper_comparison as pc
from tests.evaluation.conftest import synthetic_recording

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


def test_fraction_at_maximum_on_straight_lines():
    """A line from rest: FOAW's size is 2, 3, ... at samples 1, 2, ..., so samples 1 .. W - 2 fall short of W."""
    window = 9
    lines = [0.01 + 0.2 * np.arange(n) / 5000.0 for n in (100, 250)]
    expected = (100 - (window - 2) + 250 - (window - 2)) / 350
    assert pc.fraction_at_maximum(lines, window, 1e-9) == pytest.approx(expected, rel=1e-12)


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    from studyapp.io.recording import save

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
    from studyapp.io.recording import load

    out = tmp_path / "eval"
    assert main(["evaluate", str(recordings / "train"), "--params", str(recordings / "PARAMS.toml"), "-o", str(out),
                 "--validation", str(recordings / "valid"), "--compare-paper"]) == 0
    table = _csv(out / "paper_comparison.csv")
    assert table[0] == ["estimator", "parameter", "paper", "ours"]
    assert ["FOAW", "window", "17", "12"] in table and ["FOAW", "margin", "0.0001001", "2e-05"] in table
    assert ["LEVANT", "c", "19.7", ""] in table
    findings = _csv(out / "findings.csv")
    assert findings[0][:5] == ["finding", "paper", "ours", "agrees", "verdict"]  # then each set's (both_sets)
    assert all(r[3] in ("True", "False") for r in findings[1:])
    assert all(r[4] in ("holds", "fails", "undecided (ties)") and (r[3] == "True") == (r[4] == "holds")
               for r in findings[1:])
    # no Kalman filter, no LEVANT: best six, FOAW error, |delay| and window, LEASTSQ, beat LOWPASS, validation twice
    assert len(findings) == 1 + 8
    assert all("; rule: " in r[1] for r in findings[1:])

    # FOAW's window at its maximum, counted from the estimator's own state sample by sample
    at_max = total = 0
    for path in sorted((recordings / "train").glob("*.npz")):
        est = create("FOAW", 5000.0, window=12, margin=2e-5)
        for x in load(path)["position"]:
            est.step(x)
            at_max += est.state[GUARD + CHOSEN] + 1 == 12  # the slot holds n intervals: size n + 1
            total += 1
    row = next(r for r in findings if r[0].startswith("FOAW window"))
    assert row[2] == f"{100 * at_max / total:.3g} (size 12)"


def test_compare_paper_needs_an_output_folder(recordings, capsys):
    assert main(["evaluate", str(recordings / "train"), "--compare-paper"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--compare-paper" in err[0] and "-o" in err[0]

"""``evaluate --compare-paper``: every finding under the paper's Table 1 and under the tuned file, side by side (issue 42).

The per-set verdicts and counts are checked against each set evaluated on its own here, through the
evaluation API (``report.evaluate`` of the file's values, and of the estimators' defaults, which are Table 1
at its own 5 kHz), and against ``evaluate`` run without ``--params``.
"""

import csv
import json

import pytest

from studyapp.cli import main
from studyapp.estimators.registry import spec
from studyapp.evaluation import paper_comparison as pc
from studyapp.evaluation.dataset import Dataset, expand_paths, load_takes
from studyapp.evaluation.params_file import read
from studyapp.evaluation.report import evaluate
from studyapp.evaluation.validation import compare
from tests.evaluation.conftest import synthetic_recording

NAMES = ("LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "KALPOS", "KALMAN")


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    from studyapp.io.recording import save

    root = tmp_path_factory.mktemp("both_sets")
    for folder, seed in (("train", 0), ("valid", 50)):
        (root / folder).mkdir()
        for i, fmax in enumerate((1.0, 2.2, 4.4, 9.9)):
            save(synthetic_recording(fmax, duration=0.3, seed=seed + i), root / folder / f"fmax_{fmax}.npz")
    (root / "PARAMS.toml").write_text(
        "[LOWPASS]\ncutoff_hz = 528.0\n[LEASTSQ]\norder = 2\nwindow = 20\n[FOAW]\nwindow = 6\nmargin = 4e-4\n"
        "[LEVANT]\nc = 10.8\n[KALPOS]\nq = 1.13\n[KALMAN]\nq = 904.0\nr_acc = 80.5\n")
    return root


def _rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _independent(root, params):
    """findings.csv rows of one parameter set, evaluated here on the same recordings and validation set."""
    takes = load_takes(expand_paths([root / "train"]), "lvt")
    result = evaluate(Dataset(takes), params)
    summary, _ = compare(result, evaluate(Dataset(load_takes(expand_paths([root / "valid"]), "lvt")), params))
    return pc.finding_rows(result, [t.position for t in takes], summary)


def test_both_sets_side_by_side_and_their_counts(recordings, tmp_path, capsys):
    out = tmp_path / "ev"
    args = ["evaluate", str(recordings / "train"), "--params", str(recordings / "PARAMS.toml"),
            "--validation", str(recordings / "valid"), "-o", str(out), "--compare-paper"]
    assert main(args) == 0
    printed = capsys.readouterr().out
    rows = _rows(out / "findings.csv")
    assert list(rows[0])[:5] == ["finding", "paper", "ours", "agrees", "verdict"]  # what other readers rely on
    assert list(rows[0]) == pc.BOTH_COLUMNS

    tuned = _independent(recordings, read(recordings / "PARAMS.toml")[0])
    table1 = _independent(recordings, {n: spec(n).validate(5000.0, {})[1] for n in NAMES})
    assert [r["finding"] for r in rows] == [r["finding"] for r in tuned] == [r["finding"] for r in table1]
    for row, t, p in zip(rows, tuned, table1):
        assert (row["verdict_tuned"], row["ours_tuned"]) == (t["verdict"], t["ours"])
        assert (row["verdict_table1"], row["ours_table1"]) == (p["verdict"], p["ours"])
        assert (row["verdict"], row["ours"]) == (t["verdict"], t["ours"])  # the evaluated set's, as before
        assert row["holds_tuned"] == str(t["verdict"] == "holds") and row["holds_table1"] == str(p["verdict"] == "holds")
    # the two sets must judge something differently here, or the columns could be swapped unseen
    assert any(t["ours"] != p["ours"] for t, p in zip(tuned, table1))

    n = len(tuned)
    holds_t = sum(r["verdict"] == "holds" for r in tuned)
    holds_p = sum(r["verdict"] == "holds" for r in table1)
    assert (f"findings (findings.csv): {holds_p} of {n} hold with the paper's Table 1, {holds_t} of {n} "
            f"with the tuned parameters ({recordings / 'PARAMS.toml'})") in printed
    document = json.loads((out / "evaluation.json").read_text())["findings"]
    assert {k: v for k, v in document.items() if k != "rows"} == {
        "parameter_sets": ["table1", "tuned"], "holds_table1": holds_p, "judged_table1": n,
        "holds_tuned": holds_t, "judged_tuned": n}

    # Table 1's columns are what evaluate without --params finds on the same recordings
    single = tmp_path / "one"
    assert main(["evaluate", str(recordings / "train"), "--estimators", ",".join(NAMES),
                 "--validation", str(recordings / "valid"), "-o", str(single), "--compare-paper", "--json"]) == 0
    one = json.loads(capsys.readouterr().out)["findings"]
    assert [(r["verdict"], r["ours"]) for r in _rows(single / "findings.csv")] == [
        (r["verdict_table1"], r["ours_table1"]) for r in rows]
    assert one["parameter_sets"] == ["table1"] and one["holds_table1"] == holds_p and one["holds_tuned"] is None


def test_without_params_it_says_there_is_one_set(recordings, tmp_path, capsys):
    out = tmp_path / "ev"
    assert main(["evaluate", str(recordings / "train"), "--estimators", "LOWPASS,FOAW,LEASTSQ",
                 "-o", str(out), "--compare-paper"]) == 0
    printed = capsys.readouterr().out
    rows = _rows(out / "findings.csv")
    assert rows and all(r["verdict_tuned"] == r["holds_tuned"] == r["ours_tuned"] == "" for r in rows)
    assert all(r["verdict_table1"] == r["verdict"] for r in rows)
    holds = sum(r["verdict"] == "holds" for r in rows)
    assert (f"findings (findings.csv): {holds} of {len(rows)} hold with the paper's Table 1; one parameter set "
            "(no --params)") in printed


def test_table_1_is_made_for_the_recordings_rate(tmp_path, capsys):
    """At 10 kHz Table 1's windows in samples keep their 5 kHz duration (at_rate), as breakdown and tradeoff make it."""
    from studyapp.io.recording import save

    (tmp_path / "train").mkdir()
    save(synthetic_recording(2.2, rate=10000.0, duration=0.3), tmp_path / "train" / "fmax_2.2.npz")
    (tmp_path / "P.toml").write_text("[LEASTSQ]\norder = 2\nwindow = 50\n")
    assert main(["evaluate", str(tmp_path / "train"), "--params", str(tmp_path / "P.toml"), "-o",
                 str(tmp_path / "ev"), "--compare-paper", "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["parameters"]["LEASTSQ"]["window"] == 50
    assert main(["evaluate", str(tmp_path / "train"), "--estimators", "LEASTSQ", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["parameters"]["LEASTSQ"]["window"] == 66  # 33 x 10 / 5 kHz


def test_bad_params_with_compare_paper_exit_2_with_one_line_and_no_table(recordings, tmp_path, capsys):
    bad = tmp_path / "BAD.toml"
    bad.write_text("[LOWPASS]\ncutoff_hz = -5.0\n")
    out = tmp_path / "ev"
    assert main(["evaluate", str(recordings / "train"), "--params", str(bad), "-o", str(out), "--compare-paper"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "BAD.toml" in err[0] and "cutoff_hz" in err[0] and "Traceback" not in err[0]
    assert not (out / "findings.csv").exists()

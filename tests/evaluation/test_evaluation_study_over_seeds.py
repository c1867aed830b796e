"""``evaluate --compare-paper --params s0.toml s1.toml s2.toml``: Table 1, the metrics and the findings over seeds."""

import csv

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.evaluation import findings as fd
from studyapp.evaluation import params_file
from studyapp.evaluation import study_over_seeds as so
from tests.evaluation.conftest import synthetic_recording


def test_a_finding_holds_or_fails_over_seeds_only_when_it_does_on_every_one():
    assert so.overall([fd.HOLDS] * 3) == fd.HOLDS and so.overall([fd.FAILS] * 3) == fd.FAILS
    assert so.overall([fd.HOLDS, fd.FAILS, fd.HOLDS]) == so.MIXED
    assert so.overall([fd.HOLDS, fd.HOLDS, fd.UNDECIDED]) == fd.UNDECIDED


def test_parameter_spread_is_median_and_range():
    sets = {f"seed {s}": {"LOWPASS": {"cutoff_hz": hz}} for s, hz in enumerate((354.0, 528.0, 300.0))}
    row = next(r for r in so.parameter_rows(sets) if r["estimator"] == "LOWPASS")
    assert (row["paper"], row["median"], row["min"], row["max"]) == (256.0, 354.0, 300.0, 528.0)
    assert row["ours seed 1"] == 528.0
    assert next(r for r in so.parameter_rows(sets) if r["estimator"] == "FOAW")["median"] is None


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    from studyapp.io.recording import save

    root = tmp_path_factory.mktemp("over_seeds")
    for folder, seed in (("train", 0), ("valid", 50)):
        (root / folder).mkdir()
        for i, fmax in enumerate((1.0, 4.4, 9.9)):
            save(synthetic_recording(fmax, duration=0.3, seed=seed + i), root / folder / f"fmax_{fmax}.npz")
    for seed, (hz, window) in enumerate(((300.0, 12), (500.0, 12), (250.0, 8))):
        params_file.write(root / f"s{seed}.toml", {"LOWPASS": {"cutoff_hz": hz}, "FOAW": {"window": window,
                          "margin": 2e-5}, "LEASTSQ": {"order": 2, "window": 20}}, provenance={"seed": seed})
    return root


def _csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_evaluate_writes_the_study_over_seeds(study, tmp_path, capsys):
    out = tmp_path / "eval"
    assert main(["evaluate", str(study / "train"), "--params", *(str(study / f"s{s}.toml") for s in range(3)),
                 "-o", str(out), "--validation", str(study / "valid"), "--compare-paper"]) == 0
    assert "findings over the parameter files" in capsys.readouterr().out
    table = {(r["estimator"], r["parameter"]): r for r in _csv(out / "paper_comparison_seeds.csv")}
    low = table["LOWPASS", "cutoff_hz"]
    assert [float(low[k]) for k in ("median", "min", "max")] == [300.0, 250.0, 500.0]
    assert [float(low[f"ours seed {s}"]) for s in range(3)] == [300.0, 500.0, 250.0]
    metrics = _csv(out / "metrics_seeds.csv")
    assert {r["metric"] for r in metrics} == set(so.METRICS)
    for r in metrics:
        values = [float(r[f"seed {s}"]) for s in range(3)]
        assert float(r["median"]) == pytest.approx(np.median(values)) and float(r["min"]) == min(values)
    # each seed's findings are the single-file evaluation's, line for line
    over = _csv(out / "findings_seeds.csv")
    for s in range(3):
        single = tmp_path / f"single{s}"
        assert main(["evaluate", str(study / "train"), "--params", str(study / f"s{s}.toml"), "-o", str(single),
                     "--validation", str(study / "valid"), "--compare-paper"]) == 0
        rows = {r["finding"]: r for r in _csv(single / "findings.csv")}
        assert {r["finding"]: r[f"verdict seed {s}"] for r in over} == {f: r["verdict"] for f, r in rows.items()}
        assert {r["finding"]: r[f"ours seed {s}"] for r in over} == {f: r["ours"] for f, r in rows.items()}
    for r in over:
        verdicts = [r[f"verdict seed {s}"] for s in range(3)]
        assert r["verdict"] == so.overall(verdicts)
        assert int(r["holds_on"]) + int(r["fails_on"]) + int(r["undecided_on"]) == 3
    capsys.readouterr()

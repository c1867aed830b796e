"""Bad input to optimise, evaluate and tradeoff: exit code 2, one line on stderr, no output file."""

import sys

import pytest

from studyapp.cli import main
from tests.evaluation.conftest import fails_with_one_line






def test_missing_recording(tmp_path, capsys):
    out = tmp_path / "P.toml"
    fails_with_one_line(capsys, ["optimise", str(tmp_path / "none.npz"), "-o", str(out)], "none.npz")
    fails_with_one_line(capsys, ["evaluate", str(tmp_path / "none.npz")], "none.npz")
    assert not out.exists()


def test_unknown_estimator(short_recording, tmp_path, capsys):
    out = tmp_path / "P.toml"
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--estimators", "LOWPASS,NOPE"],
                        "NOPE")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--estimators", "NOPE"], "NOPE")
    assert not out.exists()


def test_bad_toml(short_recording, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[LOWPASS\ncutoff_hz = 1\n")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--params", str(bad)], "invalid TOML")
    bad.write_text("[LOWPASS]\ncutoff_hz = 1e9\n")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--params", str(bad)], "cutoff_hz")
    fails_with_one_line(capsys, ["tradeoff", "--params", str(bad), "-o", str(tmp_path / "t")], "cutoff_hz")
    fails_with_one_line(capsys, ["evaluate", str(short_recording), "--params", str(tmp_path / "missing.toml")],
                        "missing.toml")


def test_bad_settings(short_recording, tmp_path, capsys):
    out = tmp_path / "P.toml"
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--patience", "0"], "--patience")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--max-sets", "0"], "--max-sets")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--restarts", "-1"], "--restarts")
    for ridge in ("1.5", "-0.1", "nan"):
        fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--ridge", ridge], "--ridge")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(tmp_path / "P.txt")], ".toml")
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(out), "--resume"], "checkpoint")
    fails_with_one_line(capsys, ["tradeoff", "--rates", "500", "-o", str(tmp_path / "t")], "rate")
    assert not out.exists()


def test_scheduler_without_dask(short_recording, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # importing it now fails, as when it is not installed
    fails_with_one_line(capsys, ["optimise", str(short_recording), "-o", str(tmp_path / "P.toml"), "--scheduler",
                    "tcp://127.0.0.1:8786"], "dask.distributed")


def test_evaluation_json_records_parameters_and_conventions(short_recording, capsys):
    """evaluation.json carries what each estimator ran with and what those numbers mean."""
    import json

    from studyapp.cli import main

    assert main(["evaluate", str(short_recording), "--estimators", "KALPOS,KALMAN,FOAW,LEVANT,LOWPASS",
                 "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["parameters"]["KALPOS"]["q"] == 0.191
    assert data["conventions"] == {
        "KALPOS": {"q_convention": "continuous"}, "KALMAN": {"q_convention": "scaled"},
        "FOAW": {"window": "size"}, "LEVANT": {"start": "zero"},
    }

"""Bad input to optimise, evaluate and tradeoff: exit code 2, one line on stderr, no output file."""

import sys

import pytest

from studyapp.cli import main
from tests.evaluation.conftest import synthetic_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    from studyapp.recording import save

    path = tmp_path_factory.mktemp("evaluation_cli") / "fmax_1.npz"
    save(synthetic_recording(1.0, duration=0.3), path)
    return path


def _fails(capsys, argv, match):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("studyapp: error:") and match in lines[0]
    assert "Traceback" not in err


def test_missing_recording(tmp_path, capsys):
    out = tmp_path / "P.toml"
    _fails(capsys, ["optimise", str(tmp_path / "none.npz"), "-o", str(out)], "none.npz")
    _fails(capsys, ["evaluate", str(tmp_path / "none.npz")], "none.npz")
    assert not out.exists()


def test_unknown_estimator(recording, tmp_path, capsys):
    out = tmp_path / "P.toml"
    _fails(capsys, ["optimise", str(recording), "-o", str(out), "--estimators", "LOWPASS,NOPE"], "NOPE")
    _fails(capsys, ["evaluate", str(recording), "--estimators", "NOPE"], "NOPE")
    assert not out.exists()


def test_bad_toml(recording, tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[LOWPASS\ncutoff_hz = 1\n")
    _fails(capsys, ["evaluate", str(recording), "--params", str(bad)], "invalid TOML")
    bad.write_text("[LOWPASS]\ncutoff_hz = 1e9\n")
    _fails(capsys, ["evaluate", str(recording), "--params", str(bad)], "cutoff_hz")
    _fails(capsys, ["tradeoff", "--params", str(bad), "-o", str(tmp_path / "t")], "cutoff_hz")
    _fails(capsys, ["evaluate", str(recording), "--params", str(tmp_path / "missing.toml")], "missing.toml")


def test_bad_settings(recording, tmp_path, capsys):
    out = tmp_path / "P.toml"
    _fails(capsys, ["optimise", str(recording), "-o", str(out), "--patience", "0"], "--patience")
    _fails(capsys, ["optimise", str(recording), "-o", str(out), "--max-sets", "0"], "--max-sets")
    _fails(capsys, ["optimise", str(recording), "-o", str(tmp_path / "P.txt")], ".toml")
    _fails(capsys, ["optimise", str(recording), "-o", str(out), "--resume"], "checkpoint")
    _fails(capsys, ["tradeoff", "--rates", "500", "-o", str(tmp_path / "t")], "rate")
    assert not out.exists()


def test_scheduler_without_dask(recording, tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # importing it now fails, as when it is not installed
    _fails(capsys, ["optimise", str(recording), "-o", str(tmp_path / "P.toml"), "--scheduler",
                    "tcp://127.0.0.1:8786"], "dask.distributed")

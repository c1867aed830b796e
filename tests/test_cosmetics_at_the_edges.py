"""What the commands say at the edges of their ranges (issue 30, item 8)."""

import numpy as np
import pytest

from studyapp.cli import main
from studyapp.errors import ParameterError
from studyapp.estimators.spec import validate_rate
from studyapp.io import recording


def test_a_rate_just_above_the_top_is_shown_as_given():
    with pytest.raises(ParameterError, match=r"rate = 96000\.0001: allowed is a number from 1000 to 96000 Hz"):
        validate_rate(96000.0001)
    with pytest.raises(ParameterError, match=r"rate = 999\.9999: allowed"):
        validate_rate(999.9999)
    with pytest.raises(ParameterError, match=r"rate = 500: allowed"):
        validate_rate(500.0)


def test_simulate_refuses_96000_0001_naming_that_value(tmp_path, capsys):
    assert main(["simulate", "--rate", "96000.0001", "--duration", "0.1", "-o", str(tmp_path / "r.npz")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("96000.0001") == 1 and "rate = 96000:" not in err
    assert list(tmp_path.iterdir()) == []


def test_fmax_minus_zero_is_recorded_as_zero(tmp_path, capsys):
    # the output path holds "-0" itself (as pytest's own /tmp/pytest-of-root/pytest-0/ does on a machine's
    # first run): what is judged is the message with the path taken out
    (tmp_path / "run-0").mkdir()
    path = tmp_path / "run-0" / "r.npz"
    assert main(["simulate", "--fmax", "-0", "--duration", "0.05", "-o", str(path)]) == 0
    err = capsys.readouterr().err
    assert str(path) in err
    said = err.replace(str(path), "<path>")
    assert "F_max 0 N" in said and "-0" not in said
    meta = recording.load(path).meta
    assert meta["fmax"] == 0.0 and str(meta["fmax"]) == "0.0"
    with np.load(path) as data:
        assert '"fmax": 0.0' in str(data["__meta__"])


def _stuck_at_the_end(tmp_path, rows=2000):
    path = tmp_path / "stuck.csv"
    x = np.full(rows, 0.011)  # the handle resting against the +11 mm stop
    np.savetxt(path, x[:, None], header="position", comments="", fmt="%.17g")
    return path


def test_levant_starting_at_zero_on_a_position_at_the_stop_says_so(tmp_path, capsys):
    path = _stuck_at_the_end(tmp_path)
    out = tmp_path / "v.csv"
    assert main(["estimate", str(path), "--estimator", "LEVANT", "--rate", "5000", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    v = np.loadtxt(out, delimiter=",", skiprows=1)[:, 1]
    spike = np.abs(v[:500]).max()
    assert spike > 0.3  # the observer starts at 0 and runs to 11 mm (0.57 m/s measured)
    assert "note: LEVANT starts its observer at position 0" in err and "11 mm" in err
    assert f"{spike:.3g} m/s" in err and "--set start=first" in err
    # started at the first sample, it does not spike, and nothing is said
    assert main(["estimate", str(path), "--estimator", "LEVANT", "--rate", "5000", "--set", "start=first",
                 "-o", str(out)]) == 0
    assert "note" not in capsys.readouterr().err
    assert np.abs(np.loadtxt(out, delimiter=",", skiprows=1)[:, 1]).max() < 1e-6


def test_no_note_for_a_position_starting_near_zero(tmp_path, capsys):
    path = tmp_path / "near.csv"
    np.savetxt(path, 1e-4 * np.sin(np.arange(1000) / 50.0)[:, None], header="position", comments="", fmt="%.17g")
    assert main(["estimate", str(path), "--estimator", "LEVANT", "--rate", "5000", "-o", str(tmp_path / "v.csv")]) == 0
    assert "note" not in capsys.readouterr().err

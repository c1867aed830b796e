"""PARAMS.toml: written by hand, read back by tomllib, with provenance; bad files give one line."""

import tomllib

import pytest

from studyapp.errors import UserError
from studyapp.evaluation import params_file
from studyapp.evaluation.parameter_sets import parameter_sets


def test_round_trip(tmp_path):
    path = tmp_path / "PARAMS.toml"
    params = {"KALMAN": {"q": 108.0, "r_acc": 6.28e4, "r_pos": 2e-10, "q_convention": "eq19"},
              "LEASTSQ": {"order": 2, "window": 33}}
    provenance = {"seed": 7, "recordings": ["a b.npz", 'q"uote.npz'], "recording_sha256": ["ab" * 32, "cd" * 32],
                  "resumed": False, "seconds": 1.5}
    params_file.write(path, params, provenance, {"KALMAN": 1.25, "LEASTSQ": float("inf")}, comment="two\nlines")
    data = tomllib.loads(path.read_text())
    assert data["KALMAN"] == params["KALMAN"] and data["LEASTSQ"] == params["LEASTSQ"]
    assert data["provenance"] == provenance
    assert data["objective"] == {"KALMAN": 1.25, "LEASTSQ": float("inf")}
    read, prov = params_file.read(path)
    assert read == params and prov == provenance
    assert path.read_text().startswith("# two\n# lines\n")


def test_the_file_records_the_conventions(tmp_path):
    """[conventions]: one line per estimator that has some (choice parameters, FOAW's size); read skips it."""
    path = tmp_path / "PARAMS.toml"
    params = {"KALPOS": {"q": 0.191, "r_pos": 2e-10, "q_convention": "continuous"},
              "FOAW": {"window": 17, "margin": 1.001e-4}, "LEVANT": {"c": 19.7, "start": "zero"},
              "LOWPASS": {"cutoff_hz": 256.0}}
    params_file.write(path, params)
    data = tomllib.loads(path.read_text())
    assert set(data["conventions"]) == {"KALPOS", "FOAW", "LEVANT"}
    assert data["conventions"]["KALPOS"].startswith("q_convention = continuous: continuous white noise")
    assert data["conventions"]["FOAW"].startswith("window = size: the most samples a line is fitted to")
    assert data["conventions"]["LEVANT"].startswith("start = zero: the observer starts at w = 0")
    read, _ = params_file.read(path)
    assert read == params


def test_parameter_sets_validate_values_and_name_the_file(tmp_path):
    path = tmp_path / "P.toml"
    path.write_text("[LOWPASS]\ncutoff_hz = 300.0\n[FOAW]\nwindow = 9\n")
    chosen, _ = parameter_sets(path, None, 5000.0)
    assert chosen == {"LOWPASS": {"cutoff_hz": 300.0}, "FOAW": {"window": 9, "margin": 1.001e-4}}
    chosen, _ = parameter_sets(path, ["LOWPASS,KALPOS"], 5000.0)
    assert list(chosen) == ["LOWPASS", "KALPOS"] and chosen["KALPOS"]["q"] == 0.191
    path.write_text("[LOWPASS]\ncutoff_hz = -3\n")
    with pytest.raises(UserError, match=r"P.toml: \[LOWPASS\] .*cutoff_hz"):
        parameter_sets(path, None, 5000.0)


@pytest.mark.parametrize("text, match", [
    ("[LOWPASS\ncutoff_hz = 3", "invalid TOML"),
    ("[NOPE]\nx = 1\n", "not an estimator"),
    ("LOWPASS = 3\n", "must be a table"),
    ("[LOWPASS]\ncutoff_hz = [1, 2]\n", "number or a string"),
])
def test_bad_files(tmp_path, text, match):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(UserError, match=match) as info:
        params_file.read(path)
    assert "\n" not in str(info.value)
    assert str(path) in str(info.value)

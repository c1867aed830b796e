"""Noisiness ratings against audio_distance (``analyse --evaluation``), on hand-made evaluation.json files."""

import contextlib
import io
import json
import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from studyapp.analysis.numerical import load_evaluation
from studyapp.analysis.perceptual import NO_AUDIO_DISTANCE, audio_distances, perceptual_correlation
from studyapp.cli import main
from tests.analysis.conftest import PERCEPTUAL, SYNTHETIC_NOISINESS, synthetic_responses

NOISINESS = pd.Series({"LVT": 0.0, "KALLEV": 0.2, "LOWPASS": 0.35, "KALPOS": 0.4, "FOAW": 0.7, "LEVANT": 1.0})


def _write(folder, estimators):
    folder.mkdir(exist_ok=True)
    (folder / "evaluation.json").write_text(json.dumps({"estimators": estimators, "ranking": list(estimators)}))
    return folder


def _estimator(error, audio=None):
    result = {"error": error, "delay": [1.0] * len(error)}
    if audio is not None:
        result["audio_distance"] = audio
    return result


ESTIMATORS = {
    # audio_distance as one number, or one per recording (median over the finite ones; null skipped)
    "kallev": _estimator([1.0, 2.0], 0.5),
    "LOWPASS": _estimator([2.0, 2.0], [0.4, 0.9, None]),
    "KALPOS": _estimator([1.5, 1.5], [1.1, 1.3]),
    "FOAW": _estimator([3.0, 5.0], 2.0),
    "LEVANT": _estimator([9.0, 9.0], [3.0]),
    "LEASTSQ": _estimator([2.5, 2.5], [None]),  # evaluated, but not rated and no distance
}


def test_audio_distance_per_estimator(tmp_path):
    evaluation = load_evaluation(_write(tmp_path, ESTIMATORS))
    distances = audio_distances(evaluation)
    assert distances.to_dict() == pytest.approx({"KALLEV": 0.5, "LOWPASS": 0.65, "KALPOS": 1.2, "FOAW": 2.0,
                                                 "LEVANT": 3.0})


def test_spearman_against_scipy_beside_the_error_correlation(tmp_path):
    evaluation = load_evaluation(_write(tmp_path, ESTIMATORS))
    table, note = perceptual_correlation(evaluation, NOISINESS)
    assert note is None and list(table.columns) == PERCEPTUAL
    audio, error = table.iloc[0], table.iloc[1]
    # Conditions rated and with a distance: KALLEV, LOWPASS, KALPOS, FOAW, LEVANT (LVT is not evaluated).
    common = ["KALLEV", "LOWPASS", "KALPOS", "FOAW", "LEVANT"]
    reference = stats.spearmanr(NOISINESS[common], [0.5, 0.65, 1.2, 2.0, 3.0])
    assert (audio.comparison, audio.metric, audio.n, audio.conditions) == (
        "noisiness vs audio_distance", "audio_distance", 5, " ".join(common))
    assert (audio.rho, audio.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)
    assert audio.rho == 1.0 and math.isnan(audio.paper_rho)
    # Median error: KALLEV 1.5, LOWPASS 2, KALPOS 1.5, FOAW 4, LEVANT 9 (ties share ranks).
    reference = stats.spearmanr(NOISINESS[common], [1.5, 2.0, 1.5, 4.0, 9.0])
    assert (error.comparison, error.metric, error.n) == ("noisiness vs error", "error", 5)
    assert (error.rho, error.p_value) == pytest.approx((reference.statistic, reference.pvalue), rel=1e-12)
    assert error.paper_rho == 0.61


def test_evaluation_without_audio_distance_is_a_note(tmp_path):
    estimators = {name: _estimator(result["error"]) for name, result in ESTIMATORS.items()}
    table, note = perceptual_correlation(load_evaluation(_write(tmp_path, estimators)), NOISINESS)
    assert note == NO_AUDIO_DISTANCE and "\n" not in note
    assert table.iloc[0].n == 0 and math.isnan(table.iloc[0].rho)
    assert table.iloc[1].n == 5 and np.isfinite(table.iloc[1].rho)


def _analyse(tmp_path, estimators, name):
    source = tmp_path / "responses.csv"
    if not source.exists():
        synthetic_responses(participants=3, trials=2, seed=5).to_csv(source, index=False)
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["analyse", str(source), "--evaluation", str(_write(tmp_path / f"eval_{name}", estimators)),
                     "-o", str(tmp_path / name)])
    return code, tmp_path / name, err.getvalue()


def test_analyse_with_an_evaluation_writes_the_correlation(tmp_path):
    distance = {name: 0.1 * k + 0.05 * (k % 2) for k, name in enumerate(SYNTHETIC_NOISINESS)}
    estimators = {name: _estimator([1.0 + k], distance[name]) for k, name in enumerate(SYNTHETIC_NOISINESS)}
    code, out, err = _analyse(tmp_path, estimators, "with")
    assert code == 0 and "note:" not in err
    table = pd.read_csv(out / "perceptual_correlation.csv")
    assert list(table.columns) == PERCEPTUAL
    rated = pd.read_csv(out / "summary_rating.csv").set_index("condition")["median"]
    reference = stats.spearmanr(rated[list(distance)], list(distance.values()))
    assert table.loc[0, "n"] == len(SYNTHETIC_NOISINESS)
    assert table.loc[0, ["rho", "p_value"]].tolist() == pytest.approx([reference.statistic, reference.pvalue])
    assert table.loc[1, "paper_rho"] == 0.61
    html = (out / "report.html").read_text()
    assert "Noisiness against the perceptual audio distance" in html and "0.61" in html


def test_analyse_without_audio_distance_says_so_in_one_line(tmp_path):
    estimators = {name: _estimator([1.0 + k]) for k, name in enumerate(SYNTHETIC_NOISINESS)}
    code, out, err = _analyse(tmp_path, estimators, "without")
    assert code == 0
    notes = [line for line in err.splitlines() if "note:" in line]
    assert notes == [f"studyapp analyse: note: {NO_AUDIO_DISTANCE}"]
    table = pd.read_csv(out / "perceptual_correlation.csv")
    assert table.loc[0, "n"] == 0 and np.isnan(table.loc[0, "rho"]) and table.loc[1, "n"] == len(SYNTHETIC_NOISINESS)


@pytest.mark.parametrize("value", ["far", {"a": 1}, [1.0, "x"], True])
def test_bad_audio_distance_is_one_line_exit_2(tmp_path, value):
    estimators = {"LOWPASS": _estimator([1.0], value), "FOAW": _estimator([2.0], 1.0)}
    code, out, err = _analyse(tmp_path, estimators, "bad")
    err = err.strip().splitlines()
    assert code == 2 and not (out / "report.html").exists()
    assert err[-1].startswith("studyapp: error: ") and "estimators.LOWPASS.audio_distance" in err[-1]
    assert "evaluation.json" in err[-1]

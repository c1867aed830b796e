"""Each estimator in the closed loop, heard against TRUE (perceptual_scores.py), its figure, and tuning for it."""

import numpy as np
import pytest

from studyapp.errors import ParameterError
from studyapp.evaluation import perceptual_scores as ps
from studyapp.evaluation.perceptual import audio_distance
from studyapp.model.simulate import simulate
from tests.figure_checks import text_overlaps, texts_outside

SHORT = ps.Cases(rate=5000.0, fmax=(1.0, 4.4), seeds=(3,), duration=0.5)


def test_the_ideal_sensor_against_itself_is_at_zero():
    scores = ps.perceptual_scores(["TRUE"], {}, 5000.0, (1.0, 4.4), (3,), 0.5)
    assert scores["TRUE"]["audio_distance"] == 0.0
    assert [(c["fmax"], c["seed"]) for c in scores["TRUE"]["cases"]] == [(1.0, 3), (4.4, 3)]


def test_a_score_is_the_mean_distance_to_true_with_the_same_gesture_and_seed():
    params = {"cutoff_hz": 150.0}
    expected = []
    for fmax in SHORT.fmax:
        true = simulate(fmax, 5000.0, 0.5, source="TRUE", gesture="strokes", seed=3)
        heard = simulate(fmax, 5000.0, 0.5, source="LOWPASS", gesture="strokes", seed=3,
                         estimators={"LOWPASS": params})
        expected.append(audio_distance(true["audio"], heard["audio"], 5000.0))
    score = ps.estimator_score(SHORT, "LOWPASS", params)
    assert [c["audio_distance"] for c in score["cases"]] == expected
    assert score["audio_distance"] == pytest.approx(np.mean(expected), rel=1e-12)
    assert 0.0 < score["audio_distance"] < np.sqrt(2.0)


def test_progress_names_each_estimator(monkeypatch):
    calls = []
    ps.perceptual_scores(["LOWPASS", "LVT"], {}, 5000.0, (1.0,), (3,), 0.5,
                         progress=lambda done, total, name: calls.append((done, total, name)))
    assert calls == [(0, 2, "LOWPASS"), (1, 2, "LVT"), (2, 2, None)]


def test_a_faulted_loop_scores_infinity(monkeypatch):
    real = ps.Cases.simulate

    def faulting(self, source, fmax, seed, params=None):
        recording = real(self, source, fmax, seed, params)
        if source != "TRUE":
            recording.meta["fault"] = "non-finite value in the velocity source LOWPASS"
        return recording

    monkeypatch.setattr(ps.Cases, "simulate", faulting)
    score = ps.estimator_score(SHORT, "LOWPASS", {})
    assert score["audio_distance"] == float("inf")
    assert all(c["fault"] for c in score["cases"])
    assert ps.perceptual_objective_task(SHORT, "LOWPASS", {})[0] == float("inf")


@pytest.mark.parametrize("settings, match", [
    ({"fmax": (-1.0,)}, "fmax"),
    ({"fmax": ()}, "fmax"),
    ({"seeds": (-2,)}, "seed"),
    ({"seeds": (1.5,)}, "seed"),
    ({"duration": 0.001}, "duration"),
    ({"rate": -5.0}, "rate"),
])
def test_bad_cases_are_refused(settings, match):
    with pytest.raises(ParameterError, match=match):
        ps.Cases(**settings)


def test_spearman_matches_scipy_and_skips_missing_values():
    from scipy.stats import spearmanr

    distances = {"A": 0.1, "B": 0.3, "C": 0.2, "D": float("inf"), "E": 0.25}
    errors = {"A": 50.0, "B": 120.0, "C": 100.0, "D": 90.0, "E": 80.0}
    expected = spearmanr([0.1, 0.3, 0.2, 0.25], [50.0, 120.0, 100.0, 80.0])
    got = ps.spearman(distances, errors)
    assert got["n"] == 4
    assert got["rho"] == pytest.approx(expected.statistic) and got["p"] == pytest.approx(expected.pvalue)
    assert ps.spearman({"A": 0.1, "B": 0.2}, {"A": 1.0, "B": 2.0})["rho"] is None


def test_the_figure_has_no_overlapping_text():
    import matplotlib.pyplot as plt

    from studyapp.evaluation.perceptual_figure import draw
    from studyapp.evaluation.space import PAPER_ESTIMATORS

    rng = np.random.default_rng(4)
    names = list(PAPER_ESTIMATORS)
    distances = dict(zip(names, rng.uniform(0.1, 0.4, len(names))))
    distances["KALMAN"] = float("inf")
    errors = dict(zip(names, rng.uniform(40.0, 250.0, len(names))))
    fig = draw(names, distances, errors, {"rho": 0.61, "p": 0.03, "n": 12})
    try:
        assert text_overlaps(fig) == []
        assert texts_outside(fig) == []
        ax = fig.axes[0]
        labels = [label for _, label in sorted(zip(ax.get_yticks(), (t.get_text() for t in ax.get_yticklabels())))]
        assert labels[0] == "KALMAN (loop faulted)"  # bottom row: the faulted one, ordered last
        assert labels[-1] == min(distances, key=distances.get)  # top row: the closest to TRUE
    finally:
        plt.close(fig)


def test_tuning_for_the_audio_distance_keeps_in_range_and_never_gets_worse():
    from functools import partial

    from studyapp.estimators.registry import spec
    from studyapp.evaluation.executors import InlineExecutor
    from studyapp.evaluation.optimiser import Optimiser
    from studyapp.evaluation.space import Space

    cases = ps.Cases(rate=5000.0, fmax=(2.2,), seeds=(3,), duration=0.5)
    space = Space("LEVANT", 5000.0, "paper")
    optimiser = Optimiser({"LEVANT": space}, partial(ps.perceptual_objective_task, cases), InlineExecutor(),
                          patience=4, seed=0)
    result = optimiser.run()
    tuned = result.params["LEVANT"]
    allowed = spec("LEVANT").validate(5000.0, tuned)[1]
    assert allowed == tuned
    for dim in space.describe()["tuned"]:
        assert dim["low"] <= tuned[dim["name"]] <= dim["high"]
    true = simulate(2.2, 5000.0, 0.5, source="TRUE", seed=3)["audio"]

    def heard(params):
        audio = simulate(2.2, 5000.0, 0.5, source="LEVANT", seed=3, estimators={"LEVANT": params})["audio"]
        return audio_distance(true, audio, 5000.0)

    assert result.raw["LEVANT"][0] == pytest.approx(heard(tuned), rel=1e-12)
    assert heard(tuned) <= heard({})

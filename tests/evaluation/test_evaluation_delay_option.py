"""``--delay normalised|paper``: what each command measures with it, and where the choice is recorded."""

import json
import tomllib

import numpy as np
import pytest

from studyapp.cli import delay_option, main
from studyapp.errors import UserError
from studyapp.evaluation import delay_and_error, metric
from studyapp.evaluation.dataset import Dataset, take_from_recording
from studyapp.evaluation.normalisation import raw_objectives
from studyapp.evaluation.report import Evaluation, finite_median
from tests.evaluation.conftest import synthetic_recording

FMAX = [1.1, 4.4]


@pytest.fixture(scope="module")
def recordings(tmp_path_factory):
    from studyapp.io.recording import save

    root = tmp_path_factory.mktemp("delay_option")
    for seed, folder in enumerate(["train", "validation"]):
        (root / folder).mkdir()
        for fmax in FMAX:
            save(synthetic_recording(fmax, duration=0.4, seed=seed), root / folder / f"fmax_{fmax}.npz")
    return root


def test_the_option_offers_the_metric_methods():
    assert delay_option.METHODS == metric.METHODS
    assert delay_option.METHODS[0] == metric.DEFAULT_METHOD == "normalised"


@pytest.mark.parametrize("delay", ["normalised", "paper"])
def test_evaluate_measures_with_the_chosen_method_and_records_it(recordings, tmp_path, capsys, delay):
    from studyapp.estimators import create
    from studyapp.io.recording import load

    out = tmp_path / "ev"
    argv = ["evaluate", str(recordings / "train"), "--estimators", "LOWPASS,KALMAN", "-o", str(out),
            "--validation", str(recordings / "validation")]
    assert main(argv + ([] if delay == "normalised" else ["--delay", delay])) == 0
    capsys.readouterr()
    written = json.loads((out / "evaluation.json").read_text())
    assert written["provenance"]["delay"] == written["delay_method"] == delay
    assert written["provenance"]["command"] == "studyapp evaluate"
    assert json.loads((out / "validation.json").read_text())["provenance"]["delay"] == delay
    for r, fmax in enumerate(FMAX):
        rec = load(recordings / "train" / f"fmax_{fmax}.npz")
        est = create("KALMAN", rec.rate).process(rec["position"], rec["acceleration"], rec["velocity_lvt"])
        d, e = delay_and_error(rec["velocity_lvt"], est, 100, delay)
        assert written["estimators"]["KALMAN"]["delay"][r] == d
        assert written["estimators"]["KALMAN"]["error"][r] == pytest.approx(e)


def test_optimise_records_the_method_in_params_provenance(recordings, tmp_path):
    params = tmp_path / "P.toml"
    assert main(["optimise", str(recordings / "train"), "-o", str(params), "--estimators", "LOWPASS",
                 "--patience", "2", "--workers", "1", "--quiet", "--delay", "paper"]) == 0
    assert tomllib.loads(params.read_text())["provenance"]["delay"] == "paper"


def test_optimise_resume_refuses_a_checkpoint_of_the_other_method(recordings, tmp_path, capsys):
    params = tmp_path / "P.toml"
    argv = ["optimise", str(recordings / "train"), "-o", str(params), "--estimators", "LOWPASS",
            "--patience", "2", "--workers", "1", "--quiet"]
    assert main(argv) == 0
    assert main(argv + ["--resume", "--delay", "paper"]) == 2
    assert "delay" in capsys.readouterr().err


def test_demo_prints_the_method(capsys):
    assert main(["demo", "--seconds", "0.3", "--delay", "paper"]) == 0
    assert "paper method" in capsys.readouterr().out


def test_dataset_measures_with_its_method_and_refuses_others():
    takes = [take_from_recording(synthetic_recording(2.2, duration=0.3), "r")]
    for method in metric.METHODS:
        dataset = Dataset(takes, delay_method=method)
        errors, delays = dataset.delays_and_errors("LOWPASS", {})
        est = dataset.estimate(takes[0], "LOWPASS", {})
        assert (delays[0], errors[0]) == delay_and_error(takes[0].reference, est, 100, method)
    with pytest.raises(UserError, match="normalised or paper"):
        Dataset(takes, delay_method="overlap")


def test_objective_counts_the_magnitude_of_the_delay():
    # A lead of 3 samples is as far from the reference as a lag of 3.
    assert raw_objectives([0.1, 0.2], [-3, 4]).tolist() == [0.1, 3.0, 0.2, 4.0]
    result = Evaluation(
        names=["LEADS", "LAGS", "WORSE"], recordings=["r0", "r1"], fmax=[1.0, 2.0], rates=[5000.0] * 2,
        params={}, errors={"LEADS": np.array([1.0, 2.0]), "LAGS": np.array([1.0, 2.0]),
                           "WORSE": np.array([2.0, 3.0])},
        delays={"LEADS": np.array([-3.0, -1.0]), "LAGS": np.array([3.0, 1.0]), "WORSE": np.array([5.0, 2.0])},
        baseline_errors=np.array([1.0, 2.0]), baseline_delays=np.array([2.0, 1.0]))
    assert result.objective["LEADS"] == result.objective["LAGS"] < result.objective["WORSE"]
    assert result.delay_pct("LEADS").tolist() == [-150.0, -100.0]


def test_median_of_undefined_percentages_is_nan_without_a_warning():
    with np.errstate(all="raise"):
        assert np.isnan(finite_median([np.nan, np.nan]))
    assert finite_median([np.nan, 4.0, 1.0, np.inf]) == 2.5

"""Public API of studyapp.estimators: names, describe, create, validation, bad input, bank."""

import numpy as np
import pytest

from studyapp import estimators
from studyapp.errors import InputDataError, ParameterError

ISSUE_TABLE = {
    "BDIFF": {"steps": 1},
    "LOWPASS": {"cutoff_hz": 256},
    "LEASTSQ": {"order": 2, "window": 33},
    "FOAW": {"window": 17, "margin": 1.001e-4},
    "LEVANT": {"c": 19.7, "start": "zero"},
    "LEVANTLP": {"c": 3.6, "cutoff_hz": 293, "start": "zero"},
    "KALPOS": {"q": 0.191, "r_pos": 2e-10, "q_convention": "continuous"},
    "KALMAN": {"q": 108, "r_acc": 6.28e4, "r_pos": 2e-10, "q_convention": "scaled"},
    "KALLEV": {"q": 6.38e4, "r_acc": 195, "r_pos": 2e-10, "c": 100, "q_convention": "scaled", "start": "zero"},
    "KALLEVACC": {"q": 2954, "r_acc": 64.6, "r_pos": 2e-10, "c": 100, "hpf_hz": 20, "q_convention": "scaled",
                  "start": "zero"},
    "KALFOAW": {"q": 77.7, "r_acc": 8.06, "r_pos": 2e-10, "window": 12, "margin": 1e-4, "margin_vel": 0.5,
                "q_convention": "scaled"},
    "KALFOAWACC": {"q": 88.5, "r_acc": 3.85, "r_pos": 2e-10, "window": 12, "margin": 1e-4, "margin_vel": 0.5,
                   "hpf_hz": 20, "q_convention": "scaled"},
    "COMP1": {"cutoff_hz": 317},
    "COMP2": {"lpf_hz": 256, "hpf_hz": 2254},
    "LVT": {},
}


def test_names_are_the_issue_table_in_order():
    assert estimators.names() == list(ISSUE_TABLE)


@pytest.mark.parametrize("name", list(ISSUE_TABLE))
def test_defaults_are_table_1(name):
    d = estimators.describe(name)
    assert {p["name"]: p["default"] for p in d["parameters"]} == pytest.approx(ISSUE_TABLE[name])
    for p in d["parameters"]:
        assert p["allowed"]
        if p["kind"] != "choice":
            assert p["low"] <= p["default"] <= p["high"]
    assert set(d["inputs"]) <= {"position", "acceleration", "velocity"}


def test_inputs_read():
    reads = {n: estimators.describe(n)["inputs"] for n in estimators.names()}
    assert reads["LVT"] == ["velocity"]
    for n in ("KALMAN", "KALLEVACC", "KALFOAWACC", "COMP1", "COMP2"):
        assert "acceleration" in reads[n]
    for n in ("BDIFF", "LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS", "KALLEV", "KALFOAW"):
        assert reads[n] == ["position"]


@pytest.mark.parametrize(
    "name, params, fragment",
    [
        ("LOWPASS", {"cutoff_hz": 0.1}, "'cutoff_hz' = 0.1: allowed is a number from 1"),
        ("LOWPASS", {"cutoff_hz": 3000}, "0.45 * rate"),  # 3000 Hz is above 0.45 * 5000
        ("LEASTSQ", {"window": 2, "order": 2}, "'window' = 2: allowed is an integer above order = 2"),
        ("LEASTSQ", {"window": 3.5}, "'window' = 3.5: allowed is an integer"),
        ("KALMAN", {"q_convention": "bogus"}, "allowed is one of 'eq19', 'scaled', 'continuous'"),
        ("LEVANT", {"start": "last"}, "allowed is one of 'zero', 'first'"),
        ("FOAW", {"window": 1}, "'window' = 1: allowed is an integer from 2 to 256"),
        ("KALMAN", {"qq": 1}, "KALMAN has no parameter 'qq'"),
        ("LEVANT", {"c": float("nan")}, "'c' = nan"),
    ],
)
def test_bad_parameters_name_the_parameter_and_the_range(name, params, fragment):
    with pytest.raises(ParameterError) as err:
        estimators.create(name, 5000, **params)
    message = str(err.value)
    assert name in message or "rate" in message
    assert "\n" not in message
    if fragment != "0.45 * rate":
        assert fragment in message
    else:
        assert "2450" in message  # the cap at this rate is stated as a number


def test_rate_range():
    for bad in (999, 96_001, "fast"):
        with pytest.raises(ParameterError, match="rate"):
            estimators.create("BDIFF", bad)
    estimators.create("BDIFF", 1000)
    estimators.create("BDIFF", 96_000)


def test_unknown_estimator():
    with pytest.raises(ParameterError, match="unknown estimator 'NOPE': allowed are BDIFF"):
        estimators.create("NOPE", 5000)


def test_missing_input_is_named():
    with pytest.raises(InputDataError, match="KALMAN reads acceleration"):
        estimators.create("KALMAN", 5000).process(np.zeros(10))


def test_bad_samples_are_held_and_never_poison_later_output():
    rate = 5000.0
    x = np.linspace(0, 0.01, 400)
    clean = estimators.create("LOWPASS", rate).process(x)
    dirty = x.copy()
    dirty[100] = np.nan
    dirty[200] = np.inf
    est = estimators.create("LOWPASS", rate)
    out = est.process(dirty)
    assert np.all(np.isfinite(out))
    assert est.bad_samples == 2
    # holding the last good sample is the same as feeding it explicitly
    held = x.copy()
    held[100] = x[99]
    held[200] = x[199]
    np.testing.assert_array_equal(out, estimators.create("LOWPASS", rate).process(held))
    # the effect of the bad samples decays: the tail matches the clean run closely
    assert np.max(np.abs(out[-50:] - clean[-50:])) < 1e-3 * np.max(np.abs(clean))


def test_reset_restarts():
    est = estimators.create("LEASTSQ", 5000)
    x = np.cumsum(np.random.default_rng(1).normal(size=300)) * 1e-5
    first = est.process(x)
    est.reset()
    np.testing.assert_array_equal(first, est.process(x))


def test_bank_equals_each_estimator_alone():
    rate = 5000.0
    rng = np.random.default_rng(2)
    n = 2000
    x = np.cumsum(rng.normal(size=n)) * 1e-5
    a = rng.normal(size=n)
    v = rng.normal(size=n)
    names = estimators.names()
    bank = estimators.Bank(rate, names)
    out = np.concatenate([bank.process(x[:700], a[:700], v[:700]), bank.process(x[700:], a[700:], v[700:])], axis=1)
    for i, name in enumerate(names):
        alone = estimators.create(name, rate).process(x, a, v)
        np.testing.assert_array_equal(out[i], alone, err_msg=name)

"""The measurement scripts of issue 11 (scripts/recalibration_trials.py, scripts/model_figures.py)."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from studyapp.model import calibration
from tests.figure_checks import text_overlaps, texts_outside

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def load(name):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_shipped_trial_is_issue_11s_calibration():
    """The script records issue 11's levers on the rigid 1 kg handle (shipped 2026-11-23 to 2026-11-25)."""
    trials = load("recalibration_trials")
    shipped = dict(trials.BASE, **trials.SHIPPED)
    assert (shipped["f0"], shipped["beta"], shipped["s"], shipped["mic"]) == (440.0, 0.25, 1.2, 0.02)
    assert shipped["mass"] == 1.0 and (shipped["speed"], shipped["dwell"]) == (0.04, 0.1)
    assert shipped["f0"] == calibration.F0 and shipped["mic"] == calibration.CONTACT_MIC_GAIN
    assert [t for t in trials.TRIALS if t[2] is trials.SHIPPED]


def test_constant_acceleration_strokes_against_their_closed_form():
    trials = load("recalibration_trials")
    rate, amplitude, speed, accel, dwell = 5000.0, 0.008, 0.08, 50.0, 0.1
    x = trials.constant_acceleration_strokes(rate, 2.0, amplitude, speed, accel, dwell)
    v = np.diff(x) * rate
    a = np.diff(v) * rate
    # the first stroke goes 0 -> +A, the next ones between +-A, within a sample's travel
    assert x.max() == pytest.approx(amplitude, abs=speed / rate)
    assert x.min() == pytest.approx(-amplitude, abs=speed / rate)
    assert np.abs(v).max() == pytest.approx(speed, rel=1e-9)
    # the onset: constant acceleration for speed / accel seconds
    ramp = int(round(speed / accel * rate))
    np.testing.assert_allclose(a[: ramp - 1], accel, rtol=1e-9)
    # the dwell: at rest at +A
    stroke = int(round((speed / accel + (amplitude - speed**2 / accel) / speed + speed / accel) * rate))
    np.testing.assert_allclose(v[stroke + 1:stroke + int(dwell * rate) - 1], 0.0, atol=1e-9)


def test_spectrogram_figure_has_no_overlapping_texts():
    figures = load("model_figures")
    rng = np.random.default_rng(0)
    n = int(figures.STEP_SECONDS * figures.RATE)
    parts = [rng.standard_normal(n) * 1e-3 * (k + 1) for k in range(len(figures.STEPS))]
    fig = figures.spectrogram_figure("LVT", 12.1, parts)
    assert text_overlaps(fig) == [] and texts_outside(fig) == []
    assert len(fig.axes[0].texts) == len(figures.STEPS)

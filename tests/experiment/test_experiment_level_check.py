"""The headphone level check is calibrated to the stimulus: a calibration page without ``level_dbfs`` gets the
tone whose RMS is the bowed string's typical RMS at the protocol's F_max, computed by the model's function (so it
follows the model), stated on the page; an explicit level stays as written."""

import math

import numpy as np
import pytest

from studyapp.experiment import level_check
from studyapp.experiment.protocol import load_protocol, parse_protocol
from studyapp.experiment.schedule import build_schedule
from studyapp.model.stimulus_level import short_term_rms_dbfs, tone_peak_dbfs
from tests.experiment.test_experiment_cli import ROOT

SINCLAIR = ROOT / "protocols" / "sinclair2014.toml"
ADJUSTMENT_ONLY = """
[study]
name = "adjust"
tasks = ["adjustment"]
seed = 1

[apparatus]
rate = 5000.0

[[pages]]
kind = "calibration"
text = "Put the headphones on."
tone_hz = 500.0
{level}

[adjustment]
conditions = ["LVT"]
trials = 1
ceiling = 40.0
decades = 2.0
instructions = "Turn the knob."
"""


def _calibration_page(protocol):
    steps, _ = build_schedule(protocol, 0)
    (page,) = [s.page for s in steps if s.page is not None and s.page.kind == "calibration"]
    return page


def test_short_term_rms_is_the_closed_form_for_a_sine_and_ignores_a_burst():
    rate = 48000.0
    t = np.arange(int(2 * rate)) / rate
    x = 0.2 * np.sin(2 * np.pi * 440.0 * t)
    x[:4800] *= 10  # a loud 100 ms burst does not move the median
    assert short_term_rms_dbfs(x, rate) == pytest.approx(20 * math.log10(0.2 / math.sqrt(2)), abs=0.01)
    assert tone_peak_dbfs(-30.0) == pytest.approx(-30.0 + 20 * math.log10(math.sqrt(2)))


def test_the_sinclair_level_check_is_the_rating_strings_typical_level():
    protocol = load_protocol(SINCLAIR)
    assert level_check.stimulus_fmax(protocol) == (1.0, "rating")
    page = _calibration_page(protocol)
    rms, fmax, task = level_check.stimulus_rms_dbfs(protocol)
    assert -65 < rms < -45 and (fmax, task) == (1.0, "rating")  # the chain's gain: linear up to 10.4 N
    assert page.level_dbfs == pytest.approx(rms + 3.01, abs=0.01)
    assert f"{rms:.1f} dBFS RMS" in page.note and "F_max = 1 N" in page.note
    assert "dBFS" not in page.text and "F_max" not in page.text  # the participant's page (issue 31 item 10)


def test_the_level_follows_the_model(monkeypatch):
    protocol = parse_protocol(ADJUSTMENT_ONLY.format(level=""), "adjust.toml")
    asked = []

    def model(rate, gesture, fmax, conditions, seed=0):
        asked.append((rate, gesture, fmax, dict(conditions)))
        return -41.5

    monkeypatch.setattr(level_check, "typical_rms_dbfs", model)
    page = _calibration_page(protocol)
    assert asked == [(5000.0, "strokes", pytest.approx(4.0), {"LVT": {}})]  # the knob's middle: 40 N x 10^-1
    assert page.level_dbfs == pytest.approx(-41.5 + 3.01, abs=0.01) and "-41.5 dBFS RMS" in page.note


def test_an_explicit_level_stays_as_written(monkeypatch):
    monkeypatch.setattr(level_check, "typical_rms_dbfs", lambda *a, **k: pytest.fail("computed"))
    page = _calibration_page(parse_protocol(ADJUSTMENT_ONLY.format(level="level_dbfs = -26.0"), "adjust.toml"))
    assert page.level_dbfs == -26.0 and page.text == "Put the headphones on."

"""Breakdown while bowing (issue 20, targets 4a-4c): sinclair2014's conditions on strokes, at 5 kHz."""

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from studyapp.model import calibration, stability
from studyapp.model.breakdown import breakdown_fmax, is_broken
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.simulate import simulate

RATE = 5000.0
PROTOCOL = tomllib.loads((Path(__file__).parents[2] / "protocols" / "sinclair2014.toml").read_text())
TABLE1 = PROTOCOL["estimators"]
CONDITIONS = PROTOCOL["adjustment"]["conditions"]
POSITION = ["LOWPASS", "LEASTSQ", "FOAW", "LEVANT", "LEVANTLP", "KALPOS"]


def estimators(source):
    return {} if source in ("LVT", "TRUE") else {source: TABLE1.get(source, {})}


def fmax(source, seed, tolerance=0.02):
    return breakdown_fmax(source, seed=seed, tolerance=tolerance, estimators=estimators(source))


def band_db(audio, rate=RATE, low=100.0, high=400.0):
    sos = signal.butter(4, [low, high], "bandpass", fs=rate, output="sos")
    y = signal.sosfilt(sos, audio)[int(0.25 * rate):]
    return 10.0 * np.log10(np.mean(y * y))


def test_the_protocols_adjustment_conditions_are_the_papers():
    assert set(CONDITIONS) == set(POSITION) | {"KALLEV", "KALFOAW", "LVT"}


@pytest.mark.slow
@pytest.mark.parametrize("source", CONDITIONS)
def test_4a_every_condition_breaks_down_while_bowing_alike_over_seeds(source):
    levels = [fmax(source, seed, tolerance=0.05) for seed in range(5)]
    assert all(0.3 <= f <= 40.0 for f in levels), levels
    assert max(levels) / min(levels) <= 1.5, levels


@pytest.mark.slow
def test_4b_lvt_reaches_half_again_beyond_every_position_estimator_and_true_twice_lvt():
    lvt = float(np.median([fmax("LVT", s, 0.05) for s in range(5)]))
    assert 5.0 <= lvt <= 15.0
    for name in POSITION:
        median = float(np.median([fmax(name, s, 0.05) for s in range(5)]))
        assert lvt >= 1.5 * median, (name, median, lvt)
    true = fmax("TRUE", 0, 0.05)  # TRUE reads no sensor: every seed is the same run
    assert math.isinf(true) or true >= 2.0 * lvt


@pytest.mark.slow
@pytest.mark.parametrize("source, rise", [("LVT", 10.0), ("LOWPASS", 4.0), ("KALPOS", 4.0), ("LEVANT", 3.5),
                                          ("FOAW", 4.0)])
def test_4c_breakdown_is_heard_and_nothing_is_flagged_below_it(source, rise):
    """The audio's 100-400 Hz level rises by ``rise`` dB from 0.8 x to 1.25 x breakdown, seeds 0-9; at 0.8 x the
    string is at its pitch within 1 % and the live monitor raises no stability event.

    With issue 42's LVDT (2026-11-29, seeds 0-9) the rises are LEVANT 3.87-4.22 dB (5.3-5.6 on seeds 0-2 with
    the white LVDT, hence 4.0 then), LOWPASS 4.76-5.14, KALPOS 4.91-5.22, FOAW 4.34-4.68."""
    for seed in range(10):
        level = fmax(source, seed, tolerance=0.05)
        db = []
        for fraction in (0.8, 1.25):
            rec = simulate(fraction * level, rate=RATE, duration=5.0, source=source, gesture="strokes", seed=seed,
                           estimators=estimators(source))
            db.append(band_db(rec.columns["audio"]))
            if fraction == 0.8:
                from studyapp.model.bowing_reference import pitch

                assert pitch(rec.columns["string_velocity"][int(0.25 * RATE):], RATE) == pytest.approx(
                    calibration.F0, rel=0.01)
                assert not rec.meta["broken"], (seed, level)
        assert db[1] - db[0] >= rise, (seed, level, db)


@pytest.mark.parametrize("source", ["LVT", "LOWPASS"])
def test_the_live_monitor_agrees_with_the_trial_verdict(source):
    """The monitor the participant and the live engine read flags at 1.25 x a trial's breakdown, not at 0.8 x."""
    level = fmax(source, 0, tolerance=0.05)
    for fraction, expect in ((0.8, False), (1.25, True)):
        loop = ClosedLoop(LoopConfig(rate=RATE, estimators=estimators(source), source=source,
                                     fmax=fraction * level, audio=False))
        flags = []
        for _ in range(25):
            loop.run(1000)
            flags.append(loop.monitor.broken)
        assert any(flags[5:]) == expect and all(flags[-5:]) == expect, (fraction, flags)


def test_the_trial_verdict_is_trues_band_level_plus_six_db(monkeypatch):
    """A trial is broken when its band level passes RISE times TRUE's at the same F_max (monkeypatched RISE)."""
    assert not is_broken("LOWPASS", 2.0, estimators=estimators("LOWPASS"))
    monkeypatch.setattr(stability, "RISE", 0.5)
    assert is_broken("LOWPASS", 2.0, estimators=estimators("LOWPASS"))


def test_holding_is_judged_by_the_oscillation_criterion():
    assert not is_broken("LVT", 0.01, gesture="hold", duration=2.0)
    loop = ClosedLoop(LoopConfig(rate=RATE, source="LVT", fmax=1.0, gesture="hold", audio=False))
    assert loop.monitor.reference is None
    loop.set_gesture("strokes")
    assert loop.monitor.reference is not None and loop.monitor.reference() > 0.0

"""Perception floors of the bowing verdict (issue 42, item 2): a band counts as broken only above the least level a
person could feel or hear in it, whatever TRUE's level there.

Before the floors, a vanishing reference made any excess "broken": LEVANT at 48 kHz broke at the 0.05 N floor
because its upper band held 0.005 mm/s against TRUE's 0.002.
"""

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy import signal

from studyapp.estimators.at_rate import table1
from studyapp.experiment import level_check
from studyapp.experiment.protocol import load_protocol
from studyapp.model import breakdown, contact_mic, perception_floors as pf, stability
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.stimulus_level import STIMULUS_GAIN

ROOT = Path(__file__).resolve().parents[2]
RATES = (1000.0, 5000.0, 6000.0, 22050.0, 48000.0, 96000.0)
# ISO 226:2003 Table 1, T_f (dB SPL), typed from the standard
ISO_226 = {20: 78.5, 31.5: 59.5, 50: 44.0, 100: 26.5, 250: 11.4, 400: 6.2, 1000: 2.4, 2000: -1.3, 2500: -4.2,
           3150: -6.0, 4000: -5.4, 5000: -1.5, 8000: 12.6, 10000: 13.9, 12500: 12.3}


def test_the_hearing_threshold_is_iso_226s_table():
    table = dict(pf.THRESHOLD)
    assert len(table) == 29 and min(table) == 20.0 and max(table) == 12500.0
    for f, t in ISO_226.items():
        assert table[f] == t


def test_the_felt_floor_is_the_grasped_pacinian_minimum_as_an_rms_velocity():
    d_peak = 0.1e-6 * 10 ** (-18.5 / 20)  # Bolanowski et al. 1988's -20 dB re 1 um, less Brisben et al.'s 18.5 dB
    assert pf.felt_floor() == pytest.approx(2 * math.pi * 250.0 * d_peak / math.sqrt(2), rel=1e-12)
    assert pf.felt_floor() == pytest.approx(1.3201e-5, rel=1e-4)


def test_a_heard_floor_is_the_threshold_through_the_contact_microphone_in_closed_form():
    f = 1000.0
    gain = 10 ** (-33 / 20) * 0.02 * 2 * math.pi * f * f * f / math.sqrt(f ** 4 + 60.0 ** 4)
    assert pf.FULL_SCALE_SPL_DB == pytest.approx(80.0 + 55.1)
    assert pf.heard_velocity(f, 2.4) == pytest.approx(10 ** ((2.4 - 135.1) / 20) / gain, rel=1e-12)


@pytest.mark.parametrize("f, threshold", [(400.0, 6.2), (4000.0, -5.4)])
def test_a_sine_at_the_heard_floor_plays_at_the_threshold(f, threshold):
    """The model's own contact microphone (its digital filter, by scipy) and stimulus gain put a handle sine of the
    heard floor's RMS at the ISO 226 threshold in dB SPL."""
    rate = 48000.0
    v = pf.heard_velocity(f, threshold)
    t = np.arange(int(rate)) / rate
    accel = v * math.sqrt(2) * 2 * math.pi * f * np.cos(2 * math.pi * f * t)  # d/dt of v sqrt(2) sin(2 pi f t)
    p = contact_mic.params(rate)
    audio = STIMULUS_GAIN * signal.lfilter(p[:3], [1.0, p[3], p[4]], accel)[int(rate) // 2:]
    spl = 20 * math.log10(math.sqrt(np.mean(audio ** 2))) + 135.1
    assert spl == pytest.approx(threshold, abs=0.1)


def test_each_band_takes_its_most_sensitive_frequency():
    heard = lambda f, t: pf.heard_velocity(f, t)  # noqa: E731
    assert stability.band_floor(5000.0) == pytest.approx(heard(400.0, 6.2))  # heard below the felt floor
    assert stability.band_floor(5000.0) < pf.felt_floor()
    assert stability.hiss_floor(48000.0) == pytest.approx(heard(4000.0, -5.4))
    assert stability.hiss_floor(6000.0) == pytest.approx(heard(2500.0, -4.2))  # the band is 2.5-2.7 kHz there
    assert stability.hiss_floor(5000.0) is None


def _monitor_broken(rate, band, reference, hiss, hiss_reference):
    m = stability.StabilityMonitor(rate, reference=lambda: reference)
    m.hiss_reference = lambda: hiss_reference
    m.state[stability.MS_BAND_MS] = band ** 2
    m.state[stability.MS_HISS_MS] = (hiss or 0.0) ** 2
    return m.judge()


def _trial_broken(monkeypatch, rate, band, reference, hiss, hiss_reference):
    """``breakdown``'s block verdict on constructed levels (the loop's run and TRUE's run replaced)."""
    monkeypatch.setattr(breakdown, "_bowing_measures", lambda block, r: (band, hiss, 440.0))
    monkeypatch.setattr(breakdown, "_true_bowing", lambda *a: (reference, hiss_reference, 440.0))
    loop = SimpleNamespace(rate=rate, fault=None, run=lambda n: {}, string=SimpleNamespace(f0=440.0))
    return breakdown._broken(loop, "strokes", 1.0, 1.0, 0)


@settings(max_examples=60, deadline=None)
@given(rate=st.sampled_from(RATES), below=st.floats(0.0, 0.999), hiss_below=st.floats(0.0, 0.999),
       tiny=st.floats(1e-6, 0.4))
def test_no_band_below_its_floor_is_broken_at_any_rate(rate, below, hiss_below, tiny):
    floors = (stability.band_floor(rate), stability.hiss_floor(rate))
    band = below * floors[0]
    hiss = None if floors[1] is None else hiss_below * floors[1]
    reference = tiny * band / stability.RISE  # TRUE's levels far below: the ratio alone says "broken"
    hiss_reference = None if hiss is None else tiny * hiss / stability.RISE
    for factor in (stability.RISE, stability.RELEASE):
        assert not stability.bowing_over(band, reference, hiss, hiss_reference, factor, floors)
    assert not _monitor_broken(rate, band, reference, hiss, hiss_reference)
    with pytest.MonkeyPatch.context() as mp:
        assert not _trial_broken(mp, rate, band, reference, hiss, hiss_reference)


@pytest.mark.parametrize("rate", RATES)
def test_a_band_above_its_floor_and_over_true_is_broken(monkeypatch, rate):
    floors = (stability.band_floor(rate), stability.hiss_floor(rate))
    band = 2 * floors[0]
    assert _monitor_broken(rate, band, band / 3, None, None)
    assert _trial_broken(monkeypatch, rate, band, band / 3, None, None)
    if floors[1] is not None:  # the upper band alone
        hiss = 2 * floors[1]
        assert _monitor_broken(rate, band, band, hiss, hiss / 3)
        assert _trial_broken(monkeypatch, rate, band, band, hiss, hiss / 3)


def test_levants_hiss_at_48_khz_is_far_above_its_heard_floor():
    """Issue 42 item 4's 0.005 mm/s: the model's contact microphone plays it tens of dB above the threshold of
    hearing, so no absolute floor excuses it (docs/model.md, "Breakdown while bowing")."""
    rate = 48000.0
    loop = ClosedLoop(LoopConfig(rate=rate, estimators={"LEVANT": table1("LEVANT", rate, "seconds")},
                                 source="LEVANT", fmax=0.05, gesture="strokes", seed=0, audio=False), judge=False)
    block = loop.run(int(1.5 * rate))
    hiss = stability.hiss_level(block["velocity_true"], rate, int(0.25 * rate))
    assert 2e-6 < hiss < 2e-5
    assert 20 * math.log10(hiss / stability.hiss_floor(rate)) > 40.0


def test_the_listening_anchor_is_the_level_checks_tone():
    """The floors' one copied figure, sinclair2014's level check tone, against the model that computes it."""
    rms, fmax, task = level_check.stimulus_rms_dbfs(load_protocol(ROOT / "protocols" / "sinclair2014.toml"))
    assert (fmax, task) == (1.0, "rating")
    assert pf.TONE_RMS_DBFS == pytest.approx(rms, abs=0.3)

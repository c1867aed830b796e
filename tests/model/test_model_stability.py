"""The stability monitor's criterion (stability.py), pinned on synthetic signals and on the loop."""

import numpy as np
import pytest
from scipy import signal

from studyapp.model import stability
from studyapp.model.breakdown import breakdown_fmax, is_broken
from studyapp.model.loop import ClosedLoop, LoopConfig

RATE = 5000.0


def judge(friction):
    m = stability.StabilityMonitor(RATE)
    level, cv = m.measure(friction)
    return m, level, cv


def test_square_oscillation_between_minus_and_plus_fmax_is_broken():
    t = np.arange(int(2 * RATE)) / RATE
    m, level, cv = judge(np.sign(np.sin(2 * np.pi * 168.0 * t)))
    # a +-1 square wave has RMS 1; the 40 Hz high-pass barely touches it at 168 Hz
    assert m.level == pytest.approx(1.0, abs=0.05)
    assert m.cv < 0.05
    assert m.broken
    # the onset itself is an envelope change: the verdict comes about a second after it starts
    assert cv[int(0.5 * RATE)] > stability.CV_MAX > cv[int(1.5 * RATE)]


def test_one_signed_friction_with_ripple_is_healthy():
    t = np.arange(int(RATE)) / RATE
    saw = (t * 147.0) % 1.0
    friction = 0.7 + 0.25 * (saw - 0.5)  # friction opposing the stroke with a ripple at the period
    m, level, cv = judge(friction)
    assert m.level == pytest.approx(0.25 / np.sqrt(12), rel=0.1)  # RMS of the sawtooth ripple
    assert not m.broken


def test_narrow_band_noise_is_not_an_oscillation():
    rng = np.random.default_rng(0)
    sos = signal.butter(2, [150.0, 190.0], btype="band", fs=RATE, output="sos")
    noise = signal.sosfilt(sos, rng.standard_normal(int(4 * RATE)))
    noise *= 0.6 / noise[int(RATE):].std()
    m, level, cv = judge(noise)
    assert m.level > stability.LEVEL_MIN  # large ...
    assert m.cv > stability.CV_MAX  # ... but its envelope is random (Rayleigh: cv about 0.52 unsmoothed)
    assert not m.broken


def test_steady_with_lvt_at_1_newton():
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT", gesture="strokes", audio=False))
    for _ in range(30):
        loop.run(500)
        assert not loop.monitor.broken
        assert loop.monitor.score < 0.3
    loop.set_gesture("hold")
    for _ in range(20):
        loop.run(500)
        assert not loop.monitor.broken


def test_noisy_delayed_source_breaks_down_at_high_fmax():
    loop = ClosedLoop(LoopConfig(estimators={"LOWPASS": {}}, fmax=12.1, source="LOWPASS", gesture="hold", audio=False))
    flags = []
    for _ in range(20):
        b = loop.run(500)
        flags.append(loop.monitor.broken)
    assert any(flags[5:]) and all(flags[-5:])
    # the breakdown is an oscillation of the force between -F_max and +F_max near f0 / (1 - beta)
    f = np.fft.rfftfreq(b["force"].size, 1 / RATE)[np.argmax(np.abs(np.fft.rfft(b["force"] - b["force"].mean())))]
    assert f == pytest.approx(loop.string.f0 / (1 - loop.string.beta), rel=0.1)
    assert np.std(b["force"]) > 0.5 * 12.1


def test_breakdown_is_monotonic_and_ordered_by_delay():
    lowpass = breakdown_fmax("LOWPASS", tolerance=0.1)
    lvt = breakdown_fmax("LVT", tolerance=0.1)
    assert not is_broken("LOWPASS", 0.8 * lowpass) and is_broken("LOWPASS", 1.25 * lowpass)
    # the paper's finding (Fig. 7): the tachometer reaches about twice any estimator's range
    assert lvt > 1.5 * lowpass

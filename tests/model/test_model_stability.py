"""The stability monitor's criterion (stability.py), pinned on synthetic signals and on the loop."""

import numpy as np
import pytest
from scipy import signal

from studyapp.estimators import names as estimator_names
from studyapp.model import calibration, stability
from studyapp.model.breakdown import breakdown_fmax, is_broken
from studyapp.model.loop import ClosedLoop, LoopConfig, make_gesture

RATE = 5000.0
BUZZ = 3e-2  # m/s: the end-effector's buzz in a limit cycle at a few newtons (docs/model.md)
# a buzz above the monitor's f0 / 2 high-pass: the loop mode of the default string, f0 / (1 - beta)
BUZZ_HZ = calibration.F0 / (1.0 - calibration.BOW_POSITION)


def judge(velocity):
    m = stability.StabilityMonitor(RATE)
    level, cv = m.measure(velocity)
    return m, level, cv


def test_steady_buzz_of_the_handle_is_broken():
    t = np.arange(int(2 * RATE)) / RATE
    m, level, cv = judge(BUZZ * np.sin(2 * np.pi * BUZZ_HZ * t))
    # the RMS of a sine; the f0 / 2 high-pass barely touches it at the loop mode
    assert m.level == pytest.approx(BUZZ / np.sqrt(2), rel=0.05)
    assert m.cv < 0.05
    assert m.broken
    # the onset itself is an envelope change: the verdict comes some tenths of a second after it starts
    assert cv[int(0.2 * RATE)] > stability.CV_MAX > cv[int(1.5 * RATE)]


def test_the_same_buzz_a_hundred_times_smaller_is_not():
    t = np.arange(int(2 * RATE)) / RATE
    m, _, _ = judge(0.01 * BUZZ * np.sin(2 * np.pi * BUZZ_HZ * t))
    assert m.cv < 0.05 and not m.broken  # steady, but in m/s too small to be felt or heard


def test_strokes_and_tremor_are_filtered_out():
    n = int(3 * RATE)
    _, stroke, _ = make_gesture("strokes", RATE).block(0, n, RATE)
    _, tremor, _ = make_gesture("hold", RATE).block(0, n, RATE)
    m, level, _ = judge(stroke + tremor)
    assert np.max(level[int(0.5 * RATE):]) < 0.5 * stability.VIBRATION_MIN


def test_narrow_band_noise_is_not_an_oscillation():
    rng = np.random.default_rng(0)
    sos = signal.butter(2, [0.9 * BUZZ_HZ, 1.1 * BUZZ_HZ], btype="band", fs=RATE, output="sos")
    noise = signal.sosfilt(sos, rng.standard_normal(int(4 * RATE)))
    noise *= BUZZ / noise[int(RATE):].std()
    m, level, cv = judge(noise)
    assert m.level > stability.VIBRATION_MIN  # large ...
    assert m.cv > stability.CV_MAX  # ... but its envelope is random (Rayleigh: cv about 0.52 unsmoothed)
    assert not m.broken


@pytest.mark.parametrize("source", estimator_names() + ["LVT", "TRUE"])
def test_a_held_handle_at_ten_millinewtons_is_never_flagged(source):
    """The issue's false alarms: LEVANT and KALMAN read "broken" at 0.05 N and even 0.001 N on some seeds."""
    for seed in range(10):
        assert not is_broken(source, 0.01, gesture="hold", duration=2.0, seed=seed), f"seed {seed}"


@pytest.mark.slow
@pytest.mark.parametrize("source", ["LVT", "LOWPASS", "KALPOS", "LEVANTLP", "FOAW"])
def test_held_breakdown_spreads_by_at_most_one_and_a_half_over_seeds(source):
    levels = [breakdown_fmax(source, gesture="hold", tolerance=0.05, seed=seed) for seed in range(5)]
    assert np.all(np.isfinite(levels)) and min(levels) > 0.05
    assert max(levels) / min(levels) <= 1.5, levels


def test_steady_with_lvt_at_1_newton():
    loop = ClosedLoop(LoopConfig(fmax=1.0, source="LVT", gesture="strokes", audio=False))
    for _ in range(30):
        loop.run(500)
        assert not loop.monitor.broken
        assert loop.monitor.score < stability.RISE * loop.reference_level()
    loop.set_gesture("hold")
    for _ in range(20):
        loop.run(500)
        assert not loop.monitor.broken


def test_noisy_delayed_source_breaks_down_at_high_fmax_with_the_hand_holding():
    loop = ClosedLoop(LoopConfig(estimators={"LOWPASS": {}}, fmax=12.1, source="LOWPASS", gesture="hold", audio=False))
    flags = []
    for _ in range(20):
        b = loop.run(500)
        flags.append(loop.monitor.broken)
    assert any(flags[5:]) and all(flags[-5:])
    # the breakdown is an oscillation of the force between -F_max and +F_max, and the handle buzzes with it:
    # with a lagging source, the handle bouncing on the stuck string's stiffness, far below the loop mode
    # f0 / (1 - beta) (docs/model.md)
    def peak(x):
        return np.fft.rfftfreq(x.size, 1 / RATE)[np.argmax(np.abs(np.fft.rfft(x - x.mean())))]

    f = peak(b["force"])
    assert f == pytest.approx(peak(b["velocity_true"]), abs=RATE / b["force"].size)
    assert 20.0 < f < 0.5 * loop.string.f0 / (1 - loop.string.beta)
    assert np.std(b["force"]) > 0.5 * 12.1
    assert loop.monitor.level > stability.VIBRATION_MIN


def test_breakdown_is_monotonic_and_ordered_by_delay():
    lowpass = breakdown_fmax("LOWPASS", tolerance=0.1)
    lvt = breakdown_fmax("LVT", tolerance=0.1)
    assert not is_broken("LOWPASS", 0.8 * lowpass) and is_broken("LOWPASS", 1.25 * lowpass)
    # the paper's finding (Fig. 7): the tachometer reaches well beyond the estimators' range
    assert lvt > 1.4 * lowpass


@pytest.mark.slow
@pytest.mark.parametrize("source", ["LVT", "LOWPASS"])
def test_breakdown_is_heard_with_the_hand_holding(source):
    """The audio's 100-400 Hz level at 1.5 x the held breakdown is 10 dB above its level at 0.5 x."""
    level = breakdown_fmax(source, gesture="hold", tolerance=0.05)
    db = []
    for fraction in (0.5, 1.5):
        estimators = {} if source == "LVT" else {source: {}}
        loop = ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source=source, fmax=fraction * level,
                                     gesture="hold", audio=True))
        loop.run(int(RATE))  # settle
        f, p = signal.welch(loop.run(int(4 * RATE))["audio"], fs=RATE, nperseg=4096)
        band = (f >= 100.0) & (f <= 400.0)
        db.append(10.0 * np.log10(np.sum(p[band]) * (f[1] - f[0])))
    assert db[1] - db[0] >= 10.0, db

"""Sensors against the paper's figures (Sec. 4.2): noise RMS within 5%, LVT -3 dB near 500 Hz; the
accelerometer's AC coupling, band and noise against closed forms and scipy."""

import numpy as np
import pytest
from numba import njit
from scipy import signal

from studyapp.model import sensors
from studyapp.model.loop import ClosedLoop, LoopConfig


@pytest.fixture(scope="module")
def held():
    loop = ClosedLoop(LoopConfig(rate=5000.0, fmax=1.0, source="LVT", gesture="strokes", accelerometer=True,
                                 seed=3))
    return loop, loop.run(50_000)


def test_lvdt_noise_and_quantisation(held):
    """The noise about the conditioned position (the true one through its 250 Hz low-pass: test_model_lvdt.py)."""
    loop, b = held
    conditioned = signal.sosfilt(signal.butter(3, 250.0, fs=5000.0, output="sos"), b["position_true"])
    err = b["position"] - conditioned
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(15e-6, rel=0.05)
    lsb = 0.022 / 2 ** 16
    np.testing.assert_allclose(b["position"] / lsb, np.round(b["position"] / lsb), atol=1e-6)


def test_lvt_noise_after_its_500_hz_band(held):
    loop, b = held
    sos = signal.butter(2, 500.0, fs=5000.0, output="sos")
    err = b["velocity_lvt"] - signal.sosfilt(sos, b["velocity_true"])
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(0.115e-3, rel=0.05)


def test_accelerometer_in_the_loop_is_the_sensor_model_on_the_true_acceleration(held):
    """The loop feeds the true acceleration and its 3rd and 4th noise streams (white, low-frequency) to the sensor."""
    loop, b = held
    spec = sensors.SensorSpec()
    rate = loop.rate
    _, _, white, low = (np.random.default_rng(s) for s in np.random.SeedSequence(3).spawn(4))
    w, w_lf = white.standard_normal(b["t"].size), low.standard_normal(b["t"].size)
    rho = spec.acc_lf_pole(rate)
    lf = signal.lfilter([spec.acc_lf_drive(rate)], [1.0, -rho], w_lf)
    coupling = signal.butter(1, spec.acc_corner, btype="high", fs=rate, output="sos")
    expected = signal.sosfilt(coupling, b["acceleration_true"] + lf) + spec.acc_white_noise * w
    np.testing.assert_allclose(b["acceleration"], expected, rtol=0, atol=1e-9)  # at 5 kHz no band limit
    err = b["acceleration"] - b["acceleration_true"]
    assert abs(np.mean(err - spec.acc_white_noise * w)) < 0.01  # no bias: the coupling holds no DC (was 0.05)


@pytest.mark.parametrize("rate", [5000.0, 20000.0, 48000.0])
def test_lvt_minus_3_db_at_500_hz(rate):
    spec = sensors.SensorSpec()
    sec = spec.lvt_section(rate)
    b, a = sec[:3], np.r_[1.0, sec[3:]]
    _, h = signal.freqz(b, a, worN=[100.0, 500.0], fs=rate)
    assert 20 * np.log10(abs(h[1])) == pytest.approx(-3.01, abs=0.05)
    assert abs(h[0]) > 0.99  # flat below


@njit(cache=True)
def _lvt_response(p, s, x, out):
    for k in range(x.shape[0]):
        out[k] = sensors.lvt(p, s, x[k], 0.0)


def test_lvt_measured_transfer_function():
    rate = 5000.0
    p = sensors.SensorSpec().params(rate)
    t = np.arange(int(rate)) / rate
    for f, gain in [(100.0, 1.0), (500.0, 2 ** -0.5), (1000.0, None)]:
        x = np.sin(2 * np.pi * f * t)
        y = np.empty_like(x)
        _lvt_response(p, np.zeros(sensors.N_STATE), x, y)
        measured = np.sqrt(2 * np.mean(y[len(y) // 2:] ** 2))
        analog = 1.0 / np.sqrt(1.0 + (f / 500.0) ** 4)
        if gain is not None:
            assert measured == pytest.approx(gain, abs=0.02)
        assert measured == pytest.approx(analog, abs=0.05)  # the bilinear design follows the analog Butterworth


def test_no_accelerometer_unless_needed():
    loop = ClosedLoop(LoopConfig(estimators={"LOWPASS": {}}, source="LOWPASS"))
    assert np.all(loop.run(500)["acceleration"] == 0.0)
    loop = ClosedLoop(LoopConfig(estimators={"KALMAN": {}}, source="LVT"))
    assert np.std(loop.run(500)["acceleration"]) > 0.1


ACC = sensors.SensorSpec()


def _warp(f, rate):
    """The analog frequency the bilinear transform maps to ``f``."""
    return rate / np.pi * np.tan(np.pi * np.asarray(f, dtype=float) / rate)


def _analog_response(f, rate):
    """|H| of the accelerometer: the analog first-order high-pass times the Butterworth band, at the warped f."""
    fw, fc = _warp(f, rate), _warp(ACC.acc_corner, rate)
    gain = fw / np.hypot(fw, fc)
    if ACC.acc_band < 0.45 * rate:
        gain = gain / np.sqrt(1.0 + (fw / _warp(ACC.acc_band, rate)) ** 4)
    return gain


@njit(cache=True)
def _accelerometer(p, a, noise, noise_lf, out):
    s = np.zeros(sensors.N_STATE)
    for k in range(a.shape[0]):
        out[k] = sensors.accelerometer(p, s, a[k], noise[k], noise_lf[k])


def _at_rest(rate, seed, seconds):
    n = int(seconds * rate)
    rng = np.random.default_rng(seed)
    out = np.empty(n)
    _accelerometer(ACC.params(rate), np.zeros(n), rng.standard_normal(n), rng.standard_normal(n), out)
    return out


@pytest.mark.parametrize("rate", [5000.0, 48000.0])
def test_accelerometer_response_is_ac_coupled_and_band_limited(rate):
    """The compiled sensor's impulse response against the closed form: high-pass at 0.33 Hz, 10 kHz band."""
    n = int(10 * rate)  # 21 coupling time constants: the tail left is below 1e-9
    impulse = np.zeros(n)
    impulse[0] = 1.0
    h = np.empty(n)
    _accelerometer(ACC.params(rate), impulse, np.zeros(n), np.zeros(n), h)
    freqs = np.array([0.1, ACC.acc_corner, 0.7, 1.0, 10.0, 100.0, 1000.0, 5000.0, ACC.acc_band, 15000.0, 20000.0])
    freqs = freqs[freqs < 0.45 * rate]
    measured = np.abs(np.exp(-2j * np.pi * np.outer(freqs, np.arange(n)) / rate) @ h)  # the DTFT at freqs
    np.testing.assert_allclose(measured, _analog_response(freqs, rate), rtol=0, atol=2e-3)
    gain = dict(zip(freqs, measured))
    assert gain[ACC.acc_corner] == pytest.approx(2 ** -0.5, abs=2e-3)  # -3 dB at the corner
    assert gain[1.0] == pytest.approx(0.95, abs=1e-4)  # PCB's range: +-5% from 1 Hz ...
    assert gain[0.7] >= 0.90  # ... and +-10% from 0.7 Hz
    if ACC.acc_band in gain:
        assert gain[ACC.acc_band] == pytest.approx(2 ** -0.5, abs=2e-3)  # -3 dB at 10 kHz


def test_constant_acceleration_decays_with_the_coupling_time_constant():
    rate = 5000.0
    n = int(3 * rate)
    y = np.empty(n)
    _accelerometer(ACC.params(rate), np.ones(n), np.zeros(n), np.zeros(n), y)
    tau = 1.0 / (2 * np.pi * ACC.acc_corner)
    t = np.arange(n) / rate
    np.testing.assert_allclose(y, np.exp(-t / tau), rtol=0, atol=1e-3)
    assert abs(y[-1]) < 0.01  # 6 tau: no DC survives


def test_low_frequency_noise_gain_is_the_sum_of_the_squared_impulse_response():
    for rate in (1000.0, 5000.0, 96000.0):
        rho, hp = ACC.acc_lf_pole(rate), ACC.acc_coupling_section(rate)
        h = np.zeros(int(20 * rate))
        h[0] = 1.0
        h = signal.lfilter([hp[0], hp[1]], [1.0, hp[3]], signal.lfilter([1.0], [1.0, -rho], h))
        assert sensors.lf_gain(rho, hp) == pytest.approx((1 - rho ** 2) * np.sum(h * h), rel=1e-6)


@pytest.mark.parametrize("rate", [5000.0, 48000.0])
def test_accelerometer_noise_at_rest_is_the_papers(rate):
    for seed in range(5):
        y = _at_rest(rate, seed, 60.0)
        assert np.sqrt(np.mean(y * y)) == pytest.approx(0.22, rel=0.03), seed


def test_low_frequency_noise_stands_above_the_white_floor():
    """Welch PSD of 5 x 60 s at rest against the noise model's closed form (analog, one-sided)."""
    rate = 5000.0
    f, psd = signal.welch(np.array([_at_rest(rate, seed, 60.0) for seed in range(5)]), fs=rate, nperseg=1 << 15)
    psd = psd.mean(axis=0)
    fc, fl = ACC.acc_corner, ACC.acc_lf_corner
    white = 2 * (0.22 ** 2 - 0.10 ** 2) / rate
    level = 0.10 ** 2 * (fl + fc) / fl  # the low-pass's variance, before the coupling removes f_c / (f_l + f_c)
    model = white + level * 2 / (np.pi * fl) / (1 + (f / fl) ** 2) * f ** 2 / (f ** 2 + fc ** 2)
    for lo, hi in [(0.3, 1.0), (1.0, 2.0), (2.0, 5.0), (5.0, 20.0), (50.0, 2000.0)]:
        band = (f >= lo) & (f < hi)
        assert psd[band].mean() == pytest.approx(model[band].mean(), rel=0.15), (lo, hi)
    below = (f >= 0.3) & (f < 5.0)
    assert psd[below].mean() > 30 * white


def test_accelerometer_does_not_depend_on_how_the_run_is_cut():
    config = LoopConfig(rate=5000.0, source="LVT", gesture="hold", accelerometer=True, seed=5, audio=False)
    whole = ClosedLoop(config).run(6000)["acceleration"]
    loop = ClosedLoop(config)
    parts = np.concatenate([loop.run(n)["acceleration"] for n in (1, 2999, 1000, 2000)])
    np.testing.assert_array_equal(whole, parts)

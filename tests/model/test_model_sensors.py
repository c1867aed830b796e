"""Sensors against the paper's figures (Sec. 4.2): noise RMS within 5%, LVT -3 dB near 500 Hz."""

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
    loop, b = held
    err = b["position"] - b["position_true"]
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(15e-6, rel=0.05)
    lsb = 0.022 / 2 ** 16
    np.testing.assert_allclose(b["position"] / lsb, np.round(b["position"] / lsb), atol=1e-6)


def test_lvt_noise_after_its_500_hz_band(held):
    loop, b = held
    sos = signal.butter(2, 500.0, fs=5000.0, output="sos")
    err = b["velocity_lvt"] - signal.sosfilt(sos, b["velocity_true"])
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(0.115e-3, rel=0.05)


def test_accelerometer_noise_and_bias(held):
    loop, b = held
    err = b["acceleration"] - b["acceleration_true"]  # at 5 kHz the 10 kHz band needs no filter
    assert np.sqrt(np.var(err)) == pytest.approx(0.22, rel=0.05)
    assert np.mean(err) == pytest.approx(sensors.SensorSpec().acc_bias, abs=4 * 0.22 / np.sqrt(err.size))


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

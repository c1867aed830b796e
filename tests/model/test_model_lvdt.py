"""The LVDT as the instrument it is (sensors.py, issue 42): the conditioner's low-pass against scipy's
3rd-order Butterworth, the noise at rest 15 um RMS at every rate and band-limited by that low-pass, and
the band and noise owned by SensorSpec (the environment's STUDYAPP_LVDT_BAND / _NOISE as their default)."""

import math
import os
import subprocess
import sys

import numpy as np
import pytest
from numba import njit
from scipy import signal

from studyapp.errors import ParameterError
from studyapp.estimators.spec import NYQUIST_FRACTION
from studyapp.model import sensors
from studyapp.model.simulated_device import SimulatedDevice

SPEC = sensors.SensorSpec()


@njit(cache=True)
def _lvdt_run(p, x, noise, noise_adc, out):
    s = np.zeros(sensors.N_STATE)
    for k in range(x.shape[0]):
        out[k] = sensors.lvdt(p, s, x[k], noise[k], noise_adc[k])


def _run(spec, rate, x, seed=None):
    """The LVDT's samples of the true position ``x``: noiseless if ``seed`` is None."""
    n = x.shape[0]
    if seed is None:
        noise = noise_adc = np.zeros(n)
    else:
        noise, noise_adc = (np.random.default_rng(s).standard_normal(n) for s in np.random.SeedSequence(seed).spawn(2))
    out = np.empty(n)
    _lvdt_run(spec.params(rate), np.ascontiguousarray(x, dtype=np.float64), noise, noise_adc, out)
    return out


def _reference_sos(band, rate):
    return signal.butter(3, min(band, NYQUIST_FRACTION * rate), fs=rate, output="sos")


@pytest.mark.parametrize("rate", [1000.0, 5000.0, 48000.0, 96000.0])
@pytest.mark.parametrize("band", [100.0, 250.0, 2000.0])
def test_the_conditioner_low_pass_is_scipys_3rd_order_butterworth(rate, band):
    spec = sensors.SensorSpec(lvdt_band=band)
    first, second = spec.lvdt_sections(rate)
    f = np.geomspace(1.0, 0.49 * rate, 200)
    _, ours_1 = signal.freqz(first[:3], np.r_[1.0, first[3:]], worN=f, fs=rate)
    _, ours_2 = signal.freqz(second[:3], np.r_[1.0, second[3:]], worN=f, fs=rate)
    _, theirs = signal.sosfreqz(_reference_sos(band, rate), worN=f, fs=rate)
    np.testing.assert_allclose(ours_1 * ours_2, theirs, rtol=0, atol=1e-9)


@pytest.mark.parametrize("rate", [5000.0, 48000.0])
def test_the_sampled_position_is_delayed_and_attenuated_as_freqz_says(rate):
    """A sine through the compiled LVDT (no noise; a large amplitude so quantisation is negligible): its gain and
    phase, fitted by least squares on the second half, are the designed filter's at that frequency."""
    t = np.arange(int(rate)) / rate
    sos = _reference_sos(SPEC.lvdt_band, rate)
    for f in (50.0, 160.0, 230.0, 500.0):
        y = _run(SPEC, rate, 5e-3 * np.sin(2 * np.pi * f * t))
        half = slice(t.size // 2, None)
        basis = np.c_[np.sin(2 * np.pi * f * t[half]), np.cos(2 * np.pi * f * t[half])]
        (a, b), *_ = np.linalg.lstsq(basis, y[half] / 5e-3, rcond=None)
        _, h = signal.sosfreqz(sos, worN=[f], fs=rate)
        assert math.hypot(a, b) == pytest.approx(abs(h[0]), abs=2e-3)
        assert math.atan2(b, a) == pytest.approx(np.angle(h[0]), abs=2e-3)
    lag = signal.group_delay((*signal.sos2tf(sos),), w=[1.0], fs=rate)[1][0]
    assert lag == pytest.approx(2.0 / (2 * np.pi * SPEC.lvdt_band) * rate, rel=0.02)  # 2 / w_c at DC


@pytest.mark.parametrize("rate", [1000.0, 5000.0, 48000.0, 96000.0])
def test_the_noise_at_rest_is_15_um_rms_and_band_limited(rate):
    """60 s at rest: the RMS is the paper's 15 um within 2 % (the band-limited noise has about 2 band x 60 s
    = 30 000 independent values at 250 Hz: 0.4 % of spread); its spectrum follows the designed low-pass."""
    n = int(60 * rate)
    y = _run(SPEC, rate, np.zeros(n), seed=7)[int(rate):]
    assert np.sqrt(np.mean(y ** 2)) == pytest.approx(15e-6, rel=0.02)
    f, psd = signal.welch(y, fs=rate, nperseg=min(8192, int(rate)))
    _, h = signal.sosfreqz(_reference_sos(SPEC.lvdt_band, rate), worN=f, fs=rate)
    floor = SPEC.lvdt_adc_noise ** 2 + SPEC.lvdt_lsb ** 2 / 12  # white after the low-pass: the converter's
    expected = 2.0 / rate * (SPEC.lvdt_drive(rate) ** 2 * np.abs(h) ** 2 + floor)
    low = (f > 5.0) & (f < 0.5 * SPEC.lvdt_band)
    np.testing.assert_allclose(np.mean(psd[low]), np.mean(expected[low]), rtol=0.1)
    if rate >= 5000.0:  # where the rate leaves room above the band: the noise is band-limited, not white
        high = f > 4 * SPEC.lvdt_band
        assert np.mean(psd[high]) < 1e-2 * np.mean(psd[low])
        np.testing.assert_allclose(np.mean(psd[high]), np.mean(expected[high]), rtol=0.1)


@pytest.mark.parametrize("rate", [1000.0, 96000.0])
def test_no_band_limit_is_the_white_model(rate):
    white = sensors.SensorSpec(lvdt_band=math.inf)
    y = _run(white, rate, np.zeros(int(20 * rate)), seed=3)
    assert np.sqrt(np.mean(y ** 2)) == pytest.approx(15e-6, rel=0.02)
    f, psd = signal.welch(y, fs=rate, nperseg=256)
    assert np.std(10 * np.log10(psd[1:-1])) < 1.0  # flat: the spread of a Welch estimate of white noise
    x = np.sin(np.arange(1000) / 10.0) * 1e-3
    np.testing.assert_allclose(_run(white, rate, x), x, atol=white.lvdt_lsb)  # no delay


def test_the_loop_records_the_conditioned_position(held_loop):
    """In the closed loop (bowing, 5 kHz): the recorded position minus the true position through the designed
    low-pass is the noise: 15 um RMS, and band-limited (was white, and the true position was not delayed)."""
    b = held_loop
    err = b["position"] - signal.sosfilt(_reference_sos(SPEC.lvdt_band, 5000.0), b["position_true"])
    assert np.sqrt(np.mean(err[5000:] ** 2)) == pytest.approx(15e-6, rel=0.05)
    f, psd = signal.welch(err[5000:], fs=5000.0, nperseg=2048)
    assert np.mean(psd[f > 1000.0]) < 1e-2 * np.mean(psd[(f > 5.0) & (f < 100.0)])


@pytest.fixture(scope="module")
def held_loop():
    from studyapp.model.loop import ClosedLoop, LoopConfig
    loop = ClosedLoop(LoopConfig(rate=5000.0, fmax=1.0, source="LVT", gesture="strokes", seed=3))
    return loop.run(50_000)


def test_the_environment_sets_the_band_and_noise(monkeypatch):
    monkeypatch.delenv(sensors.BAND_VARIABLE, raising=False)
    monkeypatch.delenv(sensors.NOISE_VARIABLE, raising=False)
    assert SimulatedDevice(5000.0).sensor_spec == SPEC
    monkeypatch.setenv(sensors.BAND_VARIABLE, "inf")
    monkeypatch.setenv(sensors.NOISE_VARIABLE, "5e-6")
    spec = SimulatedDevice(5000.0).sensor_spec
    assert (spec.lvdt_band, spec.lvdt_noise) == (math.inf, 5e-6)
    given = sensors.SensorSpec(lvdt_band=1000.0)
    assert SimulatedDevice(5000.0, sensor_spec=given).sensor_spec is given
    for name, bad in ((sensors.BAND_VARIABLE, "wide"), (sensors.BAND_VARIABLE, "-5"), (sensors.NOISE_VARIABLE, "0")):
        monkeypatch.setenv(name, bad)
        with pytest.raises(ParameterError, match=f"{name}={bad!r}"):
            SimulatedDevice(5000.0)
        monkeypatch.delenv(name)


def test_a_bad_environment_value_is_one_line_and_exit_2(tmp_path):
    done = subprocess.run([sys.executable, "-m", "studyapp", "simulate", "--fmax", "1", "--duration", "0.1",
                           "-o", str(tmp_path / "r.npz")], capture_output=True, text=True, timeout=120,
                          env={**os.environ, sensors.BAND_VARIABLE: "wide"})
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "studyapp: error: environment variable STUDYAPP_LVDT_BAND='wide': allowed is a number above 0 or inf"]


# issue 42's target: LEVANT at 48 kHz breaks above 1 N (the white LVDT broke it at the search's 0.05 N bottom on
# every seed: the handle's upper band held its noise at 2.06 x TRUE's); with the conditioner's low-pass it is
# stable at 1 N on held-out seeds and breaks at 2.76-2.8 N (docs/breakdown.md)
@pytest.mark.parametrize("seed", [43, 47])
def test_levant_at_48_khz_is_stable_at_1_n(seed):
    from studyapp.model.breakdown import is_broken

    assert not is_broken("LEVANT", 1.0, rate=48000.0, seed=seed)
    assert not is_broken("LEVANT", 0.05, rate=48000.0, seed=seed)

"""The synthetic stick-slip signal at every rate from 1 to 96 kHz (issue 12: it designed a filter at Nyquist at 1 kHz)."""

import numpy as np
import pytest
from scipy import signal

from studyapp.estimators.spec import NYQUIST_FRACTION
from studyapp.synthetic import LVT_BAND_HZ, LVT_NOISE_MPS, stick_slip


@pytest.mark.parametrize("rate", [1000.0, 1020.0, 1021.0, 2000.0, 5000.0, 96000.0])
def test_lvt_is_the_tachometer_band_or_the_highest_the_rate_allows(rate):
    sig = stick_slip(rate, 1.0)
    assert all(np.isfinite(a).all() and a.shape == (int(rate),) for a in sig.values())
    band = signal.butter(2, min(LVT_BAND_HZ, NYQUIST_FRACTION * rate), fs=rate, output="sos")
    v = sig["velocity_true"]
    expected = signal.sosfilt(band, v, zi=signal.sosfilt_zi(band) * v[0])[0]
    residual = sig["velocity_lvt"] - expected  # the tachometer's noise alone
    assert np.std(residual) == pytest.approx(LVT_NOISE_MPS, rel=0.1)

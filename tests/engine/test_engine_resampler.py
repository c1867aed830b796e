"""The streaming resampler equals scipy.signal.resample_poly on the concatenated stream."""

import numpy as np
import pytest
from scipy.signal import resample_poly

from studyapp.engine.resampler import Resampler, ratio
from studyapp.errors import ParameterError


@pytest.mark.parametrize(
    "in_rate, out_rate",
    [(5000, 48000), (48000, 48000), (44100, 48000), (96000, 44100), (1000, 48000), (20000, 48000)],
)
def test_streamed_output_equals_resample_poly_for_any_block_cuts(in_rate, out_rate):
    rng = np.random.default_rng(in_rate + out_rate)
    x = rng.standard_normal(4000)
    r = Resampler(in_rate, out_rate)
    assert r.up * in_rate == r.down * out_rate
    cuts = np.sort(rng.integers(0, x.size, 60))
    y = np.concatenate([r.process(part) for part in np.split(x, cuts)] + [r.flush()])
    reference = resample_poly(x, r.up, r.down)
    assert y.shape == reference.shape
    np.testing.assert_allclose(y, reference, rtol=0, atol=1e-12)


def test_a_sine_cut_into_tiny_blocks_has_no_click_at_the_edges():
    rate, out = 5000.0, 48000.0
    t = np.arange(5000) / rate
    x = np.sin(2 * np.pi * 220 * t)
    r = Resampler(rate, out)
    y = np.concatenate([r.process(x[i:i + 5]) for i in range(0, x.size, 5)])
    # Past the start-up transient output k is the 220 Hz sine at time k / out.
    k = np.arange(y.size)
    expected = np.sin(2 * np.pi * 220 * k / out)
    steady = slice(2000, y.size)
    assert np.max(np.abs(y[steady] - expected[steady])) < 5e-3  # Kaiser beta 5 pass-band ripple
    # No sample-to-sample step larger than the sine's own largest step.
    assert np.max(np.abs(np.diff(y[steady]))) < 2 * np.pi * 220 / out * 1.01


def test_ratio_is_exact_when_it_can_be_and_bounded_otherwise():
    assert ratio(5000, 48000) == (48, 5)
    assert ratio(44100, 48000) == (160, 147)
    up, down = ratio(4999.3, 48000)
    assert max(up, down) <= 4096
    assert abs(up / down - 48000 / 4999.3) / (48000 / 4999.3) < 1e-6
    with pytest.raises(ParameterError):
        ratio(0, 48000)

"""The Butterworth sections and the sections' filter without scipy.signal equal scipy's, bit for bit (issue 30, item 4).

``butterworth.sos_row`` stands in for ``scipy.signal.butter(..., output="sos")``
and ``biquad.filter_from_rest`` for ``scipy.signal.sosfilt`` on the path of
``studyapp simulate``, which no longer imports scipy.signal (about 50 MB).
scipy is the reference; equality is exact, so no figure computed with them
moves.
"""

import numpy as np
import pytest
from scipy import signal

from studyapp.estimators.biquad import filter_from_rest, section_from_sos
from studyapp.estimators.butterworth import sos_row, sos_rows

RATES = (1000.0, 5000.0, 44100.0, 48000.0, 96000.0, 1234.5)


@pytest.mark.parametrize("rate", RATES)
@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("btype", ["low", "high"])
def test_sections_equal_scipy_bit_for_bit(rate, order, btype):
    rng = np.random.default_rng(int(rate) + order)
    cutoffs = [*(rng.uniform(1e-4, 0.4999, 300) * rate), 0.25 * rate, 0.45 * rate, 50.0, 400.0, 1e-3]
    for f in cutoffs:
        expected = signal.butter(order, f, btype, fs=rate, output="sos")[0]
        got = sos_row(order, f, rate, btype)
        assert np.array_equal(got, expected) and np.array_equal(np.signbit(got), np.signbit(expected)), (f, got,
                                                                                                          expected)


def test_bad_designs_are_refused():
    with pytest.raises(ValueError, match="order 3"):
        sos_row(3, 100.0, 5000.0)
    with pytest.raises(ValueError, match="btype 'band'"):
        sos_row(2, 100.0, 5000.0, "band")
    with pytest.raises(ValueError, match="below rate / 2"):
        sos_row(2, 2500.0, 5000.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_filter_from_rest_equals_sosfilt(seed):
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(20_000) * 10.0 ** rng.uniform(-6, 2)
    sos = np.vstack([signal.butter(2, 50.0, "high", fs=5000.0, output="sos"),
                     signal.butter(2, 400.0, "low", fs=5000.0, output="sos")])
    params = np.concatenate([section_from_sos(row) for row in sos])
    np.testing.assert_array_equal(filter_from_rest(params, x), signal.sosfilt(sos, x))


@pytest.mark.parametrize("rate", [6000.0, 10000.0, 20000.0, 44100.0, 48000.0, 96000.0])
@pytest.mark.parametrize("order", [4, 6, 8])
@pytest.mark.parametrize("btype", ["low", "high"])
def test_even_orders_equal_scipy_section_for_section(rate, order, btype):
    """The bowing verdict's 4th-order upper band (stability.hiss_sos): scipy's zpk2sos pairing and order."""
    for f in (100.0, 2500.0, 0.3 * rate, 0.45 * rate):
        np.testing.assert_array_equal(sos_rows(order, f, rate, btype), signal.butter(order, f, btype, fs=rate,
                                                                                     output="sos"))


def test_odd_orders_above_two_are_refused():
    with pytest.raises(ValueError, match="order 3"):
        sos_rows(3, 100.0, 5000.0)

"""The optimiser's fast runs equal ``Estimator.process`` exactly, for every estimator."""

import numpy as np
import pytest

from studyapp.estimators import create, names
from studyapp.evaluation import kernels
from tests.evaluation.conftest import stick_slip


@pytest.fixture(scope="module")
def signals():
    sig = stick_slip(5000.0, 0.1, seed=5)
    return sig["position"], sig["acceleration"], sig["velocity_lvt"]


@pytest.mark.parametrize("name", names())
def test_fast_run_equals_process(name, signals):
    x, a, v = signals
    expected = create(name, 5000.0).process(x, a, v)
    assert np.array_equal(kernels.run(create(name, 5000.0), x, a, v), expected)


def test_non_finite_input_takes_the_guarded_path(signals):
    x, a, v = (s.copy() for s in signals)
    x[10] = np.nan
    out = kernels.run(create("LOWPASS", 5000.0), x, a, v)
    assert np.all(np.isfinite(out))
    assert np.array_equal(out, create("LOWPASS", 5000.0).process(x, a, v))


@pytest.mark.parametrize("name, column, value", [("KALMAN", 0, 1e30), ("KALMAN", 1, -2e5), ("LVT", 2, 150.0)])
def test_absurd_finite_input_takes_the_guarded_path(signals, name, column, value):
    """Beyond an input's physical bound (1 m, 1e5 m/s^2, 100 m/s) a finite sample is bad too."""
    cols = [s.copy() for s in signals]
    cols[column][10] = value
    out = kernels.run(create(name, 5000.0), *cols)
    assert np.array_equal(out, create(name, 5000.0).process(*cols))
    held = [s.copy() for s in cols]
    held[column][10] = held[column][9]
    assert np.array_equal(out, create(name, 5000.0).process(*held))

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

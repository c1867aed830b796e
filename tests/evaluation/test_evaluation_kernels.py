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


@pytest.mark.parametrize("name", names())
def test_side_by_side_runs_equal_separate_runs(name):
    """Interleaved runs on several recordings give each recording's own run, bit for bit."""
    sigs = [stick_slip(5000.0, 0.1, seed=s) for s in (5, 6, 7)]
    cols = [np.ascontiguousarray(np.stack([s[c] for s in sigs], axis=1))
            for c in ("position", "acceleration", "velocity_lvt")]
    out = kernels.run_many(create(name, 5000.0), *cols)
    for r, s in enumerate(sigs):
        assert np.array_equal(out[r], create(name, 5000.0).process(s["position"], s["acceleration"], s["velocity_lvt"]))


@pytest.mark.parametrize("order, window", [(1, 2), (2, 33), (6, 300)])
def test_leastsq_block_form_equals_its_step(order, window, signals):
    x, a, v = signals
    cols = [np.ascontiguousarray(np.stack([c, c[::-1]], axis=1)) for c in (x, a, v)]
    out = kernels.run_many(create("LEASTSQ", 5000.0, order=order, window=window), *cols)
    for r in range(2):
        expected = create("LEASTSQ", 5000.0, order=order, window=window).process(cols[0][:, r], cols[1][:, r],
                                                                                 cols[2][:, r])
        assert np.array_equal(out[r], expected)


@pytest.mark.parametrize("name", ["KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC"])
def test_hybrid_from_a_kept_front_end_equals_process(name):
    """A hybrid run as its front end's kept output then KALMAN's step is the hybrid, bit for bit,
    for every q and r_acc on the kept front end and after a change of the front end's setting."""
    sigs = [stick_slip(5000.0, 0.1, seed=s) for s in (5, 6)]
    cols = [np.ascontiguousarray(np.stack([s[c] for s in sigs], axis=1))
            for c in ("position", "acceleration", "velocity_lvt")]
    front = {"margin": 3e-5} if "FOAW" in name else {"c": 40.0}
    fronts = {}
    settings = [{}, {"q": 3.0, "r_acc": 0.2}, {"q": 1e6, "r_acc": 1e4}, {"q": 50.0, **front}, {"q": 2.0, **front}]
    for params in settings:
        out = kernels.run_many(create(name, 5000.0, **params), *cols, fronts=fronts)
        for r, s in enumerate(sigs):
            expected = create(name, 5000.0, **params).process(s["position"], s["acceleration"], s["velocity_lvt"])
            assert np.array_equal(out[r], expected)
    assert list(fronts) == [name]

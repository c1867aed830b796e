"""Block output equals streaming output for every estimator, for any split into blocks."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from studyapp import estimators
from studyapp.synthetic import stick_slip

RATE = 5000.0
N = 600
SIGNAL = stick_slip(RATE, N / RATE, seed=5)
X, A, V = SIGNAL["position"], SIGNAL["acceleration"], SIGNAL["velocity_lvt"]
# a few bad samples too: the policy must not depend on where blocks are cut
X, A, V = X.copy(), A.copy(), V.copy()
X[[50, 51, 300]] = [np.nan, np.inf, np.nan]
A[[51, 120]] = [np.nan, -np.inf]
V[[120, 400, 401]] = [np.inf, np.nan, np.nan]


def streamed(name):
    est = estimators.create(name, RATE)
    return np.array([est.step(x, a, v) for x, a, v in zip(X, A, V)]), est.state.copy()


STREAMED, STATES = {}, {}
for _name in estimators.names():
    STREAMED[_name], STATES[_name] = streamed(_name)


@pytest.mark.parametrize("name", estimators.names())
def test_whole_block_equals_per_sample_steps(name):
    est = estimators.create(name, RATE)
    out = est.process(X, A, V)
    np.testing.assert_array_equal(out, STREAMED[name])
    assert np.all(np.isfinite(out))
    # the whole state too: the guard's last finite samples and its count of the 6 samples with a bad input
    np.testing.assert_array_equal(est.state, STATES[name])
    assert est.state[3] == 6


@settings(max_examples=25, deadline=None)
@given(cuts=st.lists(st.integers(min_value=0, max_value=N), max_size=12), name=st.sampled_from(estimators.names()))
def test_any_split_equals_per_sample_steps(cuts, name):
    edges = [0, *sorted(cuts), N]
    est = estimators.create(name, RATE)
    out = np.concatenate([est.process(X[a:b], A[a:b], V[a:b]) for a, b in zip(edges[:-1], edges[1:])])
    np.testing.assert_array_equal(out, STREAMED[name])

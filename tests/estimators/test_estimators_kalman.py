"""KALPOS and KALMAN against filterpy's textbook KalmanFilter (every q convention), and their covariance at the extremes."""

import itertools

import numpy as np
import pytest
from filterpy.common import Q_continuous_white_noise, Q_discrete_white_noise
from filterpy.kalman import KalmanFilter

from studyapp.errors import ParameterError
from studyapp.estimators import create
from studyapp.estimators.dispatch import GUARD
from studyapp.estimators.kalman import KALPOS_STATE, P0_ACCELERATION, P0_VELOCITY
from studyapp.estimators.spec import Q_CONVENTIONS


def unscaled_posterior(state, rate):
    """(mean, covariance) of the posterior in SI units from a KALPOS or KALMAN state slice.

    ``state`` is the kernel's own state (after the input guard); ``len(state)``
    tells the order. P = S^-1 U D U^T S^-1 (estimators/kalman.py's factorised form).
    """
    t = 1.0 / rate
    if len(state) == KALPOS_STATE:
        y = np.array(state[1:3])
        u = np.array([[1.0, state[3]], [0.0, 1.0]])
        d = np.array(state[4:6])
    else:
        y = np.array(state[1:4])
        u = np.array([[1.0, state[4], state[5]], [0.0, 1.0, state[6]], [0.0, 0.0, 1.0]])
        d = np.array(state[7:10])
    s_inv = np.array([1.0, 1.0 / t, 1.0 / (t * t)])[: len(y)]
    us = u * s_inv[:, None]
    return y * s_inv, (us * d) @ us.T


def signals(rate, duration, seed=0):
    """A 3 Hz, 1 cm sine with LVDT-like position noise and a noisy, biased accelerometer."""
    rng = np.random.default_rng(seed)
    n = int(rate * duration)
    t = np.arange(n) / rate
    w = 2 * np.pi * 3.0
    x = 0.01 * np.sin(w * t) + rng.normal(0.0, 1.4e-5, n)
    a = -0.01 * w * w * np.sin(w * t) + 0.3 + rng.normal(0.0, 0.22, n)
    return x, a


def filterpy_q(dim, t, q, convention):
    """Q by filterpy's own functions: eq. 19 as printed, the same times T, or continuous white noise."""
    if convention == "continuous":
        return Q_continuous_white_noise(dim, dt=t, spectral_density=q)
    return Q_discrete_white_noise(dim, dt=t, var=q * (t if convention == "scaled" else 1.0))


def filterpy_reference(name, rate, params, x, a):
    """The unscaled textbook filter: start at [x0, 0, 0] with P0, then predict/update per sample."""
    t = 1.0 / rate
    dim = 2 if name == "KALPOS" else 3
    kf = KalmanFilter(dim_x=dim, dim_z=dim - 1)
    kf.Q = filterpy_q(dim, t, params["q"], params["q_convention"])
    if dim == 2:
        kf.F = np.array([[1.0, t], [0.0, 1.0]])
        kf.H = np.array([[1.0, 0.0]])
        kf.R = np.array([[params["r_pos"]]])
        kf.P = np.diag([params["r_pos"], P0_VELOCITY**2])
    else:
        kf.F = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])
        kf.H = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
        kf.R = np.diag([params["r_pos"], params["r_acc"]])
        kf.P = np.diag([params["r_pos"], P0_VELOCITY**2, P0_ACCELERATION**2])
    kf.x = np.zeros(dim)
    kf.x[0] = x[0]
    v = np.zeros(len(x))
    for k in range(1, len(x)):
        kf.predict()
        kf.update(np.array([x[k]]) if dim == 2 else np.array([x[k], a[k]]))
        v[k] = kf.x[1]
    return v, kf


CASES = [
    ("KALPOS", {}),
    ("KALPOS", {"q": 3e3, "r_pos": 1e-9}),
    ("KALMAN", {}),
    ("KALMAN", {"q": 5e4, "r_acc": 2.0, "r_pos": 5e-11}),
]


@pytest.mark.parametrize("rate", [5000.0, 40000.0])
@pytest.mark.parametrize("convention", Q_CONVENTIONS)
@pytest.mark.parametrize("name,given", CASES)
def test_equals_filterpy_step_by_step(name, given, convention, rate):
    est = create(name, rate, q_convention=convention, **given)
    x, a = signals(rate, 4000 / rate)
    out = est.process(x, a)
    ref, kf = filterpy_reference(name, rate, est.params, x, a)
    assert out[0] == 0.0
    scale = np.sqrt(np.mean(ref**2))
    np.testing.assert_allclose(out, ref, rtol=1e-9, atol=1e-9 * scale)
    mean, cov = unscaled_posterior(est.state[GUARD:], rate)
    np.testing.assert_allclose(mean, kf.x, rtol=1e-9, atol=1e-9 * np.abs(kf.x).max())
    sd = np.sqrt(np.diag(kf.P))
    np.testing.assert_allclose(cov / np.outer(sd, sd), kf.P / np.outer(sd, sd), rtol=0, atol=1e-7)


def test_conventions_differ_by_a_factor_t_on_q():
    rate = 5000.0
    x, a = signals(rate, 0.2)
    scaled = create("KALMAN", rate, q=108.0, q_convention="scaled").process(x, a)
    eq19 = create("KALMAN", rate, q=108.0 / rate, q_convention="eq19").process(x, a)
    np.testing.assert_allclose(scaled, eq19, rtol=1e-12, atol=1e-12 * np.abs(eq19).max())


def test_table_1_defaults_are_the_conventions_they_were_tuned_in():
    """KALPOS's q = 0.191 was tuned with continuous white noise, the third-order family's with q T Gamma Gamma^T."""
    assert create("KALPOS", 5000.0).params["q_convention"] == "continuous"
    for name in ("KALMAN", "KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC"):
        assert create(name, 5000.0).params["q_convention"] == "scaled"


def test_continuous_white_noise_q_is_the_closed_form():
    """KALPOS's Q = q [[T^3/3, T^2/2], [T^2/2, T]]: filterpy's function checked against the closed form."""
    t, q = 1 / 5000.0, 0.191
    expected = q * np.array([[t**3 / 3, t**2 / 2], [t**2 / 2, t]])
    np.testing.assert_allclose(Q_continuous_white_noise(2, dt=t, spectral_density=q), expected, rtol=1e-15)


def test_stream_equals_block():
    rate = 40000.0
    x, a = signals(rate, 0.02)
    block = create("KALMAN", rate).process(x, a)
    est = create("KALMAN", rate)
    stream = np.array([est.step(xi, ai) for xi, ai in zip(x, a)])
    np.testing.assert_array_equal(block, stream)


def test_unknown_convention_is_a_parameter_error():
    with pytest.raises(ParameterError, match="q_convention"):
        create("KALMAN", 5000.0, q_convention="psd")


EXTREMES = [
    (name, q, r_pos, r_acc, conv)
    for name, q, r_pos, r_acc, conv in itertools.product(
        ["KALPOS", "KALMAN"], [1e-9, 1e15], [1e-16, 1.0], [1e-9, 1e12], Q_CONVENTIONS)
    if name == "KALMAN" or r_acc == 1e-9
]


@pytest.fixture(scope="module")
def long_signal():
    rate = 96000.0
    x, a = signals(rate, 1e6 / rate, seed=1)
    return rate, x, a


@pytest.mark.parametrize("name,q,r_pos,r_acc,conv", EXTREMES)
def test_covariance_stays_symmetric_positive_definite_at_96khz(long_signal, name, q, r_pos, r_acc, conv):
    """10^6 samples at 96 kHz; P checked every 50,000 samples.

    P = S^-1 U D U^T S^-1 is symmetric by construction (factored form), so what
    can fail is positive definiteness. It is checked twice: on the unscaled P's eigenvalues and,
    since P's entries span up to 30 orders of magnitude here, on the eigenvalues
    of P normalised by its diagonal (a scale-free test of the same property).
    """
    rate, x, a = long_signal
    params = {"q": q, "r_pos": r_pos, "q_convention": conv}
    if name == "KALMAN":
        params["r_acc"] = r_acc
    est = create(name, rate, **params)
    block = 50_000
    for start in range(0, len(x), block):
        out = est.process(x[start:start + block], a[start:start + block])
        assert np.isfinite(out).all()
        _, cov = unscaled_posterior(est.state[GUARD:], rate)
        assert np.isfinite(cov).all()
        assert np.linalg.eigvalsh(cov).min() > 0.0
        sd = np.sqrt(np.diag(cov))
        assert np.linalg.eigvalsh(cov / np.outer(sd, sd)).min() > 1e-8

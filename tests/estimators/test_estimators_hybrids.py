"""KALLEV, KALLEVACC, KALFOAW, KALFOAWACC: the differentiator chains, the Kalman part, the high-pass."""

import numpy as np
import pytest
import scipy.linalg
import scipy.signal
from filterpy.kalman import KalmanFilter

from studyapp.estimators import create, foaw
from studyapp.estimators.dispatch import GUARD
from studyapp.estimators.hybrids import Z_A
from studyapp.estimators.kalman import P0_ACCELERATION, P0_VELOCITY
from studyapp.estimators.spec import Q_CONVENTIONS
from tests.estimators.test_estimators_kalman import filterpy_q

RATE = 5000.0


def noisy_motion(rate, n, seed=0):
    """A 3 Hz, 1 cm sine with position noise; the true acceleration with noise and a bias."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    w = 2 * np.pi * 3.0
    x = 0.01 * np.sin(w * t) + rng.normal(0.0, 1.4e-5, n)
    a = -0.01 * w * w * np.sin(w * t) + 0.4 + rng.normal(0.0, 0.22, n)
    return x, a


def measurements_seen(name, rate, x, a, **params):
    """The acceleration measurement the hybrid's Kalman filter saw at every step (state slot Z_A)."""
    est = create(name, rate, **params)
    seen = np.empty(len(x))
    for k in range(len(x)):
        est.step(x[k], a[k])
        seen[k] = est.state[GUARD + Z_A]
    return seen


def foaw_pass(rate, window, margin, signal):
    """FOAW on ``signal`` through the FOAW kernel itself (margin_vel may exceed FOAW's own range)."""
    p, size = foaw.build(rate, {"window": window, "margin": margin})
    s = np.zeros(size)
    return np.array([foaw.step(s, p, xi, 0.0, 0.0) for xi in signal])


def highpass(rate, hpf_hz, a):
    """scipy's Butterworth high-pass, started in the steady state of the first sample."""
    sos = scipy.signal.butter(2, hpf_hz, btype="high", fs=rate, output="sos")
    y, _ = scipy.signal.sosfilt(sos, a, zi=scipy.signal.sosfilt_zi(sos) * a[0])
    return y


def kalman_reference(rate, params, x, za):
    """filterpy's textbook KALMAN (Q in the estimator's convention) fed with position and the given acceleration."""
    t = 1.0 / rate
    kf = KalmanFilter(dim_x=3, dim_z=2)
    kf.F = np.array([[1.0, t, t * t / 2], [0.0, 1.0, t], [0.0, 0.0, 1.0]])
    kf.H = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    kf.R = np.diag([params["r_pos"], params["r_acc"]])
    kf.Q = filterpy_q(3, t, params["q"], params["q_convention"])
    kf.P = np.diag([params["r_pos"], P0_VELOCITY**2, P0_ACCELERATION**2])
    kf.x = np.array([x[0], 0.0, 0.0])
    v = np.zeros(len(x))
    for k in range(1, len(x)):
        kf.predict()
        kf.update(np.array([x[k], za[k]]))
        v[k] = kf.x[1]
    return v


def test_kallev_measurement_is_levant_twice():
    x, a = noisy_motion(RATE, 2000)
    for c in (100.0, 7.0):
        first = create("LEVANT", RATE, c=c).process(x)
        second = create("LEVANT", RATE, c=c).process(first)
        np.testing.assert_array_equal(measurements_seen("KALLEV", RATE, x, a, c=c), second)


def test_kallevacc_measurement_is_levant_twice_plus_highpassed_acceleration():
    x, a = noisy_motion(RATE, 2000)
    lev = create("LEVANT", RATE, c=100.0).process(create("LEVANT", RATE, c=100.0).process(x))
    seen = measurements_seen("KALLEVACC", RATE, x, a, hpf_hz=20.0)
    np.testing.assert_allclose(seen, lev + highpass(RATE, 20.0, a), rtol=0, atol=1e-12)


def test_kalfoaw_measurements_are_foaw_twice():
    x, a = noisy_motion(RATE, 1500)
    chain = foaw_pass(RATE, 12, 0.5, foaw_pass(RATE, 12, 1e-4, x))
    np.testing.assert_array_equal(measurements_seen("KALFOAW", RATE, x, a), chain)
    chain = foaw_pass(RATE, 5, 0.02, foaw_pass(RATE, 5, 3e-5, x))
    seen = measurements_seen("KALFOAWACC", RATE, x, a, window=5, margin=3e-5, margin_vel=0.02, hpf_hz=50.0)
    np.testing.assert_allclose(seen, chain + highpass(RATE, 50.0, a), rtol=0, atol=1e-12)


@pytest.mark.parametrize("convention", Q_CONVENTIONS)
@pytest.mark.parametrize("name", ["KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC"])
def test_kalman_part_equals_filterpy_fed_with_the_chain(name, convention):
    x, a = noisy_motion(RATE, 2000)
    est = create(name, RATE, q_convention=convention)
    out = est.process(x, a)
    za = measurements_seen(name, RATE, x, a, q_convention=convention)
    ref = kalman_reference(RATE, est.params, x, za)
    np.testing.assert_allclose(out, ref, rtol=1e-9, atol=1e-9 * np.sqrt(np.mean(ref**2)))


def acceleration_to_velocity_gain(rate, q, r_acc, r_pos, convention):
    """l1 norm of the steady-state KALMAN's impulse response from the acceleration measurement to v.

    From scipy's discrete Riccati solution (on the state [x, T v, T^2 a], where it is well
    conditioned), independent of the estimator's code.
    """
    t = 1.0 / rate
    f = np.array([[1.0, 1.0, 0.5], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]])
    s = np.array([1.0, t, t * t])
    h = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    r = np.diag([r_pos, r_acc * t**4])
    p = scipy.linalg.solve_discrete_are(f.T, h.T, filterpy_q(3, t, q, convention) * np.outer(s, s), r)
    k = p @ h.T @ np.linalg.inv(h @ p @ h.T + r)
    closed = (np.eye(3) - k @ h) @ f
    assert np.abs(np.linalg.eigvals(closed)).max() < 0.999
    col = k[:, 1] * t * t  # the measurement enters as T^2 a
    size = np.abs(col).max()
    gain = 0.0
    while np.abs(col).max() > 1e-16 * size:
        gain += abs(col[1]) / t
        col = closed @ col
    return gain


@pytest.mark.parametrize("rate", [5000.0, 40000.0])
def test_kallev_tracks_a_clean_slow_sine(rate):
    """x = A sin(w t), A = 1 cm, 2 Hz: |x''| = 1.6 m/s^2 and |x'''| = 20 m/s^3, both within C = 100.

    KALMAN is linear in its measurements and its gains do not depend on the data,
    so KALLEV's error is KALMAN's error when fed the exact acceleration, plus the
    filter's response to the error e_a of L(L(x)). After the start-up transient
    (0.5 s, against a filter memory under 0.1 s) the second term is at most
    ||h_a||_1 max|e_a|, with h_a the steady-state impulse response from the
    acceleration measurement to v. The tolerance is that bound, with e_a and
    the exact-acceleration error measured independently (LEVANT twice; KALMAN).
    """
    amp, w = 0.01, 2 * np.pi * 2.0
    n = int(1.5 * rate)
    t = np.arange(n) / rate
    x = amp * np.sin(w * t)
    v_true = amp * w * np.cos(w * t)
    a_true = -amp * w * w * np.sin(w * t)
    est = create("KALLEV", rate)
    out = est.process(x)
    settled = t >= 0.5
    memory = t >= 0.25  # the measurements that can still matter after 0.5 s
    lev = create("LEVANT", rate, c=100.0).process(create("LEVANT", rate, c=100.0).process(x))
    e_a = np.abs(lev - a_true)[memory].max()
    p = est.params
    exact = create("KALMAN", rate, q=p["q"], r_acc=p["r_acc"], r_pos=p["r_pos"]).process(x, a_true)
    bound = (np.abs(exact - v_true)[settled].max()
             + acceleration_to_velocity_gain(rate, p["q"], p["r_acc"], p["r_pos"], p["q_convention"]) * e_a)
    assert bound < 0.05 * amp * w  # the bound itself is a meaningful tolerance: 5 % of the amplitude
    assert np.abs(out - v_true)[settled].max() <= bound


def test_kallevacc_removes_accelerometer_bias():
    """A constant bias from the start, and a second bias step at 0.5 s.

    The high-pass is primed with the first sample, so the first bias never
    reaches the output; the step does, briefly, and is gone once the 20 Hz
    high-pass has settled (time constant 1 / (0.707 * 2 pi 20) = 11 ms; after
    0.3 s what is left of it is e^-27 of the step).
    """
    n = int(1.0 * RATE)
    t = np.arange(n) / RATE
    x, a = noisy_motion(RATE, n)
    bias = 5.0 + np.where(t >= 0.5, 5.0, 0.0)
    clean = create("KALLEVACC", RATE).process(x, a)
    biased = create("KALLEVACC", RATE).process(x, a + bias)
    diff = np.abs(biased - clean)
    assert diff[t < 0.5].max() < 1e-9
    assert diff[(t >= 0.5) & (t < 0.6)].max() > 1e-4  # the step does reach the output at first
    assert diff[t >= 0.8].max() < 1e-9
    # without the high-pass (KALMAN with the same Q and R), the bias stays
    p = create("KALLEVACC", RATE).params
    kal = [create("KALMAN", RATE, q=p["q"], r_acc=p["r_acc"]).process(x, a + b) for b in (0.0, bias)]
    assert np.abs(kal[1] - kal[0])[t >= 0.8].min() > 1e-3


def test_hybrids_stream_equals_block():
    x, a = noisy_motion(40000.0, 600)
    for name in ("KALLEV", "KALLEVACC", "KALFOAW", "KALFOAWACC"):
        block = create(name, 40000.0).process(x, a)
        est = create(name, 40000.0)
        stream = np.array([est.step(xi, ai) for xi, ai in zip(x, a)])
        np.testing.assert_array_equal(block, stream)

"""KALPOS and KALMAN: Kalman filters on a driven-mass model (paper Sec. 5.6, eqs. 16-19).

Model (Bar-Shalom's discrete white-noise acceleration models, paper eq. 18),
sample period T, no input (B = 0):

    KALMAN  state [x, v, a]   F = [[1, T, T^2/2], [0, 1, T], [0, 0, 1]]   Gamma = [T^2/2, T, 1]^T
            measures z = [x, a]:  H = [[1, 0, 0], [0, 0, 1]],  R = diag(r_pos, r_acc)
    KALPOS  state [x, v]      F = [[1, T], [0, 1]]                         Gamma = [T^2/2, T]^T
            measures z = x:       H = [1, 0],                   R = r_pos

    predict  x- = F x,  P- = F P F^T + Q                                 (eqs. 16-17)
    update   K = P- H^T (H P- H^T + R)^-1,  x = x- + K (z - H x-),  P = (I - K H) P-

The output at step k is the velocity of the posterior (after the update).

The process noise Q. The paper's eq. 19 writes Q = Gamma sigma^2 Gamma^T and
calls sigma "the power spectral density"; a spectral density would need a
factor T to become a per-step variance. The paper does not say how Table 1's
Q values were tuned; the first author's public code used two conventions, and
each estimator's default is the one its Table 1 value was tuned in. The
parameter ``q_convention`` chooses:

    "eq19"        Q = q Gamma Gamma^T         the paper's eq. 19 as printed (filterpy's
                                              Q_discrete_white_noise(dim, dt=T, var=q))
    "scaled"      Q = q T Gamma Gamma^T       the authors' third-order filters: the default
                                              of KALMAN and the hybrids
    "continuous"  Q = q int_0^T e^{F s} e_n e_n^T e^{F^T s} ds, continuous white noise of
                  spectral density q on the highest derivative (filterpy's
                  Q_continuous_white_noise(dim, dt=T, spectral_density=q)):
                      KALPOS  q [[T^3/3, T^2/2], [T^2/2, T]]   the authors' KALPOS: its default
                      KALMAN  q [[T^5/20, T^4/8, T^3/6], [T^4/8, T^3/3, T^2/2], [T^3/6, T^2/2, T]]

Numerics. In metres and seconds, at 40-96 kHz the covariance spans some 15
orders of magnitude (Var x ~ 1e-10 m^2, Var a ~ 1e4 m^2/s^4, off-diagonals
with powers of T in between), and the textbook update loses its precision.
The filter therefore runs on the scaled state y = S [x, v, a] with
S = diag(1, T, T^2), i.e. y = [x, T v, T^2 a], all in metres. Then

    F_s = S F S^-1 = [[1, 1, 1/2], [0, 1, 1], [0, 0, 1]]      (constant: binomial-like)
    H_s = e_x for position (R_p unchanged) and e_a for acceleration, the measured
          acceleration entering as T^2 a with R_s = T^4 r_acc,

and the process noise Q_s = S Q S^T, written as a sum of weighted outer
products (``noise``):

    Q_s = q_g g g^T + q_h h h^T + q_e e_x e_x^T
    "eq19", "scaled":  g = [1/2, 1, 1]^T ([1/2, 1]^T for KALPOS), q_g = q T^4 ("eq19")
                       or q T^5 ("scaled"), q_h = q_e = 0
    "continuous":      KALMAN g = [1/6, 1/2, 1]^T, h = [1/2, 1, 0]^T, q_g = q T^5,
                       q_h = q T^5 / 12, q_e = q T^5 / 720;
                       KALPOS g = [1/2, 1]^T, q_g = q T^3, q_h = 0, q_e = q T^3 / 12

(the continuous forms are the U D U^T factors of T^-5 S Q S^T and T^-3 S Q S^T),
and the posterior, mapped back by S^-1, is the unscaled textbook filter's up
to rounding.

Scaling alone is not enough at the ends of the parameter ranges: when one
measurement is far more precise than the process noise (e.g. r_acc / q ~
1e-24), the conditional variances are differences of numbers 1e16 times
larger, and a covariance-form update -- Joseph form included, which we tried
first -- turns P indefinite within 10^6 samples at 96 kHz. The filter
therefore keeps P in factored form, P = U D U^T (U unit upper triangular, D
diagonal): Thornton's weighted Gram-Schmidt time update (P- = W diag(D, q_g,
q_h, q_e) W^T with W = [F_s U | g h e_x]) and Bierman's scalar measurement
update. Every new D is a weighted sum of squares or a D times a ratio of
positive numbers, so P stays symmetric (by construction) and positive
definite; D's entries are the conditional variances, which is exactly what
the subtraction above loses. A noise weight of 0 adds exact zeros, so "eq19"
and "scaled" run the rank-one update they always ran, to the last bit.
Because R is diagonal the two measurements of KALMAN are applied one after
the other (position, then acceleration), which gives the joint update's
posterior. The arithmetic is unrolled (no np.linalg, no allocation).

Bad input is held and counted by the guard (``dispatch.step_guarded``,
``bounds.py``), so the filter only sees positions within 1 m and
accelerations within 1e5 m/s^2. The bound matters: a residual of 1e300 m
overflows the update to inf, then inf - inf = NaN, and NaN never leaves the
state (before the bounds, one such sample made every later output NaN).

Start. At the first sample the filter is set to x = x_0, v = a = 0 and
P_0 = diag(r_pos, (1 m/s)^2, (100 m/s^2)^2) (unscaled; [r_pos, (1 m/s)^2]
for KALPOS), and outputs 0; from the second sample on it predicts and
updates. Ignoring the first acceleration sample keeps the start identical for
KALPOS, KALMAN and the hybrids.

State (KALMAN, ``KALMAN_STATE`` = 10):
``[started, y0, y1, y2, u01, u02, u12, d0, d1, d2]`` (scaled units).
State (KALPOS, ``KALPOS_STATE`` = 6): ``[started, y0, y1, u01, d0, d1]``.
Parameters (KALMAN, ``KALMAN_PARAMS`` = 12):
``[rate, T^2, q_g, r_pos, T^4 r_acc, P0_x, T^2 P0_v, T^4 P0_a, g_0, g_1, q_h, q_e]``.
Parameters (KALPOS, 6): ``[rate, q_g, r_pos, P0_x, T^2 P0_v, q_e]``.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec, Param, q_convention

P0_VELOCITY = 1.0  # m/s: standard deviation of the initial velocity
P0_ACCELERATION = 100.0  # m/s^2: standard deviation of the initial acceleration

KALMAN_STATE = 10
KALPOS_STATE = 6
KALMAN_PARAMS = 12


def q_param(default):
    return Param("q", default, "", 1e-9, 1e15, doc="process noise q (see q_convention)")


def r_pos_param():
    return Param("r_pos", 2e-10, "m^2", 1e-16, 1.0, doc="position measurement covariance R_p")


def r_acc_param(default):
    return Param("r_acc", default, "(m/s^2)^2", 1e-9, 1e12, doc="acceleration measurement covariance R_a")


def noise(rate, params, order):
    """``(q_g, g_0, g_1, q_h, q_e)``: the scaled process noise Q_s of the filter of ``order`` 2 (KALPOS) or 3.

    Q_s = q_g g g^T + q_h h h^T + q_e e_x e_x^T with g = [g_0, g_1, 1] (order 3)
    or [g_0, 1] (order 2) and h = [1/2, 1, 0] (module docstring).
    """
    t = 1.0 / rate
    q = params["q"]
    convention = params["q_convention"]
    if convention == "continuous":
        if order == 2:
            return q * t**3, 0.5, 1.0, 0.0, q * t**3 / 12.0
        return q * t**5, 1.0 / 6.0, 0.5, q * t**5 / 12.0, q * t**5 / 720.0
    q_g = q * t**4 * (t if convention == "scaled" else 1.0)
    return q_g, 0.5, 1.0, 0.0, 0.0


def kalman_params(rate, params):
    """The KALMAN block of a parameter vector (also the head of the hybrids')."""
    t = 1.0 / rate
    r_pos = params["r_pos"]
    q_g, g0, g1, q_h, q_e = noise(rate, params, 3)
    return np.array([
        rate, t * t, q_g, r_pos, t**4 * params["r_acc"],
        r_pos, t * t * P0_VELOCITY**2, t**4 * P0_ACCELERATION**2, g0, g1, q_h, q_e,
    ])


def build_kalpos(rate, params):
    t = 1.0 / rate
    r_pos = params["r_pos"]
    q_g, _, _, _, q_e = noise(rate, params, 2)
    return np.array([rate, q_g, r_pos, r_pos, t * t * P0_VELOCITY**2, q_e]), KALPOS_STATE


def build_kalman(rate, params):
    return kalman_params(rate, params), KALMAN_STATE


@njit(cache=True, inline="always")
def kalman_step(s, p, x, a):
    """One KALMAN step on state ``s[0:10]``, parameters ``p[0:8]``; returns the posterior velocity.

    ``a`` is the acceleration measurement (m/s^2): the accelerometer for
    KALMAN, the differentiators' estimate for the hybrids.
    """
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x
        s[2] = 0.0
        s[3] = 0.0
        s[4] = 0.0
        s[5] = 0.0
        s[6] = 0.0
        s[7] = p[5]
        s[8] = p[6]
        s[9] = p[7]
        return 0.0
    q = p[2]
    g0 = p[8]
    g1 = p[9]
    qh = p[10]
    qe = p[11]
    u01 = s[4]
    u02 = s[5]
    u12 = s[6]
    d0 = s[7]
    d1 = s[8]
    d2 = s[9]
    # predict: y = F_s y with F_s = [[1, 1, 1/2], [0, 1, 1], [0, 0, 1]]
    y0 = s[1] + s[2] + 0.5 * s[3]
    y1 = s[2] + s[3]
    y2 = s[3]
    # P- = W diag(d0, d1, d2, q_g, q_h, q_e) W^T with W = [F_s U | g h e_x],
    # g = [g0, g1, 1]^T, h = [1/2, 1, 0]^T; Thornton's weighted Gram-Schmidt,
    # last row first, gives P- = U D U^T (w0k, w1k: rows 0 and 1 of W, column k)
    w01 = u01 + 1.0
    w02 = u02 + u12 + 0.5
    w12 = u12 + 1.0
    d2n = d2 + q
    u02n = (w02 * d2 + g0 * q) / d2n
    u12n = (w12 * d2 + g1 * q) / d2n
    w02 -= u02n
    w03 = g0 - u02n
    w12 -= u12n
    w13 = g1 - u12n
    d1n = d1 + d2 * w12 * w12 + q * w13 * w13 + qh
    u01n = (w01 * d1 + w02 * w12 * d2 + w03 * w13 * q + 0.5 * qh) / d1n
    w01 -= u01n
    w02 -= u01n * w12
    w03 -= u01n * w13
    w04 = 0.5 - u01n
    d0n = d0 + d1 * w01 * w01 + d2 * w02 * w02 + q * w03 * w03 + qh * w04 * w04 + qe
    # Bierman's update with the position, H = e_0: f = U^T e_0 = [1, u01, u02]
    r = p[3]
    alpha = r + d0n
    b0 = d0n
    d0n *= r / alpha
    v1 = d1n * u01n
    beta = alpha
    alpha += v1 * u01n
    d1n *= beta / alpha
    b1 = v1
    u01_old = u01n
    u01n -= u01n / beta * b0
    b0 += u01_old * v1
    v2 = d2n * u02n
    beta = alpha
    alpha += v2 * u02n
    d2n *= beta / alpha
    lam = u02n / beta
    u02_old = u02n
    u12_old = u12n
    u02n -= lam * b0
    u12n -= lam * b1
    b0 += u02_old * v2
    b1 += u12_old * v2
    e = (x - y0) / alpha
    y0 += b0 * e
    y1 += b1 * e
    y2 += v2 * e
    # Bierman's update with the scaled acceleration T^2 a, H = e_2: f = [0, 0, 1]; U is unchanged
    r = p[4]
    alpha = r + d2n
    e = (a * p[1] - y2) / alpha
    y0 += u02n * d2n * e
    y1 += u12n * d2n * e
    y2 += d2n * e
    d2n *= r / alpha
    s[1] = y0
    s[2] = y1
    s[3] = y2
    s[4] = u01n
    s[5] = u02n
    s[6] = u12n
    s[7] = d0n
    s[8] = d1n
    s[9] = d2n
    return y1 * p[0]


@njit(cache=True, inline="always")
def step_kalman(s, p, x, a, v):
    return kalman_step(s, p, x, a)


@njit(cache=True, inline="always")
def step_kalpos(s, p, x, a, v):
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x
        s[2] = 0.0
        s[3] = 0.0
        s[4] = p[3]
        s[5] = p[4]
        return 0.0
    q = p[1]
    u01 = s[3]
    d0 = s[4]
    d1 = s[5]
    # predict: y = F_s y with F_s = [[1, 1], [0, 1]]; W = [F_s U | g e_x], g = [1/2, 1]^T,
    # weights diag(d0, d1, q_g, q_e)
    y0 = s[1] + s[2]
    y1 = s[2]
    w01 = u01 + 1.0
    d1n = d1 + q
    u01n = (w01 * d1 + 0.5 * q) / d1n
    w01 -= u01n
    w02 = 0.5 - u01n
    d0n = d0 + d1 * w01 * w01 + q * w02 * w02 + p[5]  # p[5] = q_e
    # Bierman's update with the position: f = [1, u01]
    r = p[2]
    alpha = r + d0n
    b0 = d0n
    d0n *= r / alpha
    v1 = d1n * u01n
    beta = alpha
    alpha += v1 * u01n
    d1n *= beta / alpha
    u01_old = u01n
    u01n -= u01n / beta * b0
    b0 += u01_old * v1
    e = (x - y0) / alpha
    s[1] = y0 + b0 * e
    s[2] = y1 + v1 * e
    s[3] = u01n
    s[4] = d0n
    s[5] = d1n
    return s[2] * p[0]


SPEC_KALPOS = EstimatorSpec(
    name="KALPOS", kind=kinds.KALPOS, description="2nd-order Kalman filter [x, v], position measurement.",
    inputs=("position",), params=(q_param(0.191), r_pos_param(), q_convention("continuous")),
    build=build_kalpos, reference="paper Sec. 5.6, eqs. 16-19; Table 1 (Q = 0.191, continuous white noise)",
)
SPEC_KALMAN = EstimatorSpec(
    name="KALMAN", kind=kinds.KALMAN, description="3rd-order Kalman filter [x, v, a], position and acceleration.",
    inputs=("position", "acceleration"),
    params=(q_param(108.0), r_acc_param(6.28e4), r_pos_param(), q_convention("scaled")), build=build_kalman,
    reference="paper Sec. 5.6, eqs. 16-19; Table 1 (Q = 108 with Q = q T Gamma Gamma^T, R_a = 6.28e4)",
)

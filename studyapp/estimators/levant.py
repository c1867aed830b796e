"""LEVANT and LEVANTLP: Levant's two-sliding (super-twisting) differentiator (paper Sec. 5.4).

An observer w follows the position x(t); its rate u is the velocity estimate
(eqs. 8-9: sigma = w - x, sigma_dot = u - x_dot). Levant's control laws
(eqs. 10-12):

    w_dot  = u                                             (10)
    u      = u1 - lambda |w - x|^(1/2) sgn(w - x)          (11)
    u1_dot = -alpha sgn(w - x)                             (12)

converge in finite time to u = x_dot when |x_ddot| <= C, the Lipschitz
constant of x_dot (eq. 13). We use the recommended gains (eqs. 14-15)

    alpha = 1.1 C,   lambda = sqrt(C).

Discretisation (DESIGN.md "Numerical conventions"): explicit Euler with the
sample period T. The observer starts at the first sample, w = x_0, u1 = 0, and
sgn(0) = 0, so the first output is 0. At step k the output is u computed from
the state before the update:

    e  = w - x_k
    u  = u1 - lambda sqrt|e| sgn(e)      -> output
    w  <- w + T u
    u1 <- u1 - T alpha sgn(e)

With sampled input the differentiator is no longer exact: after convergence its
error is O(C T) in u and O(C T^2) in sigma (Levant 1998, Theorem 2), so unlike a
backward difference it improves as the rate rises. The price is switching
noise ("chattering"), which LEVANTLP removes with a 2nd-order Butterworth
low-pass at ``cutoff_hz`` (scipy ``butter(2, cutoff_hz, fs=rate,
output="sos")``, zero initial state, run as in ``biquad.py``).

``levant_core`` is the reusable compiled step on a 3-slot state view
``[started, w, u1]`` (``LEVANT_STATE``); the hybrids KALLEV and KALLEVACC
chain it twice, L(L(x)).

Bad input: handled centrally by ``dispatch.step_guarded`` (a NaN, inf or
out-of-bounds sample, ``bounds.py``, is replaced by the last good one and
counted), so these kernels only ever see finite input within the bounds. The
bound matters here: the observer closes an error e at a rate of about
lambda sqrt(|e|), so after one 1e30 m sample (before the bounds) LEVANT still
read 4e6 m/s two seconds later; after a 1 m sample it is back within 0.1 s
(tests/estimators/test_estimators_extremes.py).

LEVANT state: ``[started, w, u1]``; parameters ``[alpha, lambda, T]``.
LEVANTLP state: ``[started, w, u1, z1, z2]``; parameters ``[alpha, lambda, T, section(5)]``.
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.biquad import butter_section, section_step
from studyapp.estimators.spec import EstimatorSpec, Param, cutoff

LEVANT_STATE = 3


def c_param(default):
    return Param("c", default, "m/s^2", 1e-3, 1e5, doc="Lipschitz constant C (max. acceleration)")


def gains(c):
    """``(alpha, lambda)`` from the Lipschitz constant C (eqs. 14-15)."""
    return 1.1 * c, math.sqrt(c)


def build_levant(rate, params):
    alpha, lam = gains(params["c"])
    return np.array([alpha, lam, 1.0 / rate]), LEVANT_STATE


def build_levantlp(rate, params):
    alpha, lam = gains(params["c"])
    p = np.concatenate(([alpha, lam, 1.0 / rate], butter_section(params["cutoff_hz"], rate)))
    return p, LEVANT_STATE + 2


@njit(cache=True, inline="always")
def levant_core(s, alpha, lam, period, x):
    """One Euler step of eqs. 10-12 on the state view ``s = [started, w, u1]``; returns u."""
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x
        s[2] = 0.0
    e = s[1] - x
    # Branch-free: in the sliding regime the sign of e flips at random, which a branch mispredicts.
    sign = np.sign(e)
    u = s[2] - lam * math.copysign(math.sqrt(abs(e)), e)
    s[1] += period * u
    s[2] -= period * alpha * sign
    return u


@njit(cache=True, inline="always")
def step_levant(s, p, x, a, v):
    return levant_core(s, p[0], p[1], p[2], x)


@njit(cache=True, inline="always")
def step_levantlp(s, p, x, a, v):
    u = levant_core(s[0:LEVANT_STATE], p[0], p[1], p[2], x)
    return section_step(p[3:8], s[LEVANT_STATE:LEVANT_STATE + 2], u)


SPEC_LEVANT = EstimatorSpec(
    name="LEVANT", kind=kinds.LEVANT, description="Levant's two-sliding differentiator.",
    inputs=("position",), params=(c_param(19.7),), build=build_levant,
    reference="paper Sec. 5.4, eqs. 8-15; Levant 1998; Table 1 (C = 19.7)",
)
SPEC_LEVANTLP = EstimatorSpec(
    name="LEVANTLP", kind=kinds.LEVANTLP, description="LEVANT followed by a 2nd-order Butterworth low-pass.",
    inputs=("position",), params=(c_param(3.6), cutoff("cutoff_hz", 293.0, "post-filter cut-off")),
    build=build_levantlp, reference="paper Sec. 5.4; Table 1 (C = 3.6, LPF = 293 Hz)",
)

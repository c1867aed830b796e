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
sample period T, sgn(0) = 0. The starting state is the parameter ``start``:

    "zero"   w = 0, u1 = 0 (the authors' code; the default): on a position far
             from 0 the observer first has to travel there (its first output
             is sqrt(C |x_0|); docs/estimators-nonlinear.md measures the transient)
    "first"  w = x_0, u1 = 0 (the observer on the first sample): the first output is 0

On the authors' test signal (tests/estimators/test_estimators_oracle.py) the
two starts differ by 0.5 % in root-sum-square error at 1 kHz; with "zero"
ours reproduces the authors' published figures to 1e-9. At step k the output
is u computed from the state before the update:

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
chain it twice, L(L(x)), both passes with the same ``start``.

Bad input: handled centrally by ``dispatch.step_guarded`` (a NaN, inf or
out-of-bounds sample, ``bounds.py``, is replaced by the last good one and
counted), so these kernels only ever see finite input within the bounds. The
bound matters here: the observer closes an error e at a rate of about
lambda sqrt(|e|), so after one 1e30 m sample (before the bounds) LEVANT still
read 4e6 m/s two seconds later; after a 1 m sample it is back within 0.1 s
(tests/estimators/test_estimators_extremes.py).

LEVANT state: ``[started, w, u1]``; parameters ``[alpha, lambda, T, from_first]``
(``from_first`` 1.0 for ``start = "first"``, else 0.0).
LEVANTLP state: ``[started, w, u1, z1, z2]``; parameters ``[alpha, lambda, T, from_first, section(5)]``.
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.biquad import butter_section, section_step
from studyapp.estimators.spec import EstimatorSpec, Param, cutoff

LEVANT_STATE = 3
LEVANT_PARAMS = 4
STARTS = ("zero", "first")


def c_param(default):
    return Param("c", default, "m/s^2", 1e-3, 1e5, doc="Lipschitz constant C (max. acceleration)")


def start_param():
    return Param("start", "zero", kind="choice", choices=STARTS, scale="linear",
                 doc="observer's starting state: zero: w = 0, u1 = 0 (the authors'); first: w = first position")


def gains(c):
    """``(alpha, lambda)`` from the Lipschitz constant C (eqs. 14-15)."""
    return 1.1 * c, math.sqrt(c)


def levant_params(rate, params):
    """``[alpha, lambda, T, from_first]``: the parameters ``levant_core`` reads."""
    alpha, lam = gains(params["c"])
    return [alpha, lam, 1.0 / rate, 1.0 if params["start"] == "first" else 0.0]


def build_levant(rate, params):
    return np.array(levant_params(rate, params)), LEVANT_STATE


def build_levantlp(rate, params):
    p = np.concatenate((levant_params(rate, params), butter_section(params["cutoff_hz"], rate)))
    return p, LEVANT_STATE + 2


@njit(cache=True, inline="always")
def levant_core(s, alpha, lam, period, from_first, x):
    """One Euler step of eqs. 10-12 on the state view ``s = [started, w, u1]``; returns u.

    The observer starts at w = x_0 when ``from_first`` is 1.0, at w = 0 when it is 0.0.
    """
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x * from_first
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
    return levant_core(s, p[0], p[1], p[2], p[3], x)


@njit(cache=True, inline="always")
def step_levantlp(s, p, x, a, v):
    u = levant_core(s[0:LEVANT_STATE], p[0], p[1], p[2], p[3], x)
    return section_step(p[LEVANT_PARAMS:LEVANT_PARAMS + 5], s[LEVANT_STATE:LEVANT_STATE + 2], u)


SPEC_LEVANT = EstimatorSpec(
    name="LEVANT", kind=kinds.LEVANT, description="Levant's two-sliding differentiator.",
    inputs=("position",), params=(c_param(19.7), start_param()), build=build_levant,
    reference="paper Sec. 5.4, eqs. 8-15; Levant 1998; Table 1 (C = 19.7)",
)
SPEC_LEVANTLP = EstimatorSpec(
    name="LEVANTLP", kind=kinds.LEVANTLP, description="LEVANT followed by a 2nd-order Butterworth low-pass.",
    inputs=("position",),
    params=(c_param(3.6), cutoff("cutoff_hz", 293.0, "post-filter cut-off"), start_param()),
    build=build_levantlp, reference="paper Sec. 5.4; Table 1 (C = 3.6, LPF = 293 Hz)",
)

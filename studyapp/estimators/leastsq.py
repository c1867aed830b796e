"""LEASTSQ: least-squares polynomial fit as an FIR differentiator (paper eqs. 4-7).

Fit a polynomial of degree N (``order``) to the newest M (``window``) samples
and take its derivative at the newest one. With the samples at times
t_j = (j - c) / h, j = 0 .. M-1 (c = (M-1)/2 centres and h = (M-1)/2 scales the
axis to [-1, 1], which keeps the Vandermonde matrix well conditioned at any
rate and window),

    A[j, n] = t_j^n,  c = A^+ x,  dx/dt = (1 / (h T)) * sum_n n c_n t_newest^(n-1)

so v_k = h_dot^T x is an FIR filter whose taps are h_dot^T = q_dot^T A^+ with
q_dot = [0, 1, 2 t, ..., N t^(N-1)] at t = t_newest = 1 (eq. 7).
The taps are exact on polynomials of degree <= N and equal the exact
rational taps (least squares solved with fractions) to about 1e-14 relative
over the whole allowed range (N <= 6, M <= 512; tested). They equal
``scipy.signal.savgol_coeffs(M, N, deriv=1, delta=T, pos=M-1, use="conv")``
only where scipy is accurate: its unscaled Vandermonde loses precision as M
grows: 7e-7 off at N = 4, M = 512, 100 % off at N = 5, M = 400 and 512
and at N = 6 from M = 257 (measured 2026-11-25 against the exact taps;
tests/estimators/test_estimators_linear.py).
Before M samples have been seen the history is taken equal to the first sample.

State: ``[started, head, ring of M]``. Parameters: ``[M, taps (M)]`` with
taps[j] multiplying x_{k-j}.
"""

import numpy as np
from numba import njit

from studyapp.errors import ParameterError
from studyapp.estimators import kinds
from studyapp.estimators.history import fill
from studyapp.estimators.spec import EstimatorSpec, Param


def taps(order, window, rate):
    """FIR taps of the derivative at the newest sample; taps[j] multiplies x_{k-j}."""
    h = (window - 1) / 2.0
    t = (np.arange(window) - h) / h  # oldest .. newest, newest at t = 1
    a = np.vander(t, order + 1, increasing=True)
    qdot = np.array([n * 1.0 ** (n - 1) if n > 0 else 0.0 for n in range(order + 1)])
    row = qdot @ np.linalg.pinv(a)  # weights on oldest .. newest
    return row[::-1] * (rate / h)


def check(rate, params):
    if params["window"] <= params["order"]:
        raise ParameterError(
            f"LEASTSQ parameter 'window' = {params['window']}: allowed is an integer above order = {params['order']}"
        )


def build(rate, params):
    m = params["window"]
    return np.concatenate(([float(m)], taps(params["order"], m, rate))), 2 + m


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    m = int(p[0])
    ring = s[2:2 + m]
    if s[0] == 0.0:
        s[0] = 1.0
        fill(ring, x)
    head = int(s[1])
    ring[head] = x
    acc = 0.0
    j = head
    for i in range(m):
        acc += p[1 + i] * ring[j]
        j -= 1
        if j < 0:
            j = m - 1
    s[1] = (head + 1) % m
    return acc


SPEC = EstimatorSpec(
    name="LEASTSQ",
    kind=kinds.LEASTSQ,
    description="Least-squares polynomial fit as FIR taps, derivative at the newest sample.",
    inputs=("position",),
    params=(
        Param("order", 2, "", 1, 6, kind="int", scale="linear", doc="polynomial order N"),
        Param("window", 33, "samples", 2, 512, kind="int", scale="linear", doc="window length M"),
    ),
    build=build,
    check=check,
    reference="paper Sec. 5.2, eqs. 4-7; Table 1 (N = 2, M = 33)",
)

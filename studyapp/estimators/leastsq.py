"""LEASTSQ: least-squares polynomial fit as an FIR differentiator (paper eqs. 4-7).

Fit a polynomial of degree N (``order``) to the newest M (``window``) samples
and take its derivative at the newest one. With the samples at times
t_j = (j - c) / h, j = 0 .. M-1 (c = (M-1)/2 centres and h = (M-1)/2 scales the
axis to [-1, 1], which keeps the Vandermonde matrix well conditioned at any
rate and window),

    A[j, n] = t_j^n,  c = A^+ x,  dx/dt = (1 / (h T)) * sum_n n c_n t_newest^(n-1)

so v_k = h_dot^T x is an FIR filter whose taps are h_dot^T = q_dot^T A^+ with
q_dot = [0, 1, 2 t, ..., N t^(N-1)] at t = t_newest = 1 (eq. 7).

The taps are computed exactly, in rational numbers (``fractions.Fraction``),
and rounded once to float: with u_j = 2 j - (M-1) (integers, t_j = u_j / (M-1))
and G[m, n] = sum_j u_j^(m+n) (integers), G w = r with r_n = n (M-1)^n gives
h_dot_j = (2 / ((M-1) T)) sum_n w_n u_j^n, the same least-squares solution
with the scaling divided out. Each tap is the correctly rounded value of the
exact one, so it is the same bits on every machine (no BLAS or LAPACK: numpy's
pinv of the Vandermonde matrix gave taps whose last bits depended on the CPU's
BLAS kernels, issue 39). The exact taps of the last 256 (N, M) are kept;
building them takes at most about 20 ms (N = 6, M = 512).
They equal ``numpy.linalg.pinv``'s to about 1e-14 relative and
``scipy.signal.savgol_coeffs(M, N, deriv=1, delta=T, pos=M-1, use="conv")``
only where scipy is accurate: its unscaled Vandermonde loses precision as M
grows: 7e-7 off at N = 4, M = 512, 100 % off at N = 5, M = 400 and 512
and at N = 6 from M = 257 (measured 2026-11-25 against the exact taps;
tests/estimators/test_estimators_linear.py).
Before M samples have been seen the history is taken equal to the first sample.

State: ``[started, head, ring of M]``. Parameters: ``[M, taps (M)]`` with
taps[j] multiplying x_{k-j}.
"""

import functools
import math
from fractions import Fraction

import numpy as np
from numba import njit

from studyapp.errors import ParameterError
from studyapp.estimators import kinds
from studyapp.estimators.history import fill
from studyapp.estimators.spec import EstimatorSpec, Param


@functools.lru_cache(maxsize=256)  # at most 25 kB each (N = 6, M = 512): a few MB
def exact_taps(order, window):
    """(numerators, denominator): the taps at a rate of 1 Hz, oldest .. newest, as integers over one integer."""
    span = window - 1
    u = [2 * j - span for j in range(window)]
    n = order + 1
    moments = [sum(x ** p for x in u) for p in range(2 * n - 1)]
    rows = [[Fraction(moments[a + b]) for b in range(n)] + [Fraction(a * span ** a)] for a in range(n)]
    for c in range(n):  # Gauss-Jordan; G is positive definite, so no pivot is zero
        for r in range(n):
            if r != c and rows[r][c]:
                f = rows[r][c] / rows[c][c]
                rows[r] = [x - f * y for x, y in zip(rows[r], rows[c])]
    w = [rows[a][n] / rows[a][a] for a in range(n)]
    common = math.lcm(*(x.denominator for x in w))
    coefficients = [2 * x.numerator * (common // x.denominator) for x in w]
    return tuple(sum(c * x ** a for a, c in enumerate(coefficients)) for x in u), span * common


def taps(order, window, rate):
    """FIR taps of the derivative at the newest sample; taps[j] multiplies x_{k-j}."""
    numerators, denominator = exact_taps(order, window)
    p, q = float(rate).as_integer_ratio()
    return np.array([t * p / (denominator * q) for t in reversed(numerators)])  # int / int: correctly rounded


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

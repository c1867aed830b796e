"""The zero-order-hold discretisation of a small linear system, in a fixed order of float operations.

For ds/dt = A s + B u with u held constant over a step of T seconds,

    s[k+1] = Phi s[k] + Gamma u[k],   Phi = exp(A T),   Gamma = int_0^T exp(A t) dt B,

and both come from one exponential (Van Loan):

    exp([[A T, B T], [0, 0]]) = [[Phi, Gamma], [0, I]].

``expm`` computes exp(M) by scaling and squaring: X = M / 2^s with s the
smallest integer >= 0 that brings the largest absolute row sum of X to at most
THETA = 1/4 (dividing by a power of two is exact), the Taylor sum
E = exp(X) - I = X + X^2/2! + ... + X^K/K! with K = TERMS = 18 (the first
term left out is below 0.25^19 / 19! ~ 3e-29, far under one rounding), then s
squarings with the identity kept apart, (I + E)^2 = I + (2 E + E E), so the
small entries (Gamma's) keep their digits: exp(M) = (exp(X))^(2^s) = I + E.

Why not scipy.linalg.expm: its matrix products go through BLAS, whose kernels
OpenBLAS chooses by CPU (``OPENBLAS_CORETYPE``), and different kernels round
differently, so Phi and Gamma differed in their last bits from one machine to
the next (issue 39), and the stick-slip loop grows such a difference into a
different breakdown F_max. Here every product and sum is Python float
arithmetic (IEEE double, round to nearest), each matrix entry a ``math.fsum``
(correctly rounded) of its products in a fixed order: the same bits on every
machine. On the device's grip from 1 to
96 kHz, masses 0.01-1 kg, grips 0-1e5 N/m and 0-1000 N s/m (measured 2026-11-28,
tests/model/test_model_zoh.py): within 1.8e-13 of each column's largest entry
of scipy.linalg.expm's; per entry within 5e-14 (grips up to 1e4 N/m) and
2.4e-12 (1e5 N/m, undamped, 1 kHz) of a 60-digit exponential, where scipy's
smallest entries are off by up to 1e-2.
"""

import math

THETA = 0.25
TERMS = 18


def _product(a, b):
    n, m = len(b), len(b[0])
    return [[math.fsum(row[k] * b[k][j] for k in range(n)) for j in range(m)] for row in a]


def expm(m):
    """exp(``m``) of a square matrix given as a list of rows of floats (a list of rows back)."""
    n = len(m)
    norm = max(math.fsum(abs(float(x)) for x in row) for row in m)
    s = 0
    while norm > THETA:
        norm /= 2.0
        s += 1
    x = [[math.ldexp(float(v), -s) for v in row] for row in m]
    term = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    terms = []
    for k in range(1, TERMS + 1):
        term = [[v / k for v in row] for row in _product(term, x)]
        terms.append(term)
    e = [[math.fsum(t[i][j] for t in reversed(terms)) for j in range(n)] for i in range(n)]  # exp(X) - I
    for _ in range(s):  # (I + E)^2 = I + 2 E + E E: the identity kept apart, so small entries keep their digits
        e = [[math.fsum([2.0 * e[i][j]] + [e[i][k] * e[k][j] for k in range(n)]) for j in range(n)] for i in range(n)]
    return [[e[i][j] + (1.0 if i == j else 0.0) for j in range(n)] for i in range(n)]


def discretise(a, b, t):
    """(Phi, Gamma) as lists of rows: the zero-order hold of ds/dt = ``a`` s + ``b`` u over ``t`` s."""
    n, m = len(a), len(b[0])
    big = [[float(a[i][j]) * t for j in range(n)] + [float(b[i][j]) * t for j in range(m)] for i in range(n)]
    big += [[0.0] * (n + m) for _ in range(m)]
    e = expm(big)
    return [row[:n] for row in e[:n]], [row[n:] for row in e[:n]]

"""The principal axis of a few points, in a fixed order of float operations (the search's ridge draws).

For points x_1 .. x_n in d dimensions (n >= 2), the sample covariance

    C = sum_k (x_k - m)(x_k - m)^T / (n - 1),   m = sum_k x_k / n

(``numpy.cov``'s), and its eigen-decomposition C = V diag(lambda) V^T by the
cyclic Jacobi method: sweeps over the off-diagonal entries (p, q) in order,
each rotation [[c, s], [-s, c]] chosen to zero C[p, q] (t = tan of the angle,
the smaller root of t^2 + 2 theta t - 1 = 0, theta = (C[q, q] - C[p, p]) /
(2 C[p, q])), until every off-diagonal entry is zero or below 1e-300, or
after MAX_SWEEPS sweeps (a symmetric matrix converges quadratically: a few
sweeps for d <= 8). ``principal_axis`` returns the unit eigenvector of the
largest eigenvalue, its sign chosen so that its largest component (the first
of equals) is positive, and the smallest eigenvalue.

Why not numpy.cov and numpy.linalg.eigh: they go through BLAS and LAPACK,
whose kernels OpenBLAS chooses by CPU, and different kernels round
differently (issue 39). Here each covariance entry is a ``math.fsum``
(correctly rounded, so its order does not matter) of elementwise products,
the projections t_k = (x_k - c) . u are summed coordinate by coordinate in a
fixed order, and every other step is one float operation in a fixed order:
the same bits on every machine. (An elementwise numpy operation rounds each
entry once, whatever SIMD width runs it; a matrix product does not.) For an
elite of 2000 points the axis takes a few ms.
Against numpy the eigenvalues agree to about 1e-15 of the largest and the axis
to about 1e-13 wherever the two largest eigenvalues are apart
(tests/evaluation/test_principal_axis.py).
"""

import math

import numpy as np

MAX_SWEEPS = 50
TINY = 1e-300


def covariance(points):
    """The sample covariance (rows of floats) of ``points``: n >= 2 points (rows) of d coordinates."""
    x = np.asarray(points, dtype=np.float64)
    n, d = x.shape
    centred = x - np.array([math.fsum(x[:, i]) / n for i in range(d)])  # one rounding per entry, as in Python
    c = [[0.0] * d for _ in range(d)]
    for i in range(d):
        for j in range(i, d):
            c[i][j] = c[j][i] = math.fsum(centred[:, i] * centred[:, j]) / (n - 1)
    return c


def projections(points, centre, u):
    """t_k = sum_i (x_ki - c_i) u_i for every point, summed over i = 0, 1, ... in that order."""
    x = np.asarray(points, dtype=np.float64)
    t = np.zeros(x.shape[0])
    for i in range(x.shape[1]):
        t = t + (x[:, i] - float(centre[i])) * float(u[i])
    return t


def eigh(c):
    """(eigenvalues ascending, eigenvectors as columns: rows of floats) of the symmetric matrix ``c`` (Jacobi)."""
    d = len(c)
    a = [[float(v) for v in row] for row in c]
    v = [[1.0 if i == j else 0.0 for j in range(d)] for i in range(d)]
    for _ in range(MAX_SWEEPS):
        if all(abs(a[p][q]) <= TINY for p in range(d) for q in range(p + 1, d)):
            break
        for p in range(d):
            for q in range(p + 1, d):
                if abs(a[p][q]) <= TINY:
                    continue
                theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
                t = 1.0 / (abs(theta) + math.sqrt(theta * theta + 1.0))
                if theta < 0.0:
                    t = -t
                cos = 1.0 / math.sqrt(t * t + 1.0)
                sin = t * cos
                for k in range(d):  # columns p and q of a R
                    akp, akq = a[k][p], a[k][q]
                    a[k][p] = cos * akp - sin * akq
                    a[k][q] = sin * akp + cos * akq
                for k in range(d):  # rows p and q of R^T (a R)
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k] = cos * apk - sin * aqk
                    a[q][k] = sin * apk + cos * aqk
                a[p][q] = a[q][p] = 0.0
                for k in range(d):
                    vkp, vkq = v[k][p], v[k][q]
                    v[k][p] = cos * vkp - sin * vkq
                    v[k][q] = sin * vkp + cos * vkq
    order = sorted(range(d), key=lambda i: a[i][i])
    return [a[i][i] for i in order], [[v[k][i] for i in order] for k in range(d)]


def principal_axis(points):
    """(u, lambda_min): the unit axis of the points' largest variance (largest component positive) and the
    covariance's smallest eigenvalue."""
    values, vectors = eigh(covariance(points))
    u = [row[-1] for row in vectors]
    biggest = max(range(len(u)), key=lambda i: (abs(u[i]), -i))
    if u[biggest] < 0.0:
        u = [-x for x in u]
    return u, values[0]


def dot(a, b):
    """sum_i a_i b_i, correctly rounded (math.fsum of the products)."""
    return math.fsum(float(x) * float(y) for x, y in zip(a, b))

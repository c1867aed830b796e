"""The Pareto front of points to be minimised on every axis.

A point is on the front when no other point is at least as good on every axis
and strictly better on one: here, no estimator is both cheaper (or as cheap)
and better (or as good) on the global objective.
"""

import numpy as np


def pareto_front(points):
    """Boolean mask of the non-dominated rows of ``points`` (n x k, lower is better; non-finite rows never)."""
    points = np.asarray(points, dtype=np.float64)
    n = points.shape[0]
    finite = np.all(np.isfinite(points), axis=1)
    mask = finite.copy()
    for i in range(n):
        if not finite[i]:
            continue
        others = points[finite]
        dominated = np.any(np.all(others <= points[i], axis=1) & np.any(others < points[i], axis=1))
        mask[i] = not dominated
    return mask

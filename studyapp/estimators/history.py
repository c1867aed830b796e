"""Sample history for the compiled kernels.

``fill`` starts a history at rest: every past sample equal to the first one.
It is an explicit loop on purpose: in an isolated test a broadcast slice
assignment (``a[:] = x``) inside an inlined kernel added ~16 ns per sample to
the dispatch even when never executed; the loop added nothing.
"""

from numba import njit


@njit(cache=True, inline="always")
def fill(history, x):
    for i in range(history.shape[0]):
        history[i] = x

"""Second-order sections for the compiled kernels.

Filters are designed in SOS form (``output="sos"``, never high-order
``b, a``): Butterworth sections by butterworth.py, equal to scipy.signal's
without importing it, others with scipy. They run here in transposed direct
form II, one section at a time:

    y  = b0 x + z1
    z1 = b1 x - a1 y + z2
    z2 = b2 x - a2 y

A section is stored in a parameter vector as five numbers ``b0 b1 b2 a1 a2``
(``a0`` is 1) and in a state vector as two, ``z1 z2``. ``filter_from_rest``
runs sections in series over a signal from rest: scipy.signal.sosfilt's
arithmetic, operation for operation.
"""

import numpy as np
from numba import njit

from studyapp.estimators.butterworth import sos_row

SECTION = 5  # parameters per section
STATE = 2  # state per section


def butter_section(cutoff_hz, rate, btype="low"):
    """One 2nd-order Butterworth section as the 5 numbers this module runs."""
    return section_from_sos(sos_row(2, cutoff_hz, rate, btype))


def section_from_sos(row):
    row = np.asarray(row, dtype=np.float64)
    return np.array([row[0], row[1], row[2], row[4], row[5]]) / row[3]


@njit(cache=True, inline="always")
def section_step(p, s, x):
    """Advance one section with parameters ``p[0:5]`` and state ``s[0:2]``."""
    y = p[0] * x + s[0]
    s[0] = p[1] * x - p[3] * y + s[1]
    s[1] = p[2] * x - p[4] * y
    return y


@njit(cache=True, inline="always")
def section_prime(p, s, x):
    """Set the state to the steady state for a constant input ``x``.

    For the constant input x the output settles at y = g x, with
    g = (b0 + b1 + b2) / (1 + a1 + a2); then z2 = b2 x - a2 y and
    z1 = y - b0 x.
    """
    g = (p[0] + p[1] + p[2]) / (1.0 + p[3] + p[4])
    y = g * x
    s[1] = p[2] * x - p[4] * y
    s[0] = y - p[0] * x


@njit(cache=True)
def filter_from_rest(params, x):
    """``x`` through the sections ``params`` (``SECTION`` numbers each, in series), from a zero state."""
    sections = params.shape[0] // SECTION
    state = np.zeros(sections * STATE)
    y = np.empty(x.shape[0])
    for k in range(x.shape[0]):
        v = x[k]
        for j in range(sections):
            v = section_step(params[j * SECTION:(j + 1) * SECTION], state[j * STATE:(j + 1) * STATE], v)
        y[k] = v
    return y

"""LVT: the tachometer's measured velocity, passed through unchanged.

The paper's linear velocity transducer (Trans-Tek Series 100, flat to 500 Hz,
0.115 mm/s RMS noise at rest; Sec. 4.2) needs no estimation: it is the
reference condition of the study (Sec. 8.4).
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec

NAME = "LVT"  # the estimator; the sensor pseudo-source of the same text is model/sources.py's LVT_SENSOR


def build(rate, params):
    return np.zeros(1), 1


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    return v


SPEC = EstimatorSpec(
    name=NAME,
    kind=kinds.LVT,
    description="The measured tachometer velocity, passed through.",
    inputs=("velocity",),
    build=build,
    reference="paper Sec. 4.2 and 8.4",
)

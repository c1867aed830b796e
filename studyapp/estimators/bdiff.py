"""BDIFF: the backward difference (paper eq. 3).

    v_k = (x_k - x_{k-z}) / (z T)

with ``steps`` = z >= 1 and T the sample period. Precision is bought with
delay: the estimate is centred z/2 samples in the past. Before z samples have
been seen, the missing history is taken equal to the first sample (the device
is assumed at rest before the stream starts), so the first output is 0.

State: ``[started, head, x_{k-z} .. x_{k-1} ring of z]``.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.history import fill
from studyapp.estimators.spec import EstimatorSpec, Param


def build(rate, params):
    z = params["steps"]
    return np.array([float(z), float(z) * (1.0 / rate)]), 2 + z


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    z = int(p[0])
    ring = s[2:2 + z]
    if s[0] == 0.0:
        s[0] = 1.0
        fill(ring, x)
    head = int(s[1])
    old = ring[head]
    ring[head] = x
    s[1] = (head + 1) % z
    return (x - old) / p[1]


SPEC = EstimatorSpec(
    name="BDIFF",
    kind=kinds.BDIFF,
    description="Backward difference over z steps (eq. 3).",
    inputs=("position",),
    params=(Param("steps", 1, "samples", 1, 1000, kind="int", scale="linear", doc="z, the number of steps"),),
    build=build,
    reference="paper Sec. 5.1, eq. 3",
)

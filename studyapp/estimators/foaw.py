"""FOAW. PLACEHOLDER KERNEL: to be written (helper)."""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec, Param


def build(rate, params):
    return np.zeros(1), 1


@njit(cache=True)
def step(s, p, x, a, v):
    return 0.0


SPEC = EstimatorSpec(
    name="FOAW", kind=kinds.FOAW, description="First-order adaptive windowing, best-fit method.",
    inputs=("position",),
    params=(
        Param("window", 17, "samples", 1, 256, kind="int", scale="linear", doc="largest window n"),
        Param("margin", 1.001e-4, "m", 1e-9, 1e-1, doc="noise margin"),
    ),
    build=build, reference="paper Sec. 5.3; Janabi-Sharifi et al. 2000; Table 1 (size 17, margin 1.001e-4)",
)

"""LEVANT and LEVANTLP. PLACEHOLDER KERNELS: to be written (helper)."""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec, Param, cutoff


def c_param(default):
    return Param("c", default, "m/s^2", 1e-3, 1e7, doc="Lipschitz constant C (max. acceleration)")


def build_levant(rate, params):
    return np.zeros(1), 1


def build_levantlp(rate, params):
    return np.zeros(1), 1


@njit(cache=True)
def step_levant(s, p, x, a, v):
    return 0.0


@njit(cache=True)
def step_levantlp(s, p, x, a, v):
    return 0.0


SPEC_LEVANT = EstimatorSpec(
    name="LEVANT", kind=kinds.LEVANT, description="Levant's two-sliding differentiator.",
    inputs=("position",), params=(c_param(19.7),), build=build_levant,
    reference="paper Sec. 5.4, eqs. 8-15; Table 1 (C = 19.7)",
)
SPEC_LEVANTLP = EstimatorSpec(
    name="LEVANTLP", kind=kinds.LEVANTLP, description="LEVANT followed by a 2nd-order Butterworth low-pass.",
    inputs=("position",), params=(c_param(3.6), cutoff("cutoff_hz", 293.0, "post-filter cut-off")),
    build=build_levantlp, reference="paper Sec. 5.4; Table 1 (C = 3.6, LPF = 293 Hz)",
)

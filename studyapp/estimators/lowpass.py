"""LOWPASS: backward difference followed by a 2nd-order Butterworth low-pass.

    v_k = LPF( (x_k - x_{k-1}) / T )

The paper's comparison case (Sec. 5.1, Table 1: cut-off 256 Hz). The filter is
scipy's ``butter(2, cutoff_hz, fs=rate, output="sos")`` run as one section in
transposed direct form II with zero initial state; the first difference is 0
at the first sample (the history is taken equal to the first sample).

State: ``[started, x_{k-1}, z1, z2]``. Parameters: ``[1/T, section(5)]``.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.biquad import butter_section, section_step
from studyapp.estimators.spec import EstimatorSpec, cutoff


def build(rate, params):
    return np.concatenate(([rate], butter_section(params["cutoff_hz"], rate))), 4


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x
    d = (x - s[1]) * p[0]
    s[1] = x
    return section_step(p[1:6], s[2:4], d)


SPEC = EstimatorSpec(
    name="LOWPASS",
    kind=kinds.LOWPASS,
    description="Backward difference, then a 2nd-order Butterworth low-pass.",
    inputs=("position",),
    params=(cutoff("cutoff_hz", 256.0, "low-pass cut-off"),),
    build=build,
    reference="paper Sec. 5.1; Table 1 (LPF = 256 Hz)",
)

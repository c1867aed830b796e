"""COMP1 and COMP2: low-passed differentiated position plus high-passed integrated acceleration.

    v_k = LP( (x_k - x_{k-1}) / T ) + HP( integral of a )

with 2nd-order Butterworth sections (paper Sec. 5.5, Table 2). COMP1 uses one
cut-off for both (Table 1: 317 Hz); COMP2 two (256 Hz and 2,254 Hz).

What is implemented, and why. The paper names a "complementary pair" but a
2nd-order Butterworth low-pass and high-pass at the same cut-off wc do not sum
to one: with s normalised to wc,

    LP + HP = (1 + s^2) / (s^2 + sqrt(2) s + 1),

which is a notch: zero gain at the cut-off. We implement the paper's literal
structure (Butterworth LP plus Butterworth HP), because Table 1's cut-offs were
tuned on it, and document the notch here rather than hide it. A reader who
wants a true complementary pair should use COMP2 with distinct cut-offs, or a
new estimator.

The integral is trapezoidal, T/2 (1 + z^-1) / (1 - z^-1). The Butterworth
high-pass's bilinear numerator is g (1 - z^-1)^2, so integrator and high-pass
fold into one stable section with numerator g T/2 (1 - z^-2): no free-running
integrator, so accelerometer bias cannot make the state grow without bound.

State: ``[started, x_{k-1}, lp z1 z2, hp z1 z2]``.
Parameters: ``[1/T, lp section(5), integrating hp section(5)]``.
"""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.biquad import butter_section, section_from_sos, section_step
from studyapp.estimators.butterworth import sos_row
from studyapp.estimators.spec import EstimatorSpec, cutoff


def integrating_highpass(cutoff_hz, rate):
    """One section equal to a 2nd-order Butterworth high-pass of the trapezoidal integral."""
    sos = sos_row(2, cutoff_hz, rate, "high")
    g = sos[0]  # numerator g * [1, -2, 1]
    sos[0:3] = g * 0.5 / rate * np.array([1.0, 0.0, -1.0])
    return section_from_sos(sos)


def _build(rate, lpf_hz, hpf_hz):
    p = np.concatenate(([rate], butter_section(lpf_hz, rate), integrating_highpass(hpf_hz, rate)))
    return p, 6


def build_comp1(rate, params):
    return _build(rate, params["cutoff_hz"], params["cutoff_hz"])


def build_comp2(rate, params):
    return _build(rate, params["lpf_hz"], params["hpf_hz"])


@njit(cache=True, inline="always")
def step(s, p, x, a, v):
    if s[0] == 0.0:
        s[0] = 1.0
        s[1] = x
    d = (x - s[1]) * p[0]
    s[1] = x
    return section_step(p[1:6], s[2:4], d) + section_step(p[6:11], s[4:6], a)


SPEC_COMP1 = EstimatorSpec(
    name="COMP1",
    kind=kinds.COMP1,
    description="Butterworth LP of differentiated position + HP of integrated acceleration, one cut-off.",
    inputs=("position", "acceleration"),
    params=(cutoff("cutoff_hz", 317.0, "cut-off of both filters"),),
    build=build_comp1,
    reference="paper Sec. 5.5; Table 1 (LPF = HPF = 317 Hz)",
)

SPEC_COMP2 = EstimatorSpec(
    name="COMP2",
    kind=kinds.COMP2,
    description="Butterworth LP of differentiated position + HP of integrated acceleration, two cut-offs.",
    inputs=("position", "acceleration"),
    params=(cutoff("lpf_hz", 256.0, "low-pass cut-off"), cutoff("hpf_hz", 2254.0, "high-pass cut-off")),
    build=build_comp2,
    reference="paper Sec. 5.5; Table 1 (LPF = 256 Hz, HPF = 2,254 Hz)",
)

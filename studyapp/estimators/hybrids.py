"""KALLEV, KALLEVACC, KALFOAW, KALFOAWACC. PLACEHOLDER KERNELS: to be written (helper)."""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.kalman import q_param, r_acc_param, r_pos_param
from studyapp.estimators.levant import c_param
from studyapp.estimators.spec import EstimatorSpec, Param, cutoff, q_convention


def _window():
    return Param("window", 12, "samples", 1, 256, kind="int", scale="linear", doc="FOAW largest window")


def _margin():
    return Param("margin", 1e-4, "m", 1e-9, 1e-1, doc="FOAW position margin")


def _margin_vel():
    return Param("margin_vel", 0.5, "m/s", 1e-6, 1e3, doc="FOAW velocity margin (second pass)")


def _hpf():
    return cutoff("hpf_hz", 20.0, "accelerometer high-pass (removes DC error)")


def build(rate, params):
    return np.zeros(1), 1


@njit(cache=True)
def step_kallev(s, p, x, a, v):
    return 0.0


@njit(cache=True)
def step_kallevacc(s, p, x, a, v):
    return 0.0


@njit(cache=True)
def step_kalfoaw(s, p, x, a, v):
    return 0.0


@njit(cache=True)
def step_kalfoawacc(s, p, x, a, v):
    return 0.0


SPEC_KALLEV = EstimatorSpec(
    name="KALLEV", kind=kinds.KALLEV, description="KALMAN with acceleration from LEVANT twice: K(x, L(L(x))).",
    inputs=("position",),
    params=(q_param(6.38e4), r_acc_param(195.0), r_pos_param(), c_param(100.0), q_convention()),
    build=build, reference="paper Sec. 5.7; Table 1 (Q = 6.38e4, R_a = 195)",
)
SPEC_KALLEVACC = EstimatorSpec(
    name="KALLEVACC", kind=kinds.KALLEVACC,
    description="KALMAN with LEVANT-twice acceleration plus high-passed measured: K(x, L(L(x)) + H(a)).",
    inputs=("position", "acceleration"),
    params=(q_param(2954.0), r_acc_param(64.6), r_pos_param(), c_param(100.0), _hpf(), q_convention()),
    build=build, reference="paper Sec. 5.7; Table 1 (Q = 2954, R_a = 64.6)",
)
SPEC_KALFOAW = EstimatorSpec(
    name="KALFOAW", kind=kinds.KALFOAW, description="KALMAN with acceleration from FOAW twice: K(x, F(F(x))).",
    inputs=("position",),
    params=(q_param(77.7), r_acc_param(8.06), r_pos_param(), _window(), _margin(), _margin_vel(), q_convention()),
    build=build, reference="paper Sec. 5.7; Table 1 (Q = 77.7, R_a = 8.06)",
)
SPEC_KALFOAWACC = EstimatorSpec(
    name="KALFOAWACC", kind=kinds.KALFOAWACC,
    description="KALMAN with FOAW-twice acceleration plus high-passed measured: K(x, F(F(x)) + H(a)).",
    inputs=("position", "acceleration"),
    params=(q_param(88.5), r_acc_param(3.85), r_pos_param(), _window(), _margin(), _margin_vel(), _hpf(),
            q_convention()),
    build=build, reference="paper Sec. 5.7; Table 1 (Q = 88.5, R_a = 3.85)",
)

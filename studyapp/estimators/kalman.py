"""KALPOS and KALMAN. PLACEHOLDER KERNELS: to be written (helper)."""

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.spec import EstimatorSpec, Param, q_convention


def q_param(default):
    return Param("q", default, "", 1e-9, 1e15, doc="process noise q (see q_convention)")


def r_pos_param():
    return Param("r_pos", 2e-10, "m^2", 1e-16, 1.0, doc="position measurement covariance R_p")


def r_acc_param(default):
    return Param("r_acc", default, "(m/s^2)^2", 1e-9, 1e12, doc="acceleration measurement covariance R_a")


def build_kalpos(rate, params):
    return np.zeros(1), 1


def build_kalman(rate, params):
    return np.zeros(1), 1


@njit(cache=True)
def step_kalpos(s, p, x, a, v):
    return 0.0


@njit(cache=True)
def step_kalman(s, p, x, a, v):
    return 0.0


SPEC_KALPOS = EstimatorSpec(
    name="KALPOS", kind=kinds.KALPOS, description="2nd-order Kalman filter [x, v], position measurement.",
    inputs=("position",), params=(q_param(0.191), r_pos_param(), q_convention()), build=build_kalpos,
    reference="paper Sec. 5.6, eqs. 16-19; Table 1 (Q = 0.191)",
)
SPEC_KALMAN = EstimatorSpec(
    name="KALMAN", kind=kinds.KALMAN, description="3rd-order Kalman filter [x, v, a], position and acceleration.",
    inputs=("position", "acceleration"),
    params=(q_param(108.0), r_acc_param(6.28e4), r_pos_param(), q_convention()), build=build_kalman,
    reference="paper Sec. 5.6, eqs. 16-19; Table 1 (Q = 108, R_a = 6.28e4)",
)

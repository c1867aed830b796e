"""KALLEV, KALLEVACC, KALFOAW, KALFOAWACC: KALMAN fed with a differentiated-twice acceleration (paper Sec. 5.7).

The accelerometer's low-frequency error breaks the Kalman filter's zero-mean
noise assumption, so the paper replaces (or corrects) it with an acceleration
obtained from the position by a non-linear differentiator applied twice:

    KALLEV      K(x, L(L(x)))
    KALLEVACC   K(x, L(L(x)) + H(a))
    KALFOAW     K(x, F(F(x)))
    KALFOAWACC  K(x, F(F(x)) + H(a))

K is KALMAN (``kalman.kalman_step``: state [x, v, a], measurements position
and acceleration, the same Q convention, start and numerics), L is LEVANT
(``levant.levant_core``), F is FOAW (``foaw.foaw_core``), a the measured
acceleration and H a 2nd-order Butterworth high-pass at ``hpf_hz`` (paper:
20 Hz) that removes the accelerometer's DC error. No low-pass is applied to
the position: the Kalman update handles its zero-mean noise. The output is
KALMAN's posterior velocity.

Choices the paper leaves open, and what is implemented:

- L(L(x)): both LEVANT passes use the one parameter ``c`` (Table 2 gives a
  single C = 100). The second pass differentiates the first pass's velocity,
  so strictly its Lipschitz constant bounds the jerk (m/s^3), not the
  acceleration; one shared C is the paper's set-up, and with C = 100 it covers
  jerks up to 100 m/s^3. Both passes start as ``start`` says, as LEVANT does
  (default "zero": w = 0, u1 = 0, the authors' start; "first": the observer
  at its first input); the second pass's first input is the first pass's
  first output.
- F(F(x)): the first FOAW pass on position uses ``window`` and ``margin``
  (metres), the second, on the first pass's velocity, the same ``window`` and
  ``margin_vel`` (m/s), as in Table 2 (size 12, 1e-4 m and 0.5 m/s);
  ``window`` is the paper's size, as FOAW's (``foaw.py``).
- H: scipy's ``butter(2, hpf_hz, btype="high", fs=rate, output="sos")`` run as
  one section (``biquad.py``), primed at the first sample as if the
  accelerometer had read that value for ever (``biquad.section_prime``), so a
  constant bias never reaches the measurement and a bias that appears later is
  removed with the high-pass's time constant.
- The acceleration measurement of the first sample is unused, as in KALMAN
  (the first sample initialises the filter), but it advances the
  differentiators and primes H.

State: KALMAN's 10 slots (``kalman.KALMAN_STATE``), then ``z_a`` (the
acceleration measurement K saw at the last step, for inspection), then, as
applicable, the high-pass's ``z1 z2``, two LEVANT states of 3 or two FOAW
states of ``foaw_state_size(window - 1)``:

    KALLEV      [K(10), z_a, L1(3), L2(3)]
    KALLEVACC   [K(10), z_a, H(2), L1(3), L2(3)]
    KALFOAW     [K(10), z_a, F1, F2]
    KALFOAWACC  [K(10), z_a, H(2), F1, F2]

Parameters: KALMAN's 12 (``kalman.KALMAN_PARAMS``), then ``[alpha, lambda, T, from_first]``
for LEVANT or ``[window - 1, margin, margin_vel, rate]`` for FOAW, then the
high-pass section's 5 numbers for the ``ACC`` variants.
"""

import dataclasses

import numpy as np
from numba import njit

from studyapp.estimators import kinds
from studyapp.estimators.biquad import SECTION, STATE, butter_section, section_prime, section_step
from studyapp.estimators.foaw import foaw_core, foaw_state_size, longest
from studyapp.estimators.kalman import KALMAN_PARAMS, KALMAN_STATE, kalman_params, kalman_step, q_param
from studyapp.estimators.kalman import r_acc_param, r_pos_param
from studyapp.estimators.levant import LEVANT_PARAMS, LEVANT_STATE, c_param, levant_core, levant_params, start_param
from studyapp.estimators.spec import EstimatorSpec, Param, cutoff, q_convention

Z_A = KALMAN_STATE  # state slot: the acceleration measurement of the last step
_AFTER = KALMAN_STATE + 1  # first state slot after K and z_a
_P = KALMAN_PARAMS  # first parameter after K's


def _window():
    return Param("window", 12, "samples", 2, 256, kind="int", scale="linear",
                 doc="FOAW size, the most samples in a fit, as the paper's (both passes)")


def _margin():
    return Param("margin", 1e-4, "m", 1e-9, 1e-1, doc="FOAW position margin (first pass)")


def _margin_vel():
    return Param("margin_vel", 0.5, "m/s", 1e-6, 1e3, doc="FOAW velocity margin (second pass)")


def _hpf():
    return cutoff("hpf_hz", 20.0, "accelerometer high-pass (removes DC error)")


def _c():
    return dataclasses.replace(c_param(100.0), doc="Lipschitz constant C of both LEVANT passes")


def _foaw_params(rate, params):
    return [float(longest(params["window"])), params["margin"], params["margin_vel"], rate]


def build_kallev(rate, params):
    p = np.concatenate((kalman_params(rate, params), levant_params(rate, params)))
    return p, _AFTER + 2 * LEVANT_STATE


def build_kallevacc(rate, params):
    p = np.concatenate((kalman_params(rate, params), levant_params(rate, params),
                        butter_section(params["hpf_hz"], rate, btype="high")))
    return p, _AFTER + STATE + 2 * LEVANT_STATE


def build_kalfoaw(rate, params):
    p = np.concatenate((kalman_params(rate, params), _foaw_params(rate, params)))
    return p, _AFTER + 2 * int(foaw_state_size(longest(params["window"])))


def build_kalfoawacc(rate, params):
    p = np.concatenate((kalman_params(rate, params), _foaw_params(rate, params),
                        butter_section(params["hpf_hz"], rate, btype="high")))
    return p, _AFTER + STATE + 2 * int(foaw_state_size(longest(params["window"])))


@njit(cache=True, inline="always")
def _levant_twice(s, p, x):
    """L(L(x)) on two LEVANT states starting at ``s[0]``; parameters ``p[0:4]`` (``levant.levant_params``)."""
    v1 = levant_core(s[0:LEVANT_STATE], p[0], p[1], p[2], p[3], x)
    return levant_core(s[LEVANT_STATE:2 * LEVANT_STATE], p[0], p[1], p[2], p[3], v1)


@njit(cache=True, inline="always")
def _foaw_twice(s, at, p, x):
    """F(F(x)) on two FOAW states starting at ``s[at]``; parameters ``p[0:4]``."""
    size = foaw_state_size(p[0])
    v1 = foaw_core(s, at, p[0], p[1], p[3], x)
    return foaw_core(s, at + size, p[0], p[2], p[3], v1)


@njit(cache=True, inline="always")
def _highpass(s, p, a):
    """H(a), primed at the first sample (when K has not started yet)."""
    if s[0] == 0.0:
        section_prime(p, s[_AFTER:_AFTER + STATE], a)
    return section_step(p, s[_AFTER:_AFTER + STATE], a)


@njit(cache=True, inline="always")
def step_kallev(s, p, x, a, v):
    z = _levant_twice(s[_AFTER:], p[_P:], x)
    s[Z_A] = z
    return kalman_step(s, p, x, z)


@njit(cache=True, inline="always")
def step_kallevacc(s, p, x, a, v):
    h = _highpass(s, p[_P + LEVANT_PARAMS:_P + LEVANT_PARAMS + SECTION], a)
    z = _levant_twice(s[_AFTER + STATE:], p[_P:], x) + h
    s[Z_A] = z
    return kalman_step(s, p, x, z)


@njit(cache=True, inline="always")
def step_kalfoaw(s, p, x, a, v):
    z = _foaw_twice(s, _AFTER, p[_P:], x)
    s[Z_A] = z
    return kalman_step(s, p, x, z)


@njit(cache=True, inline="always")
def step_kalfoawacc(s, p, x, a, v):
    h = _highpass(s, p[_P + 4:_P + 4 + SECTION], a)
    z = _foaw_twice(s, _AFTER + STATE, p[_P:], x) + h
    s[Z_A] = z
    return kalman_step(s, p, x, z)


# The front ends: the acceleration z each hybrid hands K at a sample, on the hybrid's own state and
# parameters, with K's started flag set as K's first step sets it (the high-pass primes on it). K's
# other slots are untouched, so a run of a front end followed by KALMAN's step on (x, z) with the
# hybrid's first KALMAN_PARAMS parameters is the hybrid, bit for bit (the optimiser's use: the
# front end's parameters are fixed while q and r_acc are tuned, evaluation/kernels.py).
@njit(cache=True, inline="always")
def front_kallev(s, p, x, a, v):
    z = _levant_twice(s[_AFTER:], p[_P:], x)
    s[0] = 1.0
    return z


@njit(cache=True, inline="always")
def front_kallevacc(s, p, x, a, v):
    h = _highpass(s, p[_P + LEVANT_PARAMS:_P + LEVANT_PARAMS + SECTION], a)
    z = _levant_twice(s[_AFTER + STATE:], p[_P:], x) + h
    s[0] = 1.0
    return z


@njit(cache=True, inline="always")
def front_kalfoaw(s, p, x, a, v):
    z = _foaw_twice(s, _AFTER, p[_P:], x)
    s[0] = 1.0
    return z


@njit(cache=True, inline="always")
def front_kalfoawacc(s, p, x, a, v):
    h = _highpass(s, p[_P + 4:_P + 4 + SECTION], a)
    z = _foaw_twice(s, _AFTER + STATE, p[_P:], x) + h
    s[0] = 1.0
    return z


SPEC_KALLEV = EstimatorSpec(
    name="KALLEV", kind=kinds.KALLEV, description="KALMAN with acceleration from LEVANT twice: K(x, L(L(x))).",
    inputs=("position",),
    params=(q_param(6.38e4), r_acc_param(195.0), r_pos_param(), _c(), q_convention("scaled"), start_param()),
    build=build_kallev, reference="paper Sec. 5.7; Table 1 (Q = 6.38e4, R_a = 195)",
)
SPEC_KALLEVACC = EstimatorSpec(
    name="KALLEVACC", kind=kinds.KALLEVACC,
    description="KALMAN with LEVANT-twice acceleration plus high-passed measured: K(x, L(L(x)) + H(a)).",
    inputs=("position", "acceleration"),
    params=(q_param(2954.0), r_acc_param(64.6), r_pos_param(), _c(), _hpf(), q_convention("scaled"),
            start_param()),
    build=build_kallevacc, reference="paper Sec. 5.7; Tables 1-2 (Q = 2954, R_a = 64.6, C = 100)",
)
SPEC_KALFOAW = EstimatorSpec(
    name="KALFOAW", kind=kinds.KALFOAW, description="KALMAN with acceleration from FOAW twice: K(x, F(F(x))).",
    inputs=("position",),
    params=(q_param(77.7), r_acc_param(8.06), r_pos_param(), _window(), _margin(), _margin_vel(),
            q_convention("scaled")),
    build=build_kalfoaw, reference="paper Sec. 5.7; Tables 1-2 (Q = 77.7, R_a = 8.06; size 12, 1e-4 m, 0.5 m/s)",
    extra={"conventions": {"window": "size"}},
)
SPEC_KALFOAWACC = EstimatorSpec(
    name="KALFOAWACC", kind=kinds.KALFOAWACC,
    description="KALMAN with FOAW-twice acceleration plus high-passed measured: K(x, F(F(x)) + H(a)).",
    inputs=("position", "acceleration"),
    params=(q_param(88.5), r_acc_param(3.85), r_pos_param(), _window(), _margin(), _margin_vel(), _hpf(),
            q_convention("scaled")),
    build=build_kalfoawacc,
    reference="paper Sec. 5.7; Tables 1-2 (Q = 88.5, R_a = 3.85; size 12, 1e-4 m, 0.5 m/s)",
    extra={"conventions": {"window": "size"}},
)

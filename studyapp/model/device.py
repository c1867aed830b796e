"""The haptic device: a small interface, and the simulated 1-DOF device behind it (paper Sec. 4).

Interface (duck-typed, mido's style: a real driver is another class with the
same methods; tests use fakes):

    device.rate                       sample rate (Hz)
    device.limits                     DeviceLimits: travel, impulsive and sustained force
    device.read_sensors() -> (x, a, v)   LVDT position (m), accelerometer (m/s^2), LVT (m/s)
    device.write_force(f)             force command (N), held until the next sample

``ClosedLoop`` runs a ``SimulatedDevice`` inside its compiled block function;
any other device is driven one sample at a time through these methods.

The simulated device is a moving mass m between end stops at +-11 mm (the
LVDT's 2.2 cm range), pushed by the motor and by the hand (hand.py). The force
command F[k] computed from the sensors at sample k is held over [k, k+1]
(zero-order hold), so the position sampled at k+1 is the first to feel it:
the one-step delay of the paper's Fig. 1 and Sec. 2. Over one step the mass
moves exactly under the constant total force f:

    x[k+1] = x[k] + T v[k] + T^2 f / (2 m),   v[k+1] = v[k] + T f / m

and an end stop is inelastic: the position is held at the stop and the
velocity into it is set to zero (a rigid stop; stable at any rate).

Motor limits (TGR, Sec. 4.1: "impulsive linear forces up to 200 N, or 60 N
sustained"): the command is clamped to +-200 N; the sustained limit is an RMS
over a window: an exponential mean of F^2 with a 1 s time constant (our
assumption; thermal limits act over seconds) and, while its root exceeds 60 N,
the clamp is +-60 N.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit


class HapticDevice:
    """The device interface. A real driver subclasses this (or just has these members)."""

    rate: float
    limits: "DeviceLimits"

    def read_sensors(self):
        """The newest sample: (LVDT position m, acceleration m/s^2, LVT velocity m/s)."""
        raise NotImplementedError

    def write_force(self, force):
        """Command ``force`` (N); it acts until the next command."""
        raise NotImplementedError


@dataclass(frozen=True)
class DeviceLimits:
    travel: float = 0.011  # m, end stops at +-travel
    impulsive: float = 200.0  # N
    sustained: float = 60.0  # N RMS
    sustained_window: float = 1.0  # s, time constant of the RMS


@dataclass(frozen=True)
class SimulatedDevice:
    """The simulated device's mechanics (calibration.py documents ``mass``)."""

    rate: float
    mass: float
    limits: DeviceLimits = DeviceLimits()

    def params(self, extra_mass=0.0):
        """Packed for the compiled loop; ``extra_mass`` (the hand's) moves with the handle."""
        p = np.zeros(N_PARAMS)
        p[DP_T] = 1.0 / self.rate
        p[DP_MASS] = self.mass + extra_mass
        p[DP_TRAVEL] = self.limits.travel
        p[DP_IMPULSIVE] = self.limits.impulsive
        p[DP_SUSTAINED] = self.limits.sustained
        p[DP_RMS_ALPHA] = 1.0 - np.exp(-1.0 / (self.rate * self.limits.sustained_window))
        return p


DP_T, DP_MASS, DP_TRAVEL, DP_IMPULSIVE, DP_SUSTAINED, DP_RMS_ALPHA = range(6)
N_PARAMS = 6
# state: true position, velocity, acceleration over the last step, mean square force
DS_X, DS_V, DS_A, DS_MS = range(4)
N_STATE = 4


@njit(cache=True, inline="always")
def clamp_force(p, s, f):
    """Clamp a force command to the motor limits and update the RMS; returns the clamped force."""
    limit = p[DP_IMPULSIVE]
    if s[DS_MS] > p[DP_SUSTAINED] * p[DP_SUSTAINED]:
        limit = p[DP_SUSTAINED]
    if f > limit:
        f = limit
    elif f < -limit:
        f = -limit
    s[DS_MS] += p[DP_RMS_ALPHA] * (f * f - s[DS_MS])
    return f


@njit(cache=True, inline="always")
def advance(p, s, f_total):
    """Move the mass over one sample under the constant force ``f_total`` (N)."""
    t = p[DP_T]
    a = f_total / p[DP_MASS]
    v0 = s[DS_V]
    x = s[DS_X] + t * v0 + 0.5 * t * t * a
    v = v0 + t * a
    stop = p[DP_TRAVEL]
    if x > stop:
        x = stop
        if v > 0.0:
            v = 0.0
    elif x < -stop:
        x = -stop
        if v < 0.0:
            v = 0.0
    s[DS_X] = x
    s[DS_A] = (v - v0) / t
    s[DS_V] = v

"""The haptic device interface and the motor limits the loop enforces on any device (paper Sec. 4).

``ClosedLoop`` (loop.py) drives every device through one call per block,
``device.exchange(control, n, out, est_out)``. The base class implements it
one sample at a time on the two methods a driver must have:

    device.rate                          sample rate (Hz)
    device.limits                        DeviceLimits: travel, impulsive and sustained force
    device.read_sensors() -> (x, a, v)   LVDT position (m), accelerometer (m/s^2), LVT (m/s)
    device.write_force(f)                force command (N), held until the next sample

so a real driver subclasses ``HapticDevice`` and writes those two; for each
sample k the base ``exchange`` reads the sensors, asks the loop for the force
(``control.sample``) and writes it. A device may override ``exchange`` with a
faster path that gives the same samples: the simulated device
(simulated_device.py) runs its mechanics, sensors and the loop's compiled
controller (``control.arrays``, control.py) in one compiled function per block.

Three optional members, with the defaults of a real device:

    device.truth()        None; a simulation returns the handle's true (x, v, a, hand force) at the
                          sample last read, which the loop records and the stability monitor and
                          contact microphone observe (else they observe the sensors)
    device.follow(g)      nothing; a simulation's virtual hand follows the gesture ``g`` (gestures.py)
    device.fault          None; a one-line text once the device itself has failed, which the loop
                          latches at the end of the block (force 0 from then on)

Motor limits (TGR, Sec. 4.1: "impulsive linear forces up to 200 N, or 60 N
sustained"): the command is clamped to +-200 N; the sustained limit is an RMS
over a window: an exponential mean of F^2 with a 1 s time constant (our
assumption; thermal limits act over seconds) and, while its root exceeds 60 N,
the clamp is +-60 N.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from studyapp.model.limits import IMPULSIVE_FORCE, SUSTAINED_FORCE, TRAVEL


@dataclass(frozen=True)
class DeviceLimits:
    travel: float = TRAVEL  # m, end stops at +-travel
    impulsive: float = IMPULSIVE_FORCE  # N
    sustained: float = SUSTAINED_FORCE  # N RMS
    sustained_window: float = 1.0  # s, time constant of the RMS

    def params(self, rate):
        """Packed for ``clamp_force`` at ``rate`` (Hz)."""
        p = np.zeros(N_LIMIT_PARAMS)
        p[LP_IMPULSIVE] = self.impulsive
        p[LP_SUSTAINED] = self.sustained
        p[LP_RMS_ALPHA] = 1.0 - np.exp(-1.0 / (rate * self.sustained_window))
        return p


LP_IMPULSIVE, LP_SUSTAINED, LP_RMS_ALPHA = range(3)
N_LIMIT_PARAMS = 3
# clamp state: the mean square force
LS_MS = 0
N_LIMIT_STATE = 1


class HapticDevice:
    """The device interface: a driver subclasses this and implements ``read_sensors`` and ``write_force``."""

    rate: float
    limits: DeviceLimits
    fault = None

    def read_sensors(self):
        """The newest sample: (LVDT position m, acceleration m/s^2, LVT velocity m/s)."""
        raise NotImplementedError

    def write_force(self, force):
        """Command ``force`` (N); it acts until the next command."""
        raise NotImplementedError

    def truth(self):
        """The true (position, velocity, acceleration, hand force) at the sample last read; None when unknown."""
        return None

    def follow(self, gesture):
        """A real device is moved by a real hand: the simulated gestures do not reach it."""

    def exchange(self, control, n, out, est_out):
        """``n`` samples of the loop, one at a time: read, ask ``control`` for the force, write.

        ``control.sample`` fills sample k of ``out`` and ``est_out`` (the loop's rows) and
        returns the force command, already clamped to ``limits`` (0 once the loop has faulted).
        """
        for k in range(n):
            sensors = self.read_sensors()
            self.write_force(control.sample(k, sensors, self.truth(), out, est_out))


@njit(cache=True, inline="always")
def clamp_force(p, s, f):
    """Clamp a force command to the motor limits and update the RMS; returns the clamped force."""
    limit = p[LP_IMPULSIVE]
    if s[LS_MS] > p[LP_SUSTAINED] * p[LP_SUSTAINED]:
        limit = p[LP_SUSTAINED]
    if f > limit:
        f = limit
    elif f < -limit:
        f = -limit
    s[LS_MS] += p[LP_RMS_ALPHA] * (f * f - s[LS_MS])
    return f

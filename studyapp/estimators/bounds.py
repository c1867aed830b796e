"""Physical bounds of the estimators' inputs: a sample beyond them is bad, like NaN.

A finite sample can still be impossible: a position of 1e30 m is a broken
sensor, cable or file, not a motion. Fed to an estimator it does lasting harm
(measured before the bounds existed: one 1e300 m sample turned every Kalman
output into NaN for good, and after one 1e30 m sample LEVANT still read
4e6 m/s two seconds later, because its observer closes an error e at a rate
of sqrt(|e|)). So the input guard (``dispatch.step_guarded``) treats a sample
whose magnitude exceeds its input's bound exactly as it treats NaN or inf:
it is replaced by the last good sample of that input and counted in
``Estimator.bad_samples``.

The bounds sit far above anything the paper's device can produce (Sec. 4.2),
so no real or simulated sample is touched, yet far below the magnitudes that
harm the kernels (in-bound worst cases are tested to recover within 0.1 s):

    POSITION_BOUND       1 m        the LVDT's whole range is 2.2 cm (+-11 mm)
    ACCELERATION_BOUND   1e5 m/s^2  the accelerometer (PCB 352C22) measures +-4,900 m/s^2
    VELOCITY_BOUND       100 m/s    the LVT tachometer on a handle that moves
                                    2.2 cm; 100 m/s would cross the travel in 0.22 ms

A sample x of an input with bound B is good when |x| <= B; NaN compares false,
so one test covers NaN, inf and the absurd.
"""

import numpy as np
from numba import njit

POSITION_BOUND = 1.0  # m
ACCELERATION_BOUND = 1e5  # m/s^2
VELOCITY_BOUND = 100.0  # m/s


@njit(cache=True, inline="always")
def good(value, bound):
    """True when ``value`` is a usable sample of an input bounded by ``bound`` (False for NaN and inf)."""
    return abs(value) <= bound


def all_good(position, acceleration, velocity):
    """True when every sample of the three arrays is within its bound (the guard would change nothing)."""
    return bool(
        np.all(np.abs(position) <= POSITION_BOUND)
        and np.all(np.abs(acceleration) <= ACCELERATION_BOUND)
        and np.all(np.abs(velocity) <= VELOCITY_BOUND)
    )

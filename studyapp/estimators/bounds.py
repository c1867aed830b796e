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

The bounds sit far above what the paper's device produces (Sec. 4.2), yet
far below the magnitudes that harm the kernels (a spike at the bound is
tested to be forgotten within 0.1 s, tests/estimators/test_estimators_extremes.py):

    POSITION_BOUND       1 m        the LVDT's whole range is 2.2 cm (+-11 mm)
    ACCELERATION_BOUND   1e5 m/s^2  the accelerometer (PCB 352C22) measures +-4,900 m/s^2
    VELOCITY_BOUND       100 m/s    the LVT tachometer on a handle that moves
                                    2.2 cm; 100 m/s would cross the travel in 0.22 ms

The simulated device (``studyapp simulate --rate 96000 --fmax 200``, 2 s,
2026-11-23) peaks at 9 mm, 0.25 m/s and 264 m/s^2. The one simulated sample
that could pass a bound is a hard hit on an end stop, which the model makes
rigid (the velocity drops to 0 in one sample): the hand driven into the stops
at 0.48 m/s (as in tests/model/test_model_extremes.py, with KALMAN observing)
gives 1.3e4 m/s^2 at 96 kHz after the accelerometer's band, so only a hit
above about 3.7 m/s would be held; the real accelerometer saturates near
4,900 m/s^2 long before.

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

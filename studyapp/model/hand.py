"""The virtual hand: an arm impedance that couples a gesture to the handle.

The arm moves the hand along the gesture's target x_g(t) (gestures.py) and the
grasp couples hand and handle through a spring and a damper:

    F_hand = K (x_g - x) + B (v_g - v)

with the hand's moving mass lumped into the handle's (loop.py adds ``mass`` to
the device's). This is the classic mass-spring-damper model of a hand holding
a haptic handle (Hogan 1984; Kuchenbecker, Park and Niemeyer 2003, "Characterizing
the human wrist for improved haptic interaction", who fit exactly this form). The
values used are in calibration.py with their sources.

A spring to a moving target means the handle lags it by F / K while a force
(the bow's friction) resists the stroke; the gesture still sets the handle's
speed, which is what the string hears.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class HandImpedance:
    mass: float  # kg, lumped into the handle
    stiffness: float  # N/m
    damping: float  # N s/m

    def params(self):
        return np.array([self.stiffness, self.damping])


HP_K, HP_B = range(2)


@njit(cache=True, inline="always")
def force(p, x_target, v_target, x, v):
    """The hand's force on the handle (N)."""
    return p[HP_K] * (x_target - x) + p[HP_B] * (v_target - v)

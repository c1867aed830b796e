"""The virtual hand: an arm impedance that moves the hand along a gesture, and the grip that couples it to the handle.

The hand (its effective mass m_h) holds the device's end-effector (mass m_e)
through the grasp: skin and grip compliance, a spring K_g and damper B_g
between the two (simulated_device.py integrates the pair). The arm drives the
hand along the gesture's target x_g(t) (gestures.py) with a feedforward of the
intended motion plus a spring and a damper around it, acting on the hand at
x_h, v_h:

    F_arm = M a_g + K (x_g - x_h) + B (v_g - v_h) + push
    F_grip = K_g (x_h - x) + B_g (v_h - v)         (on the end-effector at x, v)

M is the whole moving mass (device plus hand): people move a familiar load
with an internal model of its dynamics (Shadmehr and Mussa-Ivaldi 1994,
"Adaptive representation of dynamics during learning of a motor task",
J. Neurosci. 14), so without outside forces the handle follows the target
exactly; K and B are the arm's impedance about that motion, the classic
mass-spring-damper model of a hand on a handle (Hogan 1984; Tsuji et al. 1995,
"Human hand impedance characteristics during maintained posture", Biol. Cybern. 72;
Kuchenbecker, Park and Niemeyer 2003, who fit this form at the wrist). The values
are in calibration.py with their sources.

Under the bow's friction the handle lags the target by about F / K_g + F / K
until the push has learned the friction, but keeps the stroke's speed, which is
what the string hears. Above the grip's resonance (about 30 Hz) the hand hardly
moves with the end-effector: what the string's slips move is the end-effector.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class HandImpedance:
    mass: float  # kg, the hand's effective mass
    stiffness: float  # N/m, the arm's
    damping: float  # N s/m, the arm's

    reaction: float = 0.05  # s, time constant of the push against felt friction
    grip_stiffness: float = 3000.0  # N/m, the grasp between hand and end-effector
    grip_damping: float = 100.0  # N s/m

    def params(self, moving_mass, rate):
        """Packed for the compiled loop; ``moving_mass`` is device plus hand (kg)."""
        alpha = 0.0 if self.reaction <= 0 else 1.0 - np.exp(-1.0 / (rate * self.reaction))
        return np.array([self.stiffness, self.damping, moving_mass, alpha])


HP_K, HP_B, HP_M, HP_ALPHA = range(4)


@njit(cache=True, inline="always")
def force(p, x_target, v_target, a_target, x, v, push):
    """The arm's force on the hand at ``x``, ``v`` (N); ``push`` is its learned push against friction."""
    return p[HP_M] * a_target + p[HP_K] * (x_target - x) + p[HP_B] * (v_target - v) + push


@njit(cache=True, inline="always")
def learn_push(p, push, friction):
    """Move the push toward cancelling the felt friction force (first-order, ``reaction`` s)."""
    return push + p[HP_ALPHA] * (-friction - push)

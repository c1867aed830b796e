"""The virtual hand: an arm that follows a gesture, holding the handle through a compliant grip.

Two bodies. The hand (mass m_h: hand and forearm) follows the gesture's target
x_g(t) (gestures.py) with a feedforward of the intended motion plus a spring
and a damper around it (the arm's impedance):

    F_arm  = (m_h + m_d) a_g + K (x_g - x_h) + B (v_g - v_h) + push

and holds the handle (mass m_d, device.py) through the grip, the compliant
skin and pulp of the fingers, a spring and a damper in parallel:

    F_grip = k_g (x_h - x_d) + b_g (v_h - v_d)      (on the handle; -F_grip on the hand)
    m_h a_h = F_arm - F_grip,        m_d a_d = F_motor + F_grip

The feedforward moves the whole load (Shadmehr and Mussa-Ivaldi 1994,
"Adaptive representation of dynamics during learning of a motor task",
J. Neurosci. 14): without outside forces the pair follows the target exactly.
K and B are the classic arm impedance about that motion (Hogan 1984; Tsuji et
al. 1995, Biol. Cybern. 72); ``push`` is a slow learned push against the
friction the hand feels, so the stroke keeps its speed under the bow's drag.

Why a grip. At the stroke's few hertz the grip is stiff (the handle follows
the hand to within F / k_g), but the grip's resonance sqrt(k_g / m_d) / 2 pi
lies far below the haptic loop's 150-170 Hz, so there the handle moves as its
own mass m_d and the hand's inertia hardly takes part: the string's stick-slip
shakes the handle by tens of micrometres, as on the paper's device, and the
grip's damping b_g is the hand's share in absorbing it (Hajian and Howe 1997,
"Identification of the mechanical impedance at the human finger tip",
J. Biomech. Eng. 119: finger pad stiffness of order 10^2-10^3 N/m per finger
and damping of a few N s/m). The values are in calibration.py.

Stepped with the device: the grip force is taken at the start of a sample and
held over it, like the motor's force (device.py), and each body moves exactly
under its constant force over the sample. The explicit coupling is stable
while sqrt(k_g / m_d) T < 2 and b_g T / m_d < 2, true at every allowed rate for
the calibrated values (checked at 1 kHz in the tests).
"""

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True)
class HandImpedance:
    mass: float  # kg, the hand and forearm
    stiffness: float  # N/m, arm about the gesture
    damping: float  # N s/m, arm about the gesture
    grip_stiffness: float  # N/m, hand to handle
    grip_damping: float  # N s/m, hand to handle
    reaction: float = 0.05  # s, time constant of the push against felt friction

    def params(self, handle_mass, rate):
        """Packed for the compiled loop; ``handle_mass`` is the device's moving mass (kg)."""
        alpha = 0.0 if self.reaction <= 0 else 1.0 - np.exp(-1.0 / (rate * self.reaction))
        p = np.zeros(N_PARAMS)
        p[HP_K], p[HP_B], p[HP_M_LOAD], p[HP_ALPHA] = self.stiffness, self.damping, self.mass + handle_mass, alpha
        p[HP_M_HAND], p[HP_KG], p[HP_BG], p[HP_T] = self.mass, self.grip_stiffness, self.grip_damping, 1.0 / rate
        return p


HP_K, HP_B, HP_M_LOAD, HP_ALPHA, HP_M_HAND, HP_KG, HP_BG, HP_T = range(8)
N_PARAMS = 8
# state: hand position, velocity, learned push
HS_X, HS_V, HS_PUSH = range(3)
N_STATE = 3


@njit(cache=True, inline="always")
def grip_force(p, s, x, v):
    """The grip's force on the handle (N) for handle position ``x`` and velocity ``v``."""
    return p[HP_KG] * (s[HS_X] - x) + p[HP_BG] * (s[HS_V] - v)


@njit(cache=True, inline="always")
def advance(p, s, x_target, v_target, a_target, f_grip):
    """Move the hand over one sample under the arm's force less the grip's reaction."""
    f_arm = (p[HP_M_LOAD] * a_target + p[HP_K] * (x_target - s[HS_X]) + p[HP_B] * (v_target - s[HS_V])
             + s[HS_PUSH])
    t = p[HP_T]
    a = (f_arm - f_grip) / p[HP_M_HAND]
    s[HS_X] += t * s[HS_V] + 0.5 * t * t * a
    s[HS_V] += t * a


@njit(cache=True, inline="always")
def learn_push(p, s, friction):
    """Move the push toward cancelling the felt friction force (first-order, ``reaction`` s)."""
    s[HS_PUSH] += p[HP_ALPHA] * (-friction - s[HS_PUSH])

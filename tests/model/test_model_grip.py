"""The end-effector on the grip (simulated_device.py, issue 20 item 1): checked against scipy's ODE solver."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from studyapp.model import calibration, simulated_device
from studyapp.model.device import DeviceLimits
from studyapp.model.hand import HandImpedance
from studyapp.model.simulated_device import SimulatedDevice


def ode(m_e, m_h, k_g, b_g, f, f_arm):
    def rhs(t, s):
        x, v, xh, vh = s
        grip = k_g * (xh - x) + b_g * (vh - v)
        return [v, (f + grip) / m_e, vh, (f_arm - grip) / m_h]

    return rhs


@pytest.mark.parametrize("rate", [1000.0, 5000.0, 48000.0])
def test_one_step_of_the_pair_is_the_ode_under_held_forces(rate):
    m_e, m_h, k_g, b_g = 0.1, 0.8, 3000.0, 100.0
    phi, gamma = simulated_device.discretise(m_e, m_h, k_g, b_g, 1.0 / rate)
    s0 = np.array([1e-3, -0.05, -2e-3, 0.1])
    for f, f_arm in [(0.0, 0.0), (3.0, -1.0), (-7.5, 12.0)]:
        ref = solve_ivp(ode(m_e, m_h, k_g, b_g, f, f_arm), (0.0, 1.0 / rate), s0, rtol=1e-12, atol=1e-15).y[:, -1]
        assert phi @ s0 + gamma @ np.array([f, f_arm]) == pytest.approx(ref, rel=1e-7, abs=1e-12)


def test_the_device_under_a_constant_motor_force_follows_the_ode_for_half_a_second():
    """No arm (stiffness, damping, feedforward 0): the motor pushes the end-effector, the grip drags the hand."""
    rate = 5000.0
    hand = HandImpedance(0.8, 0.0, 0.0, reaction=0.0, grip_stiffness=3000.0, grip_damping=100.0)
    dev = SimulatedDevice(rate, mass=0.1, limits=DeviceLimits(travel=1.0), hand_impedance=hand, accelerometer=False)
    n = int(0.5 * rate)
    xs = []
    for _ in range(n):
        dev.read_sensors()
        dev.write_force(0.5)
        xs.append(dev.truth()[0])
    # the hand's feedforward is M a_g with a_g = 0 (Hold without tremor), its spring and damper 0
    t = np.arange(1, n + 1) / rate
    ref = solve_ivp(ode(0.1, 0.8, 3000.0, 100.0, 0.5, 0.0), (0.0, t[-1]), np.zeros(4), t_eval=t, rtol=1e-10,
                    atol=1e-14).y[0]
    assert np.asarray(xs) == pytest.approx(ref, rel=1e-6, abs=1e-12)
    # it ends where the whole 0.9 kg would be under 0.5 N, less the grip's stretch
    assert xs[-1] == pytest.approx(0.5 * 0.5 ** 2 / (2 * 0.9), rel=0.05)


def test_above_the_grip_the_end_effector_moves_alone():
    """At 300 Hz the hand stays put: the pair's receptance is the end-effector's on the grip to a fixed point."""
    m_e, m_h, k_g, b_g = calibration.DEVICE_MASS, calibration.HAND_MASS, calibration.GRIP_STIFFNESS, calibration.GRIP_DAMPING
    w = 2 * np.pi * 300.0
    z_grip = k_g + 1j * w * b_g
    # force on the end-effector -> its displacement, the hand free behind the grip
    hand_side = 1.0 / (1.0 / z_grip + 1.0 / (-m_h * w ** 2))
    x = 1.0 / (-m_e * w ** 2 + hand_side)
    alone = 1.0 / (-m_e * w ** 2 + z_grip)
    assert abs(x / alone - 1.0) < 0.05
    # and the hand's 0.8 kg is nowhere in it: lumped rigidly, the handle would move 9 times less
    assert abs(x) > 5.0 / ((m_e + m_h) * w ** 2)

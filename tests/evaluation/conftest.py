"""Synthetic recordings for the evaluation tests (no closed loop needed).

A stick-slip-like velocity: the handle sticks to a slowly stroking bow for
80 % of each period of f0 and slips back sharply for the rest (a zero-mean
sawtooth-like ripple with sharp transients), integrated exactly to position.
Sensors as in the paper's Sec. 4.2: LVDT position with 15 um RMS Gaussian
noise; the LVT reference is the true velocity through a 500 Hz 2nd-order
Butterworth (the tachometer's band) plus 0.115 mm/s RMS noise; the
accelerometer adds 0.22 m/s^2 RMS noise.
"""

import numpy as np
import pytest
from scipy import signal


def stick_slip(rate=5000.0, duration=1.0, f0=110.0, ripple=0.02, seed=0):
    rng = np.random.default_rng(seed)
    n = int(round(rate * duration))
    t = np.arange(n) / rate
    phase = (t * f0) % 1.0
    slip = 0.2
    ripple_v = np.where(phase < 1.0 - slip, ripple * slip, -ripple * (1.0 - slip))
    v_true = 0.05 * np.sin(2 * np.pi * 0.7 * t) + ripple_v
    x_true = np.concatenate(([0.0], np.cumsum(v_true[:-1]) / rate))
    a_true = np.gradient(v_true, 1.0 / rate)
    lvt = signal.sosfilt(signal.butter(2, 500.0, fs=rate, output="sos"), v_true)
    return {
        "t": t,
        "position": x_true + rng.normal(0.0, 15e-6, n),
        "velocity_lvt": lvt + rng.normal(0.0, 0.115e-3, n),
        "acceleration": a_true + rng.normal(0.0, 0.22, n),
        "velocity_true": v_true,
        "acceleration_true": a_true,
    }


def synthetic_recording(fmax, rate=5000.0, duration=1.0, seed=0):
    """A ``studyapp.recording.Recording`` of the synthetic signal; the ripple grows with F_max."""
    from studyapp.recording import Recording

    sig = stick_slip(rate, duration, ripple=0.01 + 0.004 * fmax, seed=seed)
    return Recording(rate, sig, {"fmax": float(fmax), "rate": rate, "source": "synthetic", "seed": seed})


@pytest.fixture(scope="session")
def synthetic():
    return stick_slip

"""A synthetic stick-slip position signal with the paper's sensor noise.

Used by the headless demo, the estimator benchmark and tests that need a
signal shaped like the paper's recordings without running the closed loop.

Velocity: a slow bow stroke ``v_bow(t) = v0 sin(2 pi f_stroke t)`` with
Helmholtz stick-slip on top: in each period 1/f0 the handle sticks (moves with
the bow) for a fraction ``1 - slip`` of the period and slips back for the rest,
so the ripple has zero mean and a sawtooth-like shape with sharp transients.
Position is the exact integral of that piecewise-linear ripple plus the stroke.

Sensors (paper Sec. 4.2): LVDT position with 15 um RMS Gaussian noise and
16-bit quantisation over 2.2 cm; LVT velocity through the tachometer's band
(a 2nd-order Butterworth at 500 Hz, started at rest on the first sample) with
0.115 mm/s RMS noise, so the LVT reference lags the true velocity as the
paper's did. A digital filter's cut-off must lie below Nyquist, so below
about 1.02 kHz the band is the highest the rate allows, ``NYQUIST_FRACTION *
rate`` (the rule of the model's sensors and every estimator cut-off).
Accelerometer with 0.22 m/s^2 RMS noise on the stroke's acceleration. The
exact velocity is returned too.
"""

import numpy as np
from scipy import signal

from studyapp.estimators.spec import NYQUIST_FRACTION

LVDT_NOISE_M = 15e-6
LVDT_RANGE_M = 0.022
LVDT_BITS = 16
LVT_NOISE_MPS = 0.115e-3
LVT_BAND_HZ = 500.0
ACC_NOISE_MPS2 = 0.22


def stick_slip(rate, duration, f0=110.0, ripple=0.02, v0=0.05, f_stroke=0.5, slip=0.2, seed=0):
    """Return a dict of arrays: t, position, velocity_true, acceleration_true,
    velocity_lvt, acceleration (noisy sensors) at ``rate`` Hz."""
    rng = np.random.default_rng(seed)
    n = int(round(rate * duration))
    t = np.arange(n) / rate
    w = 2 * np.pi * f_stroke
    phase = (t * f0) % 1.0
    # zero-mean ripple: +ripple*slip during stick, -ripple*(1-slip) during slip
    stick = phase < (1.0 - slip)
    v_ripple = np.where(stick, ripple * slip, -ripple * (1.0 - slip))
    # integral of the ripple: piecewise linear within each period, zero at period starts
    x_ripple = np.where(
        stick,
        ripple * slip * phase,
        ripple * slip * (1.0 - slip) - ripple * (1.0 - slip) * (phase - (1.0 - slip)),
    ) / f0
    velocity = v0 * np.sin(w * t) + v_ripple
    position = v0 / w * (1.0 - np.cos(w * t)) - v0 / w + x_ripple
    acceleration = v0 * w * np.cos(w * t)
    q = LVDT_RANGE_M / 2**LVDT_BITS
    band = signal.butter(2, min(LVT_BAND_HZ, NYQUIST_FRACTION * rate), fs=rate, output="sos")
    lvt = signal.sosfilt(band, velocity, zi=signal.sosfilt_zi(band) * velocity[0])[0]
    measured = np.round((position + rng.normal(0.0, LVDT_NOISE_M, n)) / q) * q
    return {
        "t": t,
        "position": measured,
        "velocity_true": velocity,
        "acceleration_true": acceleration,
        "velocity_lvt": lvt + rng.normal(0.0, LVT_NOISE_MPS, n),
        "acceleration": acceleration + rng.normal(0.0, ACC_NOISE_MPS2, n),
    }

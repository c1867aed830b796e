"""The simulated participant's measure of a condition's velocity noise.

While the participant bows, the velocity that drives the string (the selected
condition's estimate, ``v_hat``) differs from the device's true velocity ``v``.
The slow part of that difference follows the gesture and comes from the
estimator's delay; what is heard and felt as noise is the fast part. So the
measure is the RMS of the difference after a high-pass filter:

    e = HP(v_hat - v),   noise = sqrt(mean(e_k^2)),  k over the measured span

with HP a 2nd-order Butterworth high-pass at ``cutoff_hz`` (100 Hz by default,
well above bowing gestures, below the string's stick-slip fundamental), run in
second-order sections from a zero state; the first ``settle`` seconds are left
out so the filter's start-up transient does not count. Units: m/s.

This is a model of a listener, not the paper's measure (the paper found that
stationary noise measurements did not predict the ratings well, Sec. 8); it
makes the in-silico pilot's ratings follow each estimator's noise in the loop.
"""

import numpy as np
from scipy import signal

CUTOFF_HZ = 100.0
SETTLE_S = 0.02


def velocity_noise(estimate, true_velocity, rate, cutoff_hz=CUTOFF_HZ, settle=SETTLE_S):
    """RMS (m/s) of the high-passed difference between ``estimate`` and ``true_velocity``."""
    e = np.asarray(estimate, dtype=np.float64) - np.asarray(true_velocity, dtype=np.float64)
    sos = signal.butter(2, cutoff_hz, btype="highpass", fs=rate, output="sos")
    high = signal.sosfilt(sos, e)[int(round(settle * rate)):]
    if high.size == 0:
        raise ValueError(f"velocity_noise: fewer than {settle} s of samples at {rate:g} Hz")
    return float(np.sqrt(np.mean(high**2)))

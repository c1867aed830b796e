"""How a breakdown sounds: the level of what is heard below the string's pitch (dB re full scale).

A bowed string at its pitch f0 puts its sound at f0 and its harmonics
(440 Hz and up, calibration.F0); nothing of a healthy string lies below f0.
A loop that breaks down makes the handle buzz (contact_mic.py) at 100-300 Hz
(LVT, LOWPASS, LEVANT: the loop's own mode) or shake at 30-100 Hz (the Kalman
filters, against the grip), and breaks the string's tone up: both put sound
below the pitch (docs/model.md, "Hearing breakdown"). So the measure is the
level of the heard signal x in that band,

    buzz(x) = 10 log10( mean(b^2) )  (dBFS),   b = x through a band-pass LOW_HZ .. BELOW_PITCH x f0

(an 8th-order Butterworth band-pass, run forwards and backwards: no delay,
flat to within 1.3 dB over 35-300 Hz, 46 dB down at f0, where a loud string
would otherwise leak in). It is read
on the output at a fixed gain and volume (engine/signal_chain.py), where the
stimulus is linear below 1.25 x LVT's breakdown, so a rise in it is a rise in
what the listener hears. Bowed with the strokes (seed 0, the chain's gain),
from 0.5 x to 1.25 x each source's breakdown it rises by about 26 dB for LVT
(a jump between 0.8 and 1 x) and 13 dB for LOWPASS and KALLEV (their
noise-driven buzz grows into the limit cycle, 3-6 dB per step of 0.2 x):
tests/model/test_model_buzz_level.py states the rise it requires, and
docs/engine.md ("A breakdown you can hear") the figures per seed.
"""

import math

import numpy as np
from scipy import signal

from studyapp.model.calibration import F0

LOW_HZ = 30.0  # below: the strokes themselves (a few Hz), under the body's 60 Hz high-pass
BELOW_PITCH = 0.75  # the band's top, as a fraction of f0: clear of the fundamental's skirt
ORDER = 8


def band_sos(rate, f0=F0):
    return signal.butter(ORDER, (LOW_HZ, BELOW_PITCH * f0), "bandpass", fs=rate, output="sos")


def buzz_dbfs(x, rate, f0=F0):
    """The level (dBFS, RMS) of ``x`` below the string's pitch; -inf for silence."""
    x = np.asarray(x, dtype=np.float64)
    if x.size < 32:
        return -math.inf
    band = signal.sosfiltfilt(band_sos(rate, f0), x)
    power = float(np.mean(band * band))
    return 10.0 * math.log10(power) if power > 0.0 else -math.inf

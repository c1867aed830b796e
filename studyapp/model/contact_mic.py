"""What the participant hears of the handle itself: its buzz, mixed into the string's audio.

A haptic handle that goes unstable buzzes: the paper's participants found the
margin "apparent due to device oscillation and clear distortion in the sound"
(Sec. 8.2). With headphones on, that buzz reaches the ear by bone conduction
through the arm and by air from the device; with a simulated device it reaches
nobody unless the model passes it on. So the audio gets a second channel, as
if a contact microphone sat on the handle:

    audio += GAIN * HP_60(a_handle)

with a_handle the handle's acceleration (m/s^2: the simulation's true one, or
a real device's accelerometer), through the body's 60 Hz high-pass (no sound at
DC, strokes and tremor inaudible). GAIN converts m/s^2 to the audio's units
(the body filter's output, body.py): with the string above the 100-400 Hz band
(calibration.py), the band holds this channel, and GAIN is set so that the
stick-slip ripple of healthy bowing stays well below the string's own sound
(the string still sounds like a string) while the buzz of a broken loop,
saturated at +-F_max, rises at least 10 dB above the ripple in the band
(docs/model.md, "Hearing breakdown", measures both).
"""

import numpy as np
from numba import njit

from studyapp.estimators.biquad import butter_section
from studyapp.estimators.spec import NYQUIST_FRACTION
from studyapp.model.calibration import CONTACT_MIC_GAIN
from studyapp.model.sensors import section_at

HIGHPASS_HZ = 60.0
GAIN = CONTACT_MIC_GAIN  # audio units per m/s^2 (calibration.py gives the reason)


def params(rate, gain=GAIN):
    """The high-pass section (b0 b1 b2 a1 a2) with ``gain`` folded into its numerator."""
    p = butter_section(min(HIGHPASS_HZ, NYQUIST_FRACTION * rate), rate, btype="high").copy()
    p[:3] *= gain
    return p


@njit(cache=True, inline="always")
def step(p, s, a):
    """One sample of the contact microphone for the handle acceleration ``a`` (m/s^2; non-finite counts as 0).

    A real device's accelerometer feeds it: a NaN sample faults the loop (control.py), and must not stay
    in the filter's state, where it would silence the audio for the rest of the run.
    """
    if not np.isfinite(a):
        a = 0.0
    return section_at(p, 0, s, 0, a)


def new_state():
    return np.zeros(2)

"""The instrument body filter: bridge velocity -> radiated sound (the audio output).

STK's ``Bowed`` uses six fixed biquads (Esteban Maestre's violin body fit) whose
coefficients hold at one sample rate only. Here the body is designed from the
sample rate: a 2nd-order Butterworth high-pass at 60 Hz (no radiation at DC),
then peaking sections (R. Bristow-Johnson's "Audio EQ Cookbook" peaking EQ) at
the classic violin-family body resonances: the air mode A0 (~275 Hz), the
corpus modes CBR (~460 Hz) and B1- / B1+ (~550 / ~600 Hz), and the "bridge
hill" near 2.5 kHz (Gough, "The violin: Chladni patterns, plates, shells and
sounds", Eur. Phys. J. ST 145, 2007). Sections whose centre lies above
0.45 * rate are left out, so the filter exists at every rate. It only colours
the sound: nothing in the haptic loop depends on it.
"""

import numpy as np

from studyapp.estimators.biquad import butter_section
from studyapp.estimators.spec import NYQUIST_FRACTION

HIGHPASS_HZ = 60.0
# (centre Hz, Q, gain dB)
MODES = ((275.0, 8.0, 10.0), (460.0, 10.0, 8.0), (550.0, 12.0, 10.0), (600.0, 12.0, 8.0), (2500.0, 1.5, 6.0))
OUTPUT_GAIN = 0.25


def peaking(f0, q, gain_db, rate):
    """RBJ cookbook peaking-EQ biquad as 5 numbers b0 b1 b2 a1 a2 (a0 normalised)."""
    a = 10.0 ** (gain_db / 40.0)
    w0 = 2.0 * np.pi * f0 / rate
    alpha = np.sin(w0) / (2.0 * q)
    b = np.array([1.0 + alpha * a, -2.0 * np.cos(w0), 1.0 - alpha * a])
    den = np.array([1.0 + alpha / a, -2.0 * np.cos(w0), 1.0 - alpha / a])
    return np.array([b[0], b[1], b[2], den[1], den[2]]) / den[0]


def sections(rate):
    """The body filter at ``rate`` as an array of sections (rows b0 b1 b2 a1 a2); gain in row 0."""
    rows = [butter_section(min(HIGHPASS_HZ, NYQUIST_FRACTION * rate), rate, btype="high")]
    rows += [peaking(f, q, g, rate) for f, q, g in MODES if f < NYQUIST_FRACTION * rate]
    out = np.array(rows)
    out[0, :3] *= OUTPUT_GAIN
    return out


def sos(rate):
    """The same filter in scipy's sos layout (for ``scipy.signal.sosfilt``/``sosfreqz``)."""
    s = sections(rate)
    return np.column_stack([s[:, :3], np.ones(len(s)), s[:, 3:]])

"""Stability monitor: does the loop still feel and sound like a bowed string?

The paper's participants found the margin of stability while bowing, by "device
oscillation and clear distortion in the sound" (Sec. 8.3): "the point
immediately before the model no longer feels or sounds like a bowed string".
So breakdown is judged while the hand bows with the protocol's gesture, by
comparison with what the ideal sensor (TRUE, the true velocity) gives at the
same F_max: the participant's reference is a string that behaves like a string.

While bowing (``strokes``, ``strokes-validation``; ``live`` and ``playback``
judged against the strokes): the handle's velocity v (m/s: the simulation's
true velocity, or a real device's tachometer) band-passed over BAND = 50-400 Hz
(2nd-order Butterworth high-pass then low-pass), its mean square averaged over
BOW_WINDOW = 1 s (about two stroke cycles; exponential), and

    broken  =  band level > RISE * reference(F_max),   RISE = 2 (6 dB)

with reference(F_max) TRUE's band level on the same gesture at the same F_max
(bowing_reference.py: a table computed once per rate, pitch and gesture). Why
this band: below 50 Hz the strokes' own reversals fill the band (TRUE's handle
has 10-12 mm/s at 20-50 Hz, the gesture itself); above 400 Hz lie the string's
pitch and the stick-slip; between them TRUE's handle moves 3-6 mm/s while a
breaking loop buzzes at 100-300 Hz (LVT, LOWPASS, LEVANT: 20-35 mm/s at
1.25 x its breakdown) or shakes the grip at 30-100 Hz (the Kalman filters):
docs/model.md, "Breakdown while bowing". ``studyapp breakdown`` judges a whole
trial the same way (breakdown.py), with TRUE run at the same seed and F_max,
and adds the string's pitch: more than PITCH_TOLERANCE = 2 % off f0 is broken
(it catches TRUE's own breakdown, where the string leaves f0 for a higher mode).

With the hand holding (``hold``): the oscillation of a stuck string. The
handle's velocity high-passed at f0 / 2, so tremor does not count:

    level = RMS of v over the last WINDOW = 0.25 s                 (``score``, m/s)
    e(t)  = RMS of v over the last ENVELOPE = 12 ms (about one oscillation period)
    cv    = standard deviation / mean of e over the last 0.25 s
    broken  = level > VIBRATION_MIN  and  cv < CV_MAX = 0.15

A self-sustained oscillation is large and steady: the force saturates at
+-F_max, so the buzz is of order F_max / (m w), m the mass that moves at
audio rates (the end-effector: above the grip's corner the hand stays put),
with an envelope that hardly moves (cv 0.01-0.1). Estimator noise has a
random envelope (cv 0.2-0.35, Rayleigh-like). VIBRATION_MIN therefore scales
with the moving mass: IMPULSE / m, 1 mm/s for 1 kg (the rigid handle it was set
for), 10 mm/s for the 0.1 kg end-effector. The verdict lags an onset by a few
tenths of a second (cv must fall).

No friction, no breakdown. With F_max = 0 (or the force ramped to 0) the loop
feeds nothing back to the handle: whatever it does is the hand's own motion,
and it cannot be unstable. So ``engaged`` (the loop sets it: F_max x force
scale > 0) False means not broken, whatever the band holds: a pointer's jerky
bowing fills the band at F_max 0 (its target jumps at each mouse event, tens
of times a second) and was called "broken" there (issue 31).

Hysteresis. A verdict changes only when the evidence is clear, so a level
hovering at the threshold does not flip it back and forth within a trial:
broken is entered at the thresholds above and left only below lower ones,

    bowing:   enter  band > RISE x reference,          leave  band < RELEASE x reference,  RELEASE = sqrt(2) (3 dB)
    holding:  enter  level > VIBRATION_MIN, cv < CV_MAX,  leave  level < VIBRATION_MIN or cv > CV_RELEASE = 0.25

A breakdown's onset is judged exactly as before (``studyapp breakdown`` and
the simulated participant stop at the first "broken"); only the return to
"stable" comes later, once the level has fallen 3 dB below the onset's.
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators.biquad import filter_from_rest, section_from_sos
from studyapp.estimators.butterworth import sos_row
from studyapp.model import calibration
from studyapp.model.sensors import section_at

BAND = (50.0, 400.0)  # Hz, the bowing verdict's band
RISE = 2.0  # over TRUE's band level: 6 dB
PITCH_TOLERANCE = 0.02  # of f0
BOW_WINDOW = 1.0  # s
WINDOW = 0.25  # s
ENVELOPE = 0.012  # s
HIGHPASS_FRACTION = 0.5  # of f0
IMPULSE = 1e-3  # kg m/s: VIBRATION_MIN times the mass that moves at audio rates
VIBRATION_MIN = IMPULSE / calibration.DEVICE_MASS  # m/s
CV_MAX = 0.15
RELEASE = math.sqrt(2.0)  # bowing: a broken verdict holds until the band falls below this x TRUE's (3 dB)
CV_RELEASE = 0.25  # holding: ... until the envelope's cv rises above this (or the level falls below VIBRATION_MIN)

# parameter vector: high-pass section (5), long and short smoothing factors, band sections (2 x 5), band smoothing
MP_HP, MP_LONG, MP_SHORT, MP_BAND, MP_BAND_LONG = 0, 5, 6, 7, 17
N_PARAMS = 18
# state: high-pass (2), long mean of r^2, short mean of r^2, long mean of e, long mean of e^2, band sections (4),
# band mean square
MS_HP, MS_MS, MS_ENV_MS, MS_ENV_MEAN, MS_ENV_SQ, MS_BAND, MS_BAND_MS = 0, 2, 3, 4, 5, 6, 10
N_STATE = 11


def band_sos(rate):
    """The bowing band's filter at ``rate`` (scipy's sos layout, two sections: high-pass, low-pass)."""
    hi = min(BAND[1], 0.45 * rate)
    return np.vstack([sos_row(2, BAND[0], rate, "high"), sos_row(2, hi, rate, "low")])


def band_level(velocity, rate, start=0):
    """RMS (m/s) of ``velocity`` through the bowing band (causal, from rest), over its samples from ``start`` on."""
    params = np.concatenate([section_from_sos(row) for row in band_sos(rate)])
    y = filter_from_rest(params, np.ascontiguousarray(velocity, dtype=np.float64))[int(start):]
    return float(np.sqrt(np.mean(y * y))) if y.size else 0.0


@njit(cache=True, inline="always")
def observe(mp, ms, v):
    """Advance the monitor by one sample of the handle's velocity ``v`` (m/s; non-finite counts as 0)."""
    if not np.isfinite(v):
        v = 0.0
    y = section_at(mp, MP_HP, ms, MS_HP, v)
    sq = y * y
    a = mp[MP_LONG]
    ms[MS_MS] += a * (sq - ms[MS_MS])
    ms[MS_ENV_MS] += mp[MP_SHORT] * (sq - ms[MS_ENV_MS])
    e = math.sqrt(ms[MS_ENV_MS])
    ms[MS_ENV_MEAN] += a * (e - ms[MS_ENV_MEAN])
    ms[MS_ENV_SQ] += a * (e * e - ms[MS_ENV_SQ])
    b = section_at(mp, MP_BAND, ms, MS_BAND, v)
    b = section_at(mp, MP_BAND + 5, ms, MS_BAND + 2, b)
    ms[MS_BAND_MS] += mp[MP_BAND_LONG] * (b * b - ms[MS_BAND_MS])


@njit(cache=True)
def observe_block(mp, ms, velocity, level, cv):
    """``observe`` over a block, writing the running level and cv per sample."""
    for k in range(velocity.shape[0]):
        observe(mp, ms, velocity[k])
        level[k], cv[k] = verdict(ms)


@njit(cache=True, inline="always")
def verdict(ms):
    """(level, cv) from the monitor's state."""
    level = math.sqrt(max(ms[MS_MS], 0.0))
    mean = ms[MS_ENV_MEAN]
    if mean <= 0.0:
        return level, 1.0
    return level, math.sqrt(max(ms[MS_ENV_SQ] - mean * mean, 0.0)) / mean


class StabilityMonitor:
    """``.broken``, ``.score`` (= ``.level``, m/s), ``.cv``, ``.band``; the loop advances ``.state`` per sample.

    ``reference``: None judges as with the hand holding; a callable giving
    TRUE's band level (m/s) now (bowing_reference.py) judges while bowing.
    """

    def __init__(self, rate, f0=calibration.F0, reference=None):
        self.rate = float(rate)
        hp = sos_row(2, min(HIGHPASS_FRACTION * f0, 0.45 * rate), rate, "high")
        self.params = np.zeros(N_PARAMS)
        self.params[MP_HP:MP_HP + 5] = np.array([hp[0], hp[1], hp[2], hp[4], hp[5]]) / hp[3]
        self.params[MP_LONG] = 1.0 - np.exp(-1.0 / (WINDOW * rate))
        self.params[MP_SHORT] = 1.0 - np.exp(-1.0 / (ENVELOPE * rate))
        for j, sec in enumerate(band_sos(rate)):
            self.params[MP_BAND + 5 * j:MP_BAND + 5 * j + 5] = np.array([sec[0], sec[1], sec[2], sec[4], sec[5]]) / sec[3]
        self.params[MP_BAND_LONG] = 1.0 - np.exp(-1.0 / (BOW_WINDOW * rate))
        self.state = np.zeros(N_STATE)
        self.reference = reference
        self.engaged = True  # friction on: F_max x force scale > 0 (the loop sets it)
        self.reset()

    def reset(self):
        self.state[:] = 0.0
        self.level = 0.0
        self.cv = 1.0
        self.band = 0.0
        self.broken = False

    @property
    def score(self):
        """What the verdict reads (m/s): the band level while bowing, the high-passed level while holding."""
        return self.level if self.reference is None else self.band

    def judge(self):
        """Update ``level``, ``cv``, ``band`` and ``broken`` from the state (the loop calls this after each block)."""
        self.level, self.cv = verdict(self.state)
        self.band = math.sqrt(max(self.state[MS_BAND_MS], 0.0))
        if not self.engaged:
            self.broken = False
        elif self.reference is None:
            enter = self.level > VIBRATION_MIN and self.cv < CV_MAX
            leave = self.level < VIBRATION_MIN or self.cv > CV_RELEASE
            self.broken = bool(enter or (self.broken and not leave))
        else:
            reference = self.reference()
            self.broken = bool(self.band > RISE * reference or (self.broken and self.band >= RELEASE * reference))
        return self.broken

    def measure(self, velocity):
        """Feed a block of handle velocities (m/s, e.g. from a recording); returns per-sample (level, cv)."""
        r = np.ascontiguousarray(velocity, dtype=np.float64)
        level = np.empty_like(r)
        cv = np.empty_like(r)
        observe_block(self.params, self.state, r, level, cv)
        self.judge()
        return level, cv

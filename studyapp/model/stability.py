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

Above the paper's rate, a second band (issue 30): the handle's velocity
through HISS = 2.5 kHz (4th-order Butterworth high-pass) up to
min(16 kHz, HISS_TOP_FRACTION x rate) (2nd-order low-pass), mean square over
BOW_WINDOW, judged the same way against TRUE's level in that band:

    broken  =  band > RISE * reference  or  upper band > RISE * upper reference

2.5 kHz is the 5 kHz loop's Nyquist frequency: there the upper band is empty
(the rate must exceed 2.5 kHz / 0.45 = 5.6 kHz) and the verdict is exactly the
paper-rate one. At higher rates the loop makes sound up to rate / 2 and an
estimator whose parameters are counted in samples (Table 1's FOAW and LEASTSQ
windows, kept at 17 and 33 samples) hisses there: at 48 kHz the handle carries
3.1-3.4 x TRUE's upper band level at every F_max with FOAW's 17 samples, while
the sources whose noise is low-pitched stay at 0.95-1.6 x up to their buzz.
Its lower edge keeps the string's first partials and the loop's mode (about
720 Hz) out (the 4th-order high-pass puts 720 Hz 43 dB down; a 2nd-order one let
LVT's loop mode fill the band); 16 kHz is the top of most adults' hearing.

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

Perception floors (issue 42). A band counts only above the least level a
person could perceive in it, whatever TRUE's level there:

    broken  =  (band > RISE * reference  and  band > band_floor(rate))
               or  (upper band > RISE * upper reference  and  upper band > hiss_floor(rate))

band_floor: the lower of the grasp's vibrotactile threshold and the hearing
threshold through the contact microphone; hiss_floor: the hearing one only
(perception_floors.py has the tables, their sources and the conversions).
They lie 40-80 dB below TRUE's levels in this world, so they decide only
where a reference vanishes. ``bowing_over`` is the one decision the monitor
and a breakdown trial both make.

Hysteresis. A verdict changes only when the evidence is clear, so a level
hovering at the threshold does not flip it back and forth within a trial:
broken is entered at the thresholds above and left only below lower ones,

    bowing:   enter  band > RISE x reference,          leave  band < RELEASE x reference,  RELEASE = sqrt(2) (3 dB)
              (and the same for the upper band: broken while either band is above RELEASE x its reference;
              the floors hold for leaving as for entering)
    holding:  enter  level > VIBRATION_MIN, cv < CV_MAX,  leave  level < VIBRATION_MIN or cv > CV_RELEASE = 0.25

A breakdown's onset is judged exactly as before (``studyapp breakdown`` and
the simulated participant stop at the first "broken"); only the return to
"stable" comes later, once the level has fallen 3 dB below the onset's.
"""

import math

import numpy as np
from numba import njit

from studyapp.estimators.biquad import filter_from_rest, section_from_sos
from studyapp.estimators.butterworth import sos_row, sos_rows
from studyapp.model import calibration, perception_floors
from studyapp.model.sensors import section_at

BAND = (50.0, 400.0)  # Hz, the bowing verdict's band
HISS = (2500.0, 16000.0)  # Hz, the bowing verdict's upper band (its top capped at HISS_TOP_FRACTION x rate)
HISS_TOP_FRACTION = 0.45  # of the rate
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

# parameter vector: high-pass section (5), long and short smoothing factors, band sections (2 x 5), band smoothing,
# upper band sections (3 x 5; zeros where the rate has no upper band)
MP_HP, MP_LONG, MP_SHORT, MP_BAND, MP_BAND_LONG, MP_HISS = 0, 5, 6, 7, 17, 18
N_PARAMS = 33
# state: high-pass (2), long mean of r^2, short mean of r^2, long mean of e, long mean of e^2, band sections (4),
# band mean square, upper band sections (6), upper band mean square
MS_HP, MS_MS, MS_ENV_MS, MS_ENV_MEAN, MS_ENV_SQ, MS_BAND, MS_BAND_MS, MS_HISS, MS_HISS_MS = 0, 2, 3, 4, 5, 6, 10, 11, 17
N_STATE = 18


def band_sos(rate):
    """The bowing band's filter at ``rate`` (scipy's sos layout, two sections: high-pass, low-pass)."""
    hi = min(BAND[1], 0.45 * rate)
    return np.vstack([sos_row(2, BAND[0], rate, "high"), sos_row(2, hi, rate, "low")])


def band_level(velocity, rate, start=0):
    """RMS (m/s) of ``velocity`` through the bowing band (causal, from rest), over its samples from ``start`` on."""
    y = filter_from_rest(_sections(band_sos(rate)), np.ascontiguousarray(velocity, dtype=np.float64))
    return _rms(y[int(start):])


def hiss_band(rate):
    """The upper band (Hz) at ``rate``: (HISS[0], min(HISS[1], HISS_TOP_FRACTION x rate)), or None if empty."""
    top = min(HISS[1], HISS_TOP_FRACTION * float(rate))
    return (HISS[0], top) if top > HISS[0] else None


def hiss_sos(rate):
    """The upper band's filter at ``rate`` (scipy's sos layout, three sections: 4th-order high-pass, 2nd-order
    low-pass); None where the rate has no upper band."""
    band = hiss_band(rate)
    if band is None:
        return None
    return np.vstack([sos_rows(4, band[0], rate, "high"), sos_row(2, band[1], rate, "low")])


def hiss_level(velocity, rate, start=0):
    """RMS (m/s) of ``velocity`` through the upper band (causal, from rest) from ``start`` on; None without one."""
    sos = hiss_sos(rate)
    if sos is None:
        return None
    y = filter_from_rest(_sections(sos), np.ascontiguousarray(velocity, dtype=np.float64))
    return _rms(y[int(start):])


def _sections(sos):
    return np.concatenate([section_from_sos(row) for row in sos])


def _rms(y):
    return float(np.sqrt(np.mean(y * y))) if y.size else 0.0


def band_floor(rate):
    """The bowing band's perception floor (m/s RMS) at ``rate``: felt or heard (perception_floors.py)."""
    return perception_floors.floor((BAND[0], min(BAND[1], 0.45 * rate)))


def hiss_floor(rate):
    """The upper band's perception floor (m/s RMS) at ``rate``: heard only; None where the rate has no upper band."""
    band = hiss_band(rate)
    return None if band is None else perception_floors.floor(band, felt=False)


def over(level, reference, factor, floor=0.0):
    """Whether a band's ``level`` is above ``factor`` x TRUE's ``reference`` and above the band's perception
    ``floor`` (no reference, no upper band: False)."""
    return reference is not None and level is not None and level > factor * reference and level > floor


def bowing_over(band, reference, hiss, hiss_reference, factor, floors):
    """Whether either band is over ``factor`` x TRUE's level in it and over its floor; ``floors`` =
    (band_floor(rate), hiss_floor(rate)). The monitor (``judge``) and a breakdown trial both decide with it."""
    return over(band, reference, factor, floors[0]) or over(hiss, hiss_reference, factor, floors[1] or 0.0)


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
    h = section_at(mp, MP_HISS, ms, MS_HISS, v)
    h = section_at(mp, MP_HISS + 5, ms, MS_HISS + 2, h)
    h = section_at(mp, MP_HISS + 10, ms, MS_HISS + 4, h)
    ms[MS_HISS_MS] += mp[MP_BAND_LONG] * (h * h - ms[MS_HISS_MS])


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
    """``.broken``, ``.score`` (= ``.level``, m/s), ``.cv``, ``.band``, ``.hiss``; the loop advances ``.state`` per sample.

    ``reference``: None judges as with the hand holding; a callable giving
    TRUE's band level (m/s) now (bowing_reference.py) judges while bowing.
    ``hiss_reference``: None, or a callable giving TRUE's upper band level
    (m/s) now, or None where the rate has no upper band; read only while bowing.
    """

    def __init__(self, rate, f0=calibration.F0, reference=None):
        self.rate = float(rate)
        hp = sos_row(2, min(HIGHPASS_FRACTION * f0, 0.45 * rate), rate, "high")
        self.params = np.zeros(N_PARAMS)
        self.params[MP_HP:MP_HP + 5] = np.array([hp[0], hp[1], hp[2], hp[4], hp[5]]) / hp[3]
        self.params[MP_LONG] = 1.0 - np.exp(-1.0 / (WINDOW * rate))
        self.params[MP_SHORT] = 1.0 - np.exp(-1.0 / (ENVELOPE * rate))
        self._set_sections(MP_BAND, band_sos(rate))
        self.params[MP_BAND_LONG] = 1.0 - np.exp(-1.0 / (BOW_WINDOW * rate))
        hiss = hiss_sos(rate)
        if hiss is not None:  # else its sections stay 0: the kernel's upper band then reads 0
            self._set_sections(MP_HISS, hiss)
        self.floors = (band_floor(rate), hiss_floor(rate))
        self.state = np.zeros(N_STATE)
        self.reference = reference
        self.hiss_reference = None
        self.engaged = True  # friction on: F_max x force scale > 0 (the loop sets it)
        self.reset()

    def _set_sections(self, at, sos):
        for j, sec in enumerate(sos):
            self.params[at + 5 * j:at + 5 * j + 5] = np.array([sec[0], sec[1], sec[2], sec[4], sec[5]]) / sec[3]

    def reset(self):
        self.state[:] = 0.0
        self.level = 0.0
        self.cv = 1.0
        self.band = 0.0
        self.hiss = 0.0
        self.broken = False

    @property
    def score(self):
        """What the verdict reads (m/s): the band level while bowing, the high-passed level while holding."""
        return self.level if self.reference is None else self.band

    def judge(self):
        """Update ``level``, ``cv``, ``band``, ``hiss`` and ``broken`` from the state (the loop calls this after each
        block)."""
        self.level, self.cv = verdict(self.state)
        self.band = math.sqrt(max(self.state[MS_BAND_MS], 0.0))
        self.hiss = math.sqrt(max(self.state[MS_HISS_MS], 0.0))
        if not self.engaged:
            self.broken = False
        elif self.reference is None:
            enter = self.level > VIBRATION_MIN and self.cv < CV_MAX
            leave = self.level < VIBRATION_MIN or self.cv > CV_RELEASE
            self.broken = bool(enter or (self.broken and not leave))
        else:
            reference = self.reference()
            hiss = None if self.hiss_reference is None else self.hiss_reference()
            enter = bowing_over(self.band, reference, self.hiss, hiss, RISE, self.floors)
            stay = bowing_over(self.band, reference, self.hiss, hiss, RELEASE, self.floors)
            self.broken = bool(enter or (self.broken and stay))
        return self.broken

    def measure(self, velocity):
        """Feed a block of handle velocities (m/s, e.g. from a recording); returns per-sample (level, cv)."""
        r = np.ascontiguousarray(velocity, dtype=np.float64)
        level = np.empty_like(r)
        cv = np.empty_like(r)
        observe_block(self.params, self.state, r, level, cv)
        self.judge()
        return level, cv

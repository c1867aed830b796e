"""Perception floors: the least handle velocity a person could feel or hear, per band of the bowing verdict.

The bowing verdict (stability.py) compares the handle's velocity in a band
with TRUE's in the same band. A ratio alone calls any excess "broken", even
one nobody could perceive: at 48 kHz LEVANT's upper band held 0.005 mm/s
against TRUE's 0.002 at 0.05 N (issue 42, item 4). So each band also has an
absolute floor, the smallest RMS velocity (m/s) of the handle in that band
that a person could perceive, and a band counts only above both:

    broken in a band  <=>  level > RISE x TRUE's level  and  level > floor(band)

A band's level is perceived if it is felt (the hand on the handle) or heard
(the headphones), so its floor is the lower of the two:

    floor(band) = min(felt(band), heard(band))

Felt (the 50-400 Hz band). Vibrotactile detection by the Pacinian channel:
Verrillo (1963, J. Acoust. Soc. Am. 35:1962, thenar eminence, 2.9 cm^2
contactor) found the displacement threshold flat up to 40 Hz, falling at
12 dB per octave to its minimum near 250 Hz and rising above (the U-shaped
curve); Bolanowski, Gescheider, Verrillo & Checkosky (1988, J. Acoust. Soc.
Am. 84:1680, the four-channel model) put that minimum at about -20 dB re 1 um
peak, 0.1 um (PACINIAN_MIN_UM). A handle is grasped, not touched by a probe:
Brisben, Hsiao & Johnson (1999, J. Neurophysiol. 81:1548) found thresholds
through a grasped cylinder 18.5 dB lower at 300 Hz (GRASP_DB) than through a
1 mm probe vibrating perpendicular to the skin, some subjects below 0.01 um.
Taken off the large contactor's minimum (whose threshold is already below a
1 mm probe's) the correction errs low, as a floor should; the result sits
among Brisben's lowest subjects. The floor takes that grasped minimum,

    d_min = 0.1 um x 10^(-18.5 / 20) = 0.0119 um peak,

at the most sensitive frequency F_FELT = 250 Hz, as an RMS velocity:

    felt  = 2 pi F_FELT d_min / sqrt(2)  = 1.32e-5 m/s (0.0132 mm/s).

Why the most sensitive frequency and not a weighting: in velocity the
threshold 2 pi f d(f) falls as 1/f up to 250 Hz (d ~ f^-2) and rises above it,
so 250 Hz (inside 50-400 Hz at every rate the app allows) is where the least
band energy is felt; a floor there cannot excuse a level felt at any other
frequency of the band. The Pacinian channel sums energy over its band, so a
band level below the threshold of its best frequency is below threshold
whatever its spectrum. The upper band (2.5 kHz and up) is not felt: the
published curves stop near 1 kHz (Verrillo 1963, 1966), rising there, and
above 2.5 kHz the displacement of the levels in question (10^-10 m) is four
orders below them, so only its heard floor counts.

Heard (both bands). The handle's own vibration reaches the headphones through
the model's contact microphone (contact_mic.py): GAIN (audio units per m/s^2)
times its acceleration, high-passed at 60 Hz, then the stimulus gain
(stimulus_level.STIMULUS_GAIN) to full scale. For a sine of RMS velocity v
at f:

    audio (dBFS RMS) = 20 log10(STIMULUS_GAIN x GAIN x 2 pi f x |H60(f)| x v),
    |H60(f)| = f^2 / sqrt(f^4 + 60^4)         (2nd-order Butterworth high-pass)
    SPL      = audio + FULL_SCALE_SPL_DB

and it is heard where SPL exceeds the absolute threshold of hearing T(f),
ISO 226:2003 Table 1's T_f (free field, binaural, 18-25 year olds; THRESHOLD
below, 20 Hz-12.5 kHz). So

    heard(f)    = 10^((T(f) - FULL_SCALE_SPL_DB) / 20) / (STIMULUS_GAIN x GAIN x 2 pi f x |H60(f)|)
    heard(band) = min over THRESHOLD's frequencies f in the band of heard(f)

(the band's most sensitive frequency, as for touch). From 12.5 to 16 kHz the
threshold rises by a further 16-28 dB (ISO 389-5:2006's earphone thresholds,
ER-2A and HDA 200), far more than 2 pi f's 2 dB there, so the minimum lies
within the table for every band.

The listening level. The app sets no absolute level: the headphone level check
plays a tone as loud as the bowed string's typical RMS (stimulus_level.py,
experiment/level_check.py: sinclair2014's TONE_RMS_DBFS = -55.1 dBFS, docs/
engine.md "Levels") and the participant sets it comfortable. The floors take
that tone at LISTENING_SPL_DB = 80 dB SPL, the WHO-ITU H.870 (2018) safe
listening limit for adults (80 dB(A) for 40 h a week): louder than a
comfortable setting is taken to be, and a louder assumption only lowers every
heard floor, so the verdict can only be stricter than the participant's ears.
Hence FULL_SCALE_SPL_DB = 80 - (-55.1) = 135.1 dB SPL at 0 dBFS RMS.

What follows (docs/model.md, "Breakdown while bowing"): the heard floors lie
far below the felt one (the contact microphone makes the handle's buzz
audible, by design), 0.3 um/s in the 50-400 Hz band and 0.01 um/s in the upper
band, 40-80 dB under TRUE's own levels there; they change no verdict of the
world as it is, and keep a vanishing reference from turning noise into
"breakdown".
"""

import math

import numpy as np

from studyapp.model import contact_mic
from studyapp.model.stimulus_level import STIMULUS_GAIN

# ISO 226:2003, Table 1: threshold of hearing T_f (dB SPL), free field, frontal incidence, binaural
THRESHOLD = ((20.0, 78.5), (25.0, 68.7), (31.5, 59.5), (40.0, 51.1), (50.0, 44.0), (63.0, 37.5), (80.0, 31.5),
             (100.0, 26.5), (125.0, 22.1), (160.0, 17.9), (200.0, 14.4), (250.0, 11.4), (315.0, 8.6),
             (400.0, 6.2), (500.0, 4.4), (630.0, 3.0), (800.0, 2.2), (1000.0, 2.4), (1250.0, 3.5),
             (1600.0, 1.7), (2000.0, -1.3), (2500.0, -4.2), (3150.0, -6.0), (4000.0, -5.4), (5000.0, -1.5),
             (6300.0, 6.0), (8000.0, 12.6), (10000.0, 13.9), (12500.0, 12.3))
PACINIAN_MIN_UM = 0.1  # um peak at about 250 Hz (Bolanowski et al. 1988; Verrillo 1963): -20 dB re 1 um
GRASP_DB = 18.5  # a grasped cylinder's threshold below a probe's at 300 Hz (Brisben, Hsiao & Johnson 1999)
F_FELT = 250.0  # Hz, the Pacinian channel's most sensitive frequency (Verrillo 1963)
TONE_RMS_DBFS = -55.1  # sinclair2014's level check tone, the string's typical RMS (docs/engine.md, "Levels")
LISTENING_SPL_DB = 80.0  # the tone as heard: WHO-ITU H.870 (2018), adults' safe listening level
FULL_SCALE_SPL_DB = LISTENING_SPL_DB - TONE_RMS_DBFS  # 135.1 dB SPL at 0 dBFS RMS


def felt_floor():
    """The least RMS velocity (m/s) of the handle felt in the grasp: the Pacinian minimum at F_FELT."""
    d_peak = PACINIAN_MIN_UM * 1e-6 * 10.0 ** (-GRASP_DB / 20.0)
    return 2.0 * math.pi * F_FELT * d_peak / math.sqrt(2.0)


def mic_gain(f):
    """Full-scale RMS per m/s RMS of handle velocity at ``f`` Hz through the contact microphone and the stimulus
    gain."""
    f = np.asarray(f, dtype=np.float64)
    highpass = f * f / np.sqrt(f ** 4 + contact_mic.HIGHPASS_HZ ** 4)
    return STIMULUS_GAIN * contact_mic.GAIN * 2.0 * np.pi * f * highpass


def heard_velocity(f, threshold_db):
    """The RMS handle velocity (m/s) at ``f`` Hz whose sound reaches ``threshold_db`` dB SPL."""
    return 10.0 ** ((np.asarray(threshold_db, dtype=np.float64) - FULL_SCALE_SPL_DB) / 20.0) / mic_gain(f)


def heard_floor(band):
    """The least RMS handle velocity (m/s) heard in ``band`` (lo, hi) Hz: the lowest over THRESHOLD's
    frequencies within it (inf if none lies within)."""
    lo, hi = band
    f, t = np.array([row for row in THRESHOLD if lo <= row[0] <= hi]).reshape(-1, 2).T
    return float(np.min(heard_velocity(f, t))) if f.size else math.inf


def floor(band, felt=True):
    """A band's floor (m/s RMS): the lower of its felt (``felt``: a band the hand feels) and heard floors."""
    heard = heard_floor(band)
    return min(felt_floor(), heard) if felt else heard

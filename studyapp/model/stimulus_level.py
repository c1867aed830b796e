"""How loud the stimulus is: the typical RMS of the bowed string, for the headphone level check.

The experimenter sets the headphones on the level check's reference tone, so
the tone must be as loud as what the participant will mostly hear: the string
bowed with the protocol's gesture at the protocol's F_max. That level is
computed from the model itself (it follows any change to the device, the
string or the gestures), never written down by hand:

    for each condition c:  a = the loop's audio (ClosedLoop, bow on, F_max, gesture), after SETTLE_S
                           L_c = median over 100 ms windows w of 20 log10 sqrt(mean(a_w^2))   (dBFS)
    level = median over c of L_c

The median of short-term (100 ms) RMS is the level of the string while it
sounds, not pulled down by the reversals of the strokes nor up by a burst.
Full scale is the audio's 1.0, as in the engine's output at volume 1 (the
resampler to the device's rate keeps the RMS of this band-limited signal:
tests/engine check it against the signal chain's output).

A sine's RMS is its peak / sqrt(2), so a tone of that RMS has its peak
3.01 dB higher (``tone_peak_dbfs``).

The stimulus gain. The loop's audio is in its own unit (the body filter's
output, model/body.py, plus the handle's buzz, model/contact_mic.py); the
signal chain (engine/signal_chain.py) scales it by one fixed gain G before
anything else, so that the stimulus stays linear, under the output
limiter's knee (-18 dBFS), over every F_max a protocol's knob reaches below
1.25 x LVT's bowing breakdown as it was when the gain was set (8.29 N,
``studyapp breakdown --source LVT``, docs/breakdown.md of 2026-11-25: 10.4 N;
since issue 42's sensors and string LVT breaks at 7.40 N, so 10.4 N is 1.4 x
it, and tests/engine/test_engine_gain_staging.py holds the headroom on the
world as it is). The string gets louder with F_max: bowed with
the strokes, its peaks rise from about -11 dB (re the audio's unit) at 1 N to
at most LOUDEST_DB = +11 dB up to 10.4 N for any of sinclair2014's nine
conditions (seed 0: +6.9 to +10.8 dB at 10.4 N; a knob sweep reaches +11.8 dB
over 10.4-12 N); so

    G = KNEE - HEADROOM_DB - LOUDEST_DB = -18 - 4 - 11 = -33 dB,

4 dB of headroom under the knee at 1.25 x LVT's breakdown, and the rating
task's 1 N about -55 dBFS RMS, -44 dBFS peak. Above that F_max (broken loops
buzzing at +-F_max) the limiter bends what passes the knee, and counts it.
The volume (-40 to 0 dB) only attenuates: the listener sets the headphones'
comfort with the level check, heard at this gain (``typical_rms_dbfs``
includes it). docs/engine.md ("Levels") has the figures.
"""

import math
from functools import lru_cache

import numpy as np

from studyapp.model.sources import is_pseudo

WINDOW_S = 0.1  # short-term RMS window
SETTLE_S = 1.0  # the start of bowing left out (the string building up)
SECONDS = 6.0  # bowed per condition (several strokes)
SINE_CREST_DB = 20.0 * math.log10(math.sqrt(2.0))  # 3.01 dB: a sine's peak over its RMS
LVT_BREAKDOWN_N = 8.29  # the gain's design point: LVT's bowing breakdown on 2026-11-25 (N, median of 5 seeds)
LINEAR_UP_TO_N = 1.25 * LVT_BREAKDOWN_N  # 10.4 N: the stimulus is linear (under the knee) up to here
LOUDEST_DB = 11.0  # the loudest bowed peak up to 1.25 x LVT's breakdown, dB re the audio's unit (above)
HEADROOM_DB = 4.0  # under the limiter's knee there
KNEE_DBFS = -18.0  # the output limiter's knee: the stimulus stays under it (engine/signal_chain.py's limiter)
STIMULUS_GAIN_DB = KNEE_DBFS - HEADROOM_DB - LOUDEST_DB  # -33 dB: the loop's audio -> the output (above)
STIMULUS_GAIN = 10.0 ** (STIMULUS_GAIN_DB / 20.0)


def short_term_rms_dbfs(audio, rate, window_s=WINDOW_S):
    """The median over ``window_s`` windows of the RMS of ``audio`` (dBFS; -inf for silence)."""
    n = max(1, int(round(window_s * rate)))
    whole = np.asarray(audio, dtype=np.float64)[: len(audio) // n * n].reshape(-1, n)
    if whole.size == 0:
        return -math.inf
    level = float(np.median(np.sqrt(np.mean(whole**2, axis=1))))
    return 20.0 * math.log10(level) if level > 0 else -math.inf


@lru_cache(maxsize=16)
def _typical(rate, gesture, fmax, conditions, seed, seconds):
    from studyapp.model.loop import ClosedLoop, LoopConfig  # numba: the schedule (level_check) imports this module

    levels = []
    for name, params in conditions:
        estimators = {} if is_pseudo(name) else {name: dict(params)}
        loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=name, fmax=fmax,
                                     gesture=gesture, seed=seed, audio=True))
        audio = loop.run(int(round(seconds * rate)))["audio"][int(round(SETTLE_S * rate)):]
        levels.append(short_term_rms_dbfs(STIMULUS_GAIN * audio, rate))
    return float(np.median(levels))


def typical_rms_dbfs(rate, gesture, fmax, conditions, seed=0, seconds=SECONDS):
    """The typical RMS (dBFS) of the string bowed with ``gesture`` at ``fmax`` N.

    ``conditions``: velocity sources, a list of names or a dict name -> estimator parameters.
    """
    if not isinstance(conditions, dict):
        conditions = {name: {} for name in conditions}
    frozen = tuple((name, tuple(sorted(params.items()))) for name, params in conditions.items())
    return _typical(float(rate), str(gesture), float(fmax), frozen, int(seed), float(seconds))


def tone_peak_dbfs(rms_dbfs):
    """The peak level of a sine whose RMS is ``rms_dbfs``."""
    return rms_dbfs + SINE_CREST_DB

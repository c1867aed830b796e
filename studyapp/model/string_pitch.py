"""The pitch the waveguide string sounds at: what playable.py's bound rate >= 6 f0 rests on (issue 30, item 2).

Each measure is the spectral peak of the string's velocity at the bow
(``bowing_reference.pitch``: Hann window, 4x zero padding, parabolic
interpolation), searched above f0 / 2:

- ``alone_pitch``: the string by itself (bowed_string.run) under a constant
  bow velocity (0.18 string units, the strokes' 0.15 m/s), over the second
  half of the run: the waveguide's own pitch;
- ``cruise_pitches``: TRUE bowed on the strokes through the closed loop, one
  pitch per stroke cruise, a cruise being where the handle's speed (mean over
  10 ms) exceeds 0.8 x calibration.STROKE_SPEED, less its first 20 ms, and at
  least 8 periods long (``cruise_pitch``: their median).

tests/model/test_model_playable.py and scripts/string_pitch.py measure with these.
"""

import numpy as np

from studyapp.model import bowed_string, calibration
from studyapp.model.bowing_reference import pitch
from studyapp.model.bowed_string import StringDesign
from studyapp.model.loop import ClosedLoop, LoopConfig

BOW_VELOCITY = 0.18  # string units: the strokes' 0.15 m/s
CRUISE_SPEED = 0.8  # of calibration.STROKE_SPEED
SPEED_WINDOW = 0.01  # s
CRUISE_SKIP = 0.02  # s, the start of each cruise left out
CRUISE_PERIODS = 8  # periods of f0 a cruise needs


def alone_pitch(rate, f0, v_bow=BOW_VELOCITY, seconds=1.0):
    """The pitch (Hz) of the string alone under a constant bow of ``v_bow`` string units, over its second half."""
    design = StringDesign(rate, f0)
    state, bridge, nut = design.new_state()
    n = int(seconds * rate)
    u, v_string, v_bridge = np.zeros(n), np.zeros(n), np.zeros(n)
    bowed_string.run(design.params(), state, bridge, nut, np.full(n, v_bow), True, u, v_string, v_bridge)
    return pitch(v_string[n // 2:], rate, fmin=0.5 * f0)


def cruise_pitches(rate, f0, fmax, seed=0, seconds=2.5):
    """The pitch (Hz) of each stroke cruise of TRUE bowing the strokes at ``fmax`` N for ``seconds``."""
    loop = ClosedLoop(LoopConfig(rate=rate, source="TRUE", fmax=fmax, gesture="strokes", seed=seed, f0=f0,
                                 audio=False), judge=False)
    block = loop.run(int(seconds * rate))
    m = max(1, int(SPEED_WINDOW * rate))
    speed = np.convolve(np.abs(block["velocity_true"]), np.ones(m) / m, "same")
    cruise = (speed > CRUISE_SPEED * calibration.STROKE_SPEED).astype(np.int8)
    edges = np.flatnonzero(np.diff(np.r_[0, cruise, 0]))
    return [pitch(block["string_velocity"][a:e], rate, fmin=0.5 * f0)
            for a, e in zip(edges[::2] + int(CRUISE_SKIP * rate), edges[1::2])
            if (e - a) * f0 / rate >= CRUISE_PERIODS]


def cruise_pitch(rate, f0, fmax, seed=0, seconds=2.5):
    """The median of ``cruise_pitches`` (Hz); NaN when no cruise is long enough."""
    found = cruise_pitches(rate, f0, fmax, seed, seconds)
    return float(np.median(found)) if found else float("nan")

"""TRUE's band levels while bowing: the reference the stability monitor judges a live loop against.

The bowing verdict (stability.py) compares the handle's velocity in the band
stability.BAND, and in the upper band stability.hiss_band(rate) where the rate
has one (above 5.6 kHz), with what the ideal sensor gives on the same gesture
at the same F_max. A breakdown search (breakdown.py) runs TRUE beside each
trial; a live loop cannot, so it reads this table instead: TRUE's level in each
band (stability.band_level and stability.hiss_level over [SETTLE, DURATION] s
of the gesture from rest) at F_max on a log grid GRID (0.05-200 N, 25 points,
a factor 1.41 apart), interpolated linearly in log F_max and log level, and
held constant outside the grid. TRUE's string stays at its pitch up to about
22 N (5 kHz); above the first grid point where it leaves f0 by more than
stability.PITCH_TOLERANCE, the table holds the last healthy levels (a broken
TRUE is no reference).

TRUE's run does not depend on the seed (it reads no sensor) and the strokes
are deterministic, so one table per (rate, f0, gesture) serves every seed. It
is computed on first use (about 0.3 s at 5 kHz, 3-5 s at 48 kHz) and kept for
the process. ``live`` and ``playback`` read the strokes' table: the
protocol's strokes stand for a person's bowing.

The table's memory sets the peak of a short ``studyapp simulate`` at high
rates (issue 30, item 4), so each run goes a block of ``RUN_BLOCK`` samples at
a time (the loop's result does not depend on how it is cut) keeping only the
two columns it measures, and its pitch (whether TRUE is still within
PITCH_TOLERANCE of f0) is taken on a transform of at most ``TABLE_POINTS`` =
2^18 points: at 96 kHz the 4x padded transform of 2^20 points took 28 MB
while it ran, one of 2^18 about 7 MB (bins 0.37 Hz apart before the parabolic
interpolation). Up to about 29 kHz nothing changes (4x padding stays within
2^18 points); above, the tables equal those of the 4x padded pitch
(tests/model/test_model_bowing_reference.py at 48 kHz; by hand at 96 kHz with
f0 150 and 440 Hz, 48 kHz with 2000 Hz, 2026-11-27). Less padding is not
harmless everywhere: the argmax can move between two peaks of near equal
height (at 1 kHz with f0 150 Hz, unpadded, two grid points changed).
"""

import functools
import math

import numpy as np

from studyapp.model import stability

RUN_BLOCK = 4096  # samples
TABLE_POINTS = 1 << 18  # the most points of the table's pitch transform (module docstring)
GRID = tuple(float(f) for f in np.geomspace(0.05, 200.0, 25))
DURATION = 2.5  # s
SETTLE = 0.25  # s
TABLE_GESTURE = {"strokes": "strokes", "strokes-validation": "strokes-validation", "live": "strokes",
                 "playback": "strokes"}


def pitch(x, rate, fmin=100.0, max_points=None):
    """Frequency (Hz) of the largest spectral peak of ``x`` above ``fmin`` (Hann window, zero padding, parabolic).

    The transform has the first power of 2 at or above 4x the samples, at most
    ``max_points`` (when given) unless the samples alone are more.
    """
    x = np.asarray(x, dtype=np.float64) - np.mean(x)
    if x.size < 8 or not np.any(x):
        return math.nan
    n = 1 << int(np.ceil(np.log2(x.size * 4)))
    if max_points is not None:
        n = max(min(n, int(max_points)), 1 << int(np.ceil(np.log2(x.size))))
    x *= np.hanning(x.size)
    spec = np.abs(np.fft.rfft(x, n))
    del x
    step = 1.0 / (n * (1.0 / rate))  # the bins' spacing, as np.fft.rfftfreq computes it: bin i is at i * step
    low = min(spec.size, int(fmin / step) + 2)
    spec[:low][np.arange(low) * step < fmin] = 0.0
    i = int(np.argmax(spec))
    if i == 0 or i + 1 >= spec.size or min(spec[i - 1:i + 2]) <= 0.0:
        return float(i * step)
    a, b, c = np.log(spec[i - 1:i + 2])
    den = a - 2.0 * b + c
    return float(i * step + (0.5 * (a - c) / den if den != 0.0 else 0.0) * step)


def true_run(rate, f0, gesture, fmax, duration=DURATION, seed=0):
    """(band level, upper band level or None, pitch) of TRUE bowing ``gesture`` at ``fmax`` for ``duration`` s,
    measured after SETTLE."""
    from studyapp.model.loop import ClosedLoop, LoopConfig  # the loop imports this module

    loop = ClosedLoop(LoopConfig(rate=rate, estimators={}, source="TRUE", fmax=fmax, gesture=gesture, f0=f0,
                                 seed=seed, audio=False), judge=False)
    total = int(round(duration * loop.rate))
    velocity, string = np.empty(total), np.empty(total)
    for done in range(0, total, RUN_BLOCK):
        block = loop.run(min(RUN_BLOCK, total - done))
        velocity[done:done + RUN_BLOCK] = block["velocity_true"]
        string[done:done + RUN_BLOCK] = block["string_velocity"]
    start = int(round(SETTLE * loop.rate))
    return measures(velocity, string, loop.rate, start, max_points=TABLE_POINTS)


def measures(velocity, string_velocity, rate, start, max_points=None):
    """(band level, upper band level or None, pitch) of a bowing run's handle and string velocities from ``start``."""
    return (stability.band_level(velocity, rate, start), stability.hiss_level(velocity, rate, start),
            pitch(string_velocity[start:], rate, max_points=max_points))


@functools.lru_cache(maxsize=16)
def table(rate, f0, gesture):
    """(log F_max, log band level, log upper band level or None) arrays of TRUE over GRID, held after TRUE leaves
    its pitch."""
    levels = []
    for fmax in GRID:
        band, hiss, p = true_run(rate, f0, gesture, fmax)
        if levels and not abs(p / f0 - 1.0) <= stability.PITCH_TOLERANCE:
            band, hiss = levels[-1]
        levels.append((max(band, 1e-12), None if hiss is None else max(hiss, 1e-12)))
    band, hiss = zip(*levels)
    return (np.log(np.array(GRID)), np.log(np.array(band)),
            None if hiss[0] is None else np.log(np.array(hiss)))


def level(rate, f0, gesture, fmax):
    """TRUE's band level (m/s) at ``fmax`` on ``gesture`` (``hold`` has none: None)."""
    return _interpolated(rate, f0, gesture, fmax, 1)


def hiss_level(rate, f0, gesture, fmax):
    """TRUE's upper band level (m/s) at ``fmax`` on ``gesture`` (``hold``, or a rate without the band: None)."""
    return _interpolated(rate, f0, gesture, fmax, 2)


def _interpolated(rate, f0, gesture, fmax, column):
    name = TABLE_GESTURE.get(gesture)
    if name is None:
        return None
    found = table(float(rate), float(f0), name)
    if found[column] is None:
        return None
    return float(np.exp(np.interp(math.log(max(fmax, GRID[0])), found[0], found[column])))

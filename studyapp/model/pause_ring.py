"""The string between strokes: what rings while the bow is held still (issue 42, item 7).

While the bow sticks it pins the string at the bow point, so the two
segments ring on their own: the nut side at f0 / (1 - beta), the bridge side
at f0 / beta. ``ring_levels`` measures the nut segment's ring in each pause
of the ``strokes`` gesture (where the gesture's target velocity is 0, the
dwell at each end, less its first ``SETTLE`` seconds) against the bowed level:

    A(x, band) = max over the band of 2 |X(f)| / sum(w)    (Hann window w, 8x zero padding)

is the amplitude of the largest sinusoid of ``x`` in ``band``; the pause's
ring level is A(pause, f_ring +- 5 %) and the bowed level the median of
A(cruise, f0 +- 20 %) over the strokes' cruises (where the target speed is
the full stroke speed), both in dB of the same signal: the audio (what the
participant hears: the bridge through the body plus the contact microphone)
and the handle's true velocity (what the hand feels).

``ring_decay`` is the ring's decay rate (dB/s) in a pause: the slope of a
straight line fitted to 20 log10 of the band's amplitude over consecutive
windows of ``DECAY_WINDOW`` seconds. bowed_string.py says why a segment
pinned by the bow must decay at least as fast as the whole string does by
its own losses, 20 f0 log10(loss) dB/s.
"""

from dataclasses import replace

import numpy as np

from studyapp.model import calibration
from studyapp.model.gestures import Strokes
from studyapp.model.loop import ClosedLoop, LoopConfig

SETTLE = 0.005  # s: the pause's start left out (the last slip of the stroke's reversal)
RING_BAND = 0.05  # of f_ring, each side
BOWED_BAND = 0.2  # of f0, each side
DECAY_WINDOW = 0.02  # s
SIGNALS = ("audio", "velocity_true")


def amplitude(x, rate, lo, hi):
    """(amplitude, frequency) of the largest sinusoid of ``x`` between ``lo`` and ``hi`` Hz (docstring)."""
    x = np.asarray(x, dtype=np.float64)
    w = np.hanning(x.size)
    n = 8 * x.size
    spec = np.abs(np.fft.rfft((x - x.mean()) * w, n)) * 2.0 / w.sum()
    freq = np.fft.rfftfreq(n, 1.0 / rate)
    inside = (freq > lo) & (freq < hi)
    i = int(np.argmax(np.where(inside, spec, -1.0)))
    return float(spec[i]), float(freq[i])


def intervals(mask):
    """(start, end) index pairs of the runs of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.r_[0, mask.astype(np.int8), 0]))
    return list(zip(edges[::2], edges[1::2]))


def strokes_phases(t):
    """(pauses, cruises): index intervals of the strokes gesture's dwells and full-speed cruises at times ``t``."""
    g = Strokes(calibration.STROKE_AMPLITUDE, calibration.STROKE_SPEED, calibration.STROKE_RAMP,
                calibration.STROKE_DWELL)
    _, v, _ = g.at(t)
    rate = 1.0 / (t[1] - t[0])
    skip = int(round(SETTLE * rate))
    full = int(0.9 * g.dwell * rate)  # a whole dwell, not the run's first sample nor one cut by its end
    pauses = [(a + skip, e) for a, e in intervals(v == 0.0) if e - a >= full]
    cruises = [(a, e) for a, e in intervals(np.abs(v) >= 0.999 * g.speed) if (e - a) >= 0.02 * rate]
    return pauses, cruises


STRING_PARAMS = 7  # Control.arrays[7]: the string's parameter vector (control.py ``sample``'s unpacking)


def run_strokes(rate, fmax, seed, source="TRUE", seconds=2.5, f0=calibration.F0, nut_loss=True):
    """(the loop's outputs, its StringDesign) with ``source`` bowing the strokes at ``fmax`` N for ``seconds``.

    ``nut_loss=False`` runs STK's lumped losses (bowed_string.py; the string before 2026-11-29) for comparison.
    """
    estimators = [] if source in ("TRUE", "LVT") else [source]
    loop = ClosedLoop(LoopConfig(rate=rate, source=source, fmax=fmax, gesture="strokes", seed=seed, f0=f0,
                                 estimators=estimators), judge=False)
    string = replace(loop.string, nut_loss=nut_loss)
    loop.control.arrays[STRING_PARAMS][:] = string.params()
    return loop.run(int(round(seconds * rate))), string


def ring_levels(block, rate, f0, beta):
    """{signal: (dB of the ring at f0 / (1 - beta) in each pause, its frequency in Hz)} against the bowed level."""
    pauses, cruises = strokes_phases(block["t"])
    f_ring = f0 / (1.0 - beta)
    out = {}
    for name in SIGNALS:
        x = block[name]
        bowed = np.median([amplitude(x[a:e], rate, (1 - BOWED_BAND) * f0, (1 + BOWED_BAND) * f0)[0]
                           for a, e in cruises])
        rings = [amplitude(x[a:e], rate, (1 - RING_BAND) * f_ring, (1 + RING_BAND) * f_ring) for a, e in pauses]
        out[name] = (np.array([20.0 * np.log10(r / bowed) for r, _ in rings]), np.array([f for _, f in rings]))
    return out


def ring_decay(x, rate, f_ring):
    """The ring's decay (dB/s, positive when it decays) over one pause ``x`` (docstring)."""
    m = int(round(DECAY_WINDOW * rate))
    levels = [20.0 * np.log10(amplitude(x[i:i + m], rate, (1 - RING_BAND) * f_ring, (1 + RING_BAND) * f_ring)[0])
              for i in range(0, x.size - m + 1, m)]
    t = np.arange(len(levels)) * DECAY_WINDOW
    return float(-np.polyfit(t, levels, 1)[0])


def free_decay(loss, f0):
    """The whole string's own decay (dB/s): a round trip of 1 / f0 s multiplies a wave by ``loss`` at DC."""
    return -20.0 * f0 * np.log10(loss)

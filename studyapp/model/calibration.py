"""Calibration: the simulated world's constants, each with its source or reason.

What the world must show (issue 11, paper Secs. 4, 7-8), at 5 kHz:
breakdown F_max for LVT within 5-15 N with LOWPASS at 0.3-0.7 of it (Fig. 7:
the tachometer reached about twice the range of the estimators); a verdict
that does not depend on the seed; a breakdown that a participant can hear;
and a stick-slip ripple on the handle that the sensors can see.

Two invariants decide most of it (measured, `studyapp breakdown`). (1) While
the bow sticks, the string acts on the handle like a damper
B = 0.98 G s = F_max / v_break with v_break = breakaway / s the handle speed at
which a bow on a string at rest slips. (2) Breakdown F_max scales as
m_loop / s, with m_loop the mass that moves at the loop mode's frequency
(about f0 / (1 - beta)), while the ripple at a given F_max scales as
1 / m_loop. So a light handle gives ripple, a small velocity scale s gives
range, and the bow speed in string units (s times the stroke speed) must stay
in the bow table's Helmholtz range (0.02-0.05 string units at slope 3, checked
on the string alone), with strokes that fit the device's +-11 mm.

The levers, and what each does:
- A compliant grip (hand.py): the hand's 0.8 kg hangs on the handle through
  the finger pads, so at the loop's 100-170 Hz only the device's own mass
  moves (m_loop = DEVICE_MASS), while the strokes' few hertz still carry the
  hand's force.
- A lower string (F0 = 98 Hz): the loop mode moves down with it (112 Hz),
  where a source's lag costs less phase, and the ripple grows as 1 / f^2.
- A lossy nut (NUT_REFLECTION): STK lumps all of the string's loss at the
  bridge, so while the bow sticks the nut-side segment, the resonator of the
  loop mode, rings with only the bow table's 2 % loss per round trip. Real
  strings lose energy along their length and at both ends; a 7 % loss at the
  nut doubles every source's breakdown F_max (measured: LVT 1.1 -> 2.0 N, LOWPASS
  0.5 -> 1.1 N on a 0.1 kg handle) and leaves the pitch alone (the reflection is
  real, so it adds no delay). The bridge keeps STK's loss, so the string's DC
  round-trip gain stays below 1 at each end (a bridge gain above 1 at DC
  would let a slipping bow stay stuck to a string that keeps moving after the
  bow stops).

What it does not reach (docs/model.md, "Calibration"): on strokes the ripple
during cruise is 4-6 um RMS at 2 N and 10-12 um at 8 N, not 10-60 um over the
whole 2-8 N range; a lighter handle or a smaller s would move every breakdown
below the 5 N floor or the bow out of the Helmholtz range at speeds a +-11 mm
stroke allows.

Constants (SI):

F0 = 98 Hz: the string's pitch (G2, a cello's G string). At 5 kHz it leaves
    51 samples per period.
DEVICE_MASS = 0.04 kg: the moving parts at the handle: the TGR key's slider
    with the LVT's 15 g moving magnet and the 0.5 g accelerometer (paper
    Sec. 4.2). The paper gives no moving mass; this is our assumption, chosen
    for the ripple (above).
HAND_MASS = 0.8 kg: the hand and forearm's effective translational inertia
    (Tsuji et al. 1995, "Human hand impedance characteristics during
    maintained posture", Biol. Cybern. 72: 0.5-2 kg).
HAND_STIFFNESS = 5000 N/m, HAND_DAMPING = 70 N s/m: the arm's impedance about
    the intended motion, a firm co-contracted grasp (Gomi and Osu 1998,
    J. Neurosci. 18; relaxed postures are 100-800 N/m and 2-20 N s/m).
GRIP_STIFFNESS = 10 kN/m, GRIP_DAMPING = 10 N s/m: the finger pads between
    hand and handle, several fingers in parallel (Hajian and Howe 1997,
    J. Biomech. Eng. 119: of order 10^3 N/m and a few N s/m per finger). The
    handle on the grip resonates at sqrt(k / m) / 2 pi = 80 Hz, below the loop
    mode, so there the handle moves as its own mass.
HAND_REACTION = 0.05 s: the hand learns to push against the felt friction
    with this time constant (long-latency reflex, 50-100 ms).
TREMOR_AMPLITUDE = 20 um, TREMOR_HZ = 9: physiological tremor of a held hand
    (Elble and Koller 1990, "Tremor").
VELOCITY_SCALE = 0.13 string units per m/s: with STK's slope 3 the breakaway
    is 0.085 units, so v_break = 0.65 m/s; the strokes below bow at 0.0195
    units, at the low end of the Helmholtz range.
NUT_REFLECTION = 0.93: the nut's reflection (above).
STROKE_AMPLITUDE = 8 mm, STROKE_SPEED = 0.15 m/s, STROKE_RAMP = 0.03 s,
    STROKE_DWELL = 0.25 s: detached strokes of 16 mm (3 mm from the stops)
    at a moderate bowing speed, with a pause at each reversal (martele-like):
    a resting bow is where a broken loop buzzes, so the pause is where a
    participant hears it on strokes.
VALIDATION_STROKES: the second data set's slightly different strokes
    (paper Sec. 7.3).
"""

import numpy as np

F0 = 98.0
DEVICE_MASS = 0.04
HAND_MASS = 0.8
HAND_STIFFNESS = 5000.0
HAND_DAMPING = 70.0
HAND_REACTION = 0.05
GRIP_STIFFNESS = 10000.0
GRIP_DAMPING = 10.0
TREMOR_AMPLITUDE = 20e-6
TREMOR_HZ = 9.0
VELOCITY_SCALE = 0.13
NUT_REFLECTION = 0.93
STROKE_AMPLITUDE = 0.008
STROKE_SPEED = 0.15
STROKE_RAMP = 0.03
STROKE_DWELL = 0.25
VALIDATION_STROKES = dict(amplitude=0.007, speed=0.17, ramp=0.04, dwell=0.3)

BREAKDOWN_SETTLE = 0.25  # s before the monitor's verdict counts (its window)
BREAKDOWN_BLOCK = 0.05  # s


def describe():
    """The constants as a dict (stored in recordings' metadata)."""
    return {k.lower(): v for k, v in globals().items() if k.isupper() and not k.startswith("BREAKDOWN")}


def is_broken(source, fmax, rate=5000.0, gesture="hold", duration=4.0, seed=0, estimators=None, f0=None):
    """Whether the stability monitor flags breakdown within ``duration`` s at ``fmax`` N."""
    from studyapp.model.loop import ClosedLoop, LoopConfig

    estimators = dict(estimators or {})
    if source not in ("LVT", "TRUE") and source not in estimators:
        estimators[source] = {}
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture=gesture,
                                 f0=F0 if f0 is None else f0, seed=seed, audio=False))
    block = max(1, int(round(BREAKDOWN_BLOCK * loop.rate)))
    settle = int(round(BREAKDOWN_SETTLE * loop.rate))
    done = 0
    total = int(round(duration * loop.rate))
    while done < total:
        loop.run(block)
        done += block
        if loop.fault is not None or (done >= settle and loop.monitor.broken):
            return True
    return False


def breakdown_fmax(source, rate=5000.0, gesture="hold", duration=4.0, low=0.05, high=200.0, tolerance=0.02,
                   seed=0, estimators=None, f0=None):
    """The largest F_max (N) at which ``source`` stays stable, by bisection on a log scale.

    Stable means: the stability monitor (stability.py) does not flag breakdown
    within ``duration`` s with the hand holding the handle (``gesture="hold"``,
    with tremor). Returns ``low`` if even ``low`` breaks down and ``inf`` if
    ``high`` does not; otherwise the geometric midpoint of the final bracket,
    whose width is at most ``tolerance`` (relative).
    """
    kwargs = dict(rate=rate, gesture=gesture, duration=duration, seed=seed, estimators=estimators, f0=f0)
    if is_broken(source, low, **kwargs):
        return low
    if not is_broken(source, high, **kwargs):
        return float("inf")
    lo, hi = low, high
    while hi / lo > 1.0 + tolerance:
        mid = float(np.sqrt(lo * hi))
        if is_broken(source, mid, **kwargs):
            hi = mid
        else:
            lo = mid
    return float(np.sqrt(lo * hi))

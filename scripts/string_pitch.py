"""The string's pitch over rate / f0: where the waveguide stops sounding at f0 (issue 30, item 2).

Two measures, each the spectral peak (Hann window, zero padding, parabolic;
``bowing_reference.pitch``) divided by f0:

- ``alone``: the string by itself (bowed_string.run) under a constant bow
  velocity of 0.18 string units (the strokes' 0.15 m/s), over its second half
  second: the waveguide's own pitch;
- ``loop``: TRUE bowed on the strokes through the closed loop, per stroke
  cruise (at least 8 periods; median over the cruises), at F_max 1 and 5 N.

The loop refuses rate / f0 below RATE_PER_F0_MIN (model/playable.py); this
script lifts that refusal, to measure what it guards against.

    PYTHONPATH=. python scripts/string_pitch.py [--rates 1000 5000] [--ratios 4 4.5 5 5.5 6 7 8]
"""

import argparse

import numpy as np

from studyapp.model import calibration, loop as loop_module
from studyapp.model.bowed_string import StringDesign, run
from studyapp.model.bowing_reference import pitch
from studyapp.model.loop import ClosedLoop, LoopConfig


def alone(rate, f0, v_bow=0.18, seconds=1.0):
    design = StringDesign(rate, f0)
    p = design.params()
    state, bridge, nut = design.new_state()
    n = int(seconds * rate)
    u, v_string, v_bridge = np.zeros(n), np.zeros(n), np.zeros(n)
    run(p, state, bridge, nut, np.full(n, v_bow), True, u, v_string, v_bridge)
    return pitch(v_string[n // 2:], rate, fmin=0.5 * f0) / f0


def in_loop(rate, f0, fmax, seed=0, seconds=2.0):
    loop = ClosedLoop(LoopConfig(rate=rate, source="TRUE", fmax=fmax, gesture="strokes", seed=seed, f0=f0,
                                 audio=False), judge=False)
    block = loop.run(int(seconds * rate))
    m = max(1, int(0.01 * rate))
    speed = np.convolve(np.abs(block["velocity_true"]), np.ones(m) / m, "same")
    cruise = (speed > 0.8 * calibration.STROKE_SPEED).astype(np.int8)
    edges = np.flatnonzero(np.diff(np.r_[0, cruise, 0]))
    found = [pitch(block["string_velocity"][a:e], rate, fmin=0.5 * f0)
             for a, e in zip(edges[::2] + int(0.02 * rate), edges[1::2]) if (e - a) * f0 / rate >= 8]
    return float(np.median(found)) / f0 if found else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rates", nargs="+", type=float, default=[1000.0, 5000.0])
    parser.add_argument("--ratios", nargs="+", type=float, default=[4, 4.5, 5, 5.5, 5.75, 6, 6.5, 7, 8, 10])
    args = parser.parse_args()
    loop_module.check_playable = lambda rate, f0: (rate, f0)  # measure below the bound too
    print("| rate (Hz) | rate / f0 | f0 (Hz) | alone | loop, 1 N | loop, 5 N |")
    print("|---|---|---|---|---|---|")
    for rate in args.rates:
        for ratio in args.ratios:
            f0 = rate / ratio
            if not 20.0 <= f0 <= 2000.0:
                continue
            cells = [alone(rate, f0), in_loop(rate, f0, 1.0), in_loop(rate, f0, 5.0)]
            print(f"| {rate:g} | {ratio:g} | {f0:.1f} | " + " | ".join(f"{c:.4f}" for c in cells) + " |", flush=True)


if __name__ == "__main__":
    main()

"""The string's pitch over rate / f0: where the waveguide stops sounding at f0 (issue 30, item 2).

Two measures (studyapp/model/string_pitch.py, as the tests measure), each
divided by f0:

- ``alone``: the string by itself under a constant bow (the strokes' speed),
  over its second half second: the waveguide's own pitch;
- ``loop``: TRUE bowed on the strokes through the closed loop for 2 s, the
  median over the stroke cruises, at F_max 1 and 5 N.

The loop refuses rate / f0 below RATE_PER_F0_MIN (model/playable.py); this
script lifts that refusal, to measure what it guards against.

    PYTHONPATH=. python scripts/string_pitch.py [--rates 1000 5000] [--ratios 4 4.5 5 5.5 6 7 8]
"""

import argparse

from studyapp.model import loop as loop_module
from studyapp.model.string_pitch import alone_pitch, cruise_pitch


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
            cells = [alone_pitch(rate, f0) / f0, cruise_pitch(rate, f0, 1.0, seconds=2.0) / f0,
                     cruise_pitch(rate, f0, 5.0, seconds=2.0) / f0]
            print(f"| {rate:g} | {ratio:g} | {f0:.1f} | " + " | ".join(f"{c:.4f}" for c in cells) + " |", flush=True)


if __name__ == "__main__":
    main()

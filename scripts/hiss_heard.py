"""The bowing verdict's upper band on the handle against what reaches the ears (docs/model.md, "Perception floors").

    PYTHONPATH=. python scripts/hiss_heard.py [--rate 48000] [--seed 40] [--fmax 0.05,1,2,3]

For each source (LEVANT with Table 1 made for the rate in seconds; FOAW and
LEASTSQ with its windows in samples, issue 30's hissing ones) and F_max,
bowing the strokes for 2.5 s (levels from 0.25 s on, as stability.hiss_level):

- the handle's velocity in stability.hiss_band(rate), as a ratio to TRUE's
  (what the verdict reads), and how far above its perception floor it lies;
- the loop's sound (the string's body-filtered velocity and the contact
  microphone, at the stimulus gain) through the same band, as a ratio to
  TRUE's, in dBFS and in dB SPL at perception_floors.FULL_SCALE_SPL_DB.
"""

import argparse
import math

import numpy as np
from scipy import signal

from studyapp.estimators.at_rate import table1
from studyapp.model import perception_floors, stability, stimulus_level
from studyapp.model.loop import ClosedLoop, LoopConfig

SOURCES = (("LEVANT", "seconds"), ("FOAW", "samples"), ("LEASTSQ", "samples"))
SECONDS = 2.5
SETTLE = 0.25


def levels(source, windows, fmax, rate, seed):
    """(handle upper band m/s, sound upper band full-scale RMS) of one bowing run."""
    estimators = {} if source == "TRUE" else {source: table1(source, rate, windows)}
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=source, fmax=fmax, gesture="strokes",
                                 seed=seed, audio=True), judge=False)
    block = loop.run(int(SECONDS * rate))
    start = int(SETTLE * rate)
    sound = signal.sosfilt(stability.hiss_sos(rate), stimulus_level.STIMULUS_GAIN * block["audio"])[start:]
    return stability.hiss_level(block["velocity_true"], rate, start), float(np.sqrt(np.mean(sound * sound)))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=48000.0)
    parser.add_argument("--seed", type=int, default=40)
    parser.add_argument("--fmax", default="0.05,1,2,3", help="F_max values (N), comma-separated")
    args = parser.parse_args(argv)
    if stability.hiss_band(args.rate) is None:
        parser.error(f"--rate {args.rate:g}: allowed is a rate with an upper band (above 5.6 kHz)")
    floor = stability.hiss_floor(args.rate)
    print(f"rate {args.rate:g} Hz, seed {args.seed}, upper band {stability.hiss_band(args.rate)} Hz, "
          f"heard floor {floor * 1e6:.4f} um/s")
    print("source   windows  F_max  handle/TRUE  handle over floor  sound/TRUE  sound dBFS  dB SPL  TRUE dBFS")
    for fmax in (float(f) for f in args.fmax.split(",")):
        true_handle, true_sound = levels("TRUE", "seconds", fmax, args.rate, args.seed)
        for source, windows in SOURCES:
            handle, sound = levels(source, windows, fmax, args.rate, args.seed)
            db = 20 * math.log10(sound)
            print(f"{source:8s} {windows:8s} {fmax:5.2f}  {handle / true_handle:11.2f}  "
                  f"{20 * math.log10(handle / floor):14.1f} dB  {sound / true_sound:10.2f}  {db:10.1f}  "
                  f"{db + perception_floors.FULL_SCALE_SPL_DB:6.1f}  {20 * math.log10(true_sound):9.1f}")


if __name__ == "__main__":
    main()

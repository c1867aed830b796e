"""The audibility floor of F_max (studyapp/experiment/audible_fmax.py): how much the force fed back moves
the string's level, per source and seed, against the same source at F_max = 1e-6 N.

    PYTHONPATH=. python scripts/audible_fmax.py [--seeds 0 1 2] [--fmax 0.1 0.15 0.2 0.3 0.5 1.0]

Prints one line per seed and F_max: the level rise (dB) of each source, and their median.
"""

import argparse

import numpy as np

from studyapp.model.stimulus_level import typical_rms_dbfs

SOURCES = ("LVT", "TRUE", "LOWPASS", "LEVANT")
RATE = 5000.0
NO_FORCE = 1e-6  # N: the level is flat from here to 1e-3 N


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2])
    parser.add_argument("--fmax", type=float, nargs="+", default=[0.1, 0.15, 0.2, 0.3, 0.5, 1.0])
    args = parser.parse_args()
    print("seed  F_max (N)  " + "  ".join(f"{s:>8}" for s in SOURCES) + "    median  (dB above F_max 1e-6 N)")
    for seed in args.seeds:
        base = {s: typical_rms_dbfs(RATE, "strokes", NO_FORCE, [s], seed=seed) for s in SOURCES}
        for fmax in args.fmax:
            rise = [typical_rms_dbfs(RATE, "strokes", fmax, [s], seed=seed) - base[s] for s in SOURCES]
            print(f"{seed:>4}  {fmax:>9g}  " + "  ".join(f"{r:>8.2f}" for r in rise) + f"  {np.median(rise):>8.2f}")


if __name__ == "__main__":
    main()

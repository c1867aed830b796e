"""Why BDIFF breaks at the search's floor on one seed and at 5.5 N on another (issue 42, measured item 6).

``studyapp breakdown --source BDIFF --first-seed 40 --seeds 5`` gives 8.56, <= 0.05, 5.53, 8.56, 8.85 N.
For each seed and F_max this prints what breakdown.py's bowing verdict reads
(breakdown._bowing_measures, the trial's own measures): the handle's band
level against TRUE's (broken above stability.RISE), and the string's pitch
(broken beyond stability.PITCH_TOLERANCE of f0), with the width of the
string's spectral line at f0 (Hz between the -3 dB points of its Welch
spectrum over the same span, 0.5 s segments) and BDIFF's velocity noise at rest against the bow's
breakaway speed (calibration.VELOCITY_SCALE, bow_table.breakaway).
docs/model.md ("The seed outliers") quotes its output.
"""

import argparse

import numpy as np
from scipy import signal

from studyapp.estimators.at_rate import table1
from studyapp.model import bow_table, breakdown, calibration, stability
from studyapp.model.loop import ClosedLoop, LoopConfig

RATE = 5000.0
WELCH_SECONDS = 0.5  # 2 Hz resolution: 0.45 % of f0, a quarter of the verdict's tolerance


def line_width(x, rate, f0):
    """Hz between the -3 dB points of the averaged spectrum's peak within 20 % of ``f0`` (Welch, 0.5 s segments)."""
    freq, spec = signal.welch(np.asarray(x, dtype=np.float64), rate, nperseg=int(WELCH_SECONDS * rate),
                              nfft=8 * int(WELCH_SECONDS * rate))
    inside = np.flatnonzero((freq > 0.8 * f0) & (freq < 1.2 * f0))
    i = inside[np.argmax(spec[inside])]
    half = spec[i] / 2.0
    lo, hi = i, i
    while lo > inside[0] and spec[lo] > half:
        lo -= 1
    while hi < inside[-1] and spec[hi] > half:
        hi += 1
    return float(freq[hi] - freq[lo])


def trial(source, fmax, seed):
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={source: table1(source, RATE, "seconds")}, source=source,
                                 fmax=fmax, gesture="strokes", seed=seed, audio=False), judge=False)
    total = int(round(breakdown.DURATION * RATE))
    block = loop.run(total)
    level, _, pitch = breakdown._bowing_measures(block, RATE)
    ref, _, _ = breakdown._true_bowing(RATE, float(loop.string.f0), "strokes", float(fmax), total, int(seed))
    settle = int(round(breakdown.SETTLE * RATE))
    width = line_width(block["string_velocity"][settle:], RATE, loop.string.f0)
    return level / ref, pitch / loop.string.f0 - 1.0, width, block


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--source", default="BDIFF")
    p.add_argument("--fmax", default="0.05,5,6")
    p.add_argument("--seeds", default="40,41,42,43,44")
    a = p.parse_args(argv)
    breakaway = bow_table.breakaway(3.0) / calibration.VELOCITY_SCALE
    print(f"bow breakaway {1e3 * breakaway:.1f} mm/s; verdict: band ratio > {stability.RISE:.2f} or "
          f"|pitch / f0 - 1| > {100 * stability.PITCH_TOLERANCE:g} %")
    print("| source | seed | F_max (N) | band / TRUE | pitch - f0 (%) | f0 line width, -3 dB (Hz) | noise RMS (mm/s) | broken |")
    print("|---|---|---|---|---|---|---|---|")
    for seed in (int(s) for s in a.seeds.split(",")):
        for f in (float(x) for x in a.fmax.split(",")):
            ratio, off, width, block = trial(a.source, f, seed)
            noise = np.std(block["source_velocity"] - block["velocity_true"])
            broken = ratio > stability.RISE or abs(off) > stability.PITCH_TOLERANCE
            print(f"| {a.source} | {seed} | {f:g} | {ratio:.2f} | {100 * off:+.2f} | {width:.1f} | {1e3 * noise:.0f} | "
                  f"{'yes' if broken else 'no'} |", flush=True)


if __name__ == "__main__":
    main()

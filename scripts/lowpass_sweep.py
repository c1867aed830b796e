"""LOWPASS's objective over its cut-off: why ``optimise`` puts it near 528 Hz where the paper's put it at 256 Hz.

    PYTHONPATH=. python scripts/lowpass_sweep.py DATA/train --params docs/study/params.toml -o lowpass_sweep.png \
        [--low 150 --high 1000 --step 10] [--noise 0,15,30,60] [--seed 0] [--delay normalised|paper]

The objective is the optimiser's own (docs/evaluation.md, "The optimiser";
``normalisation.py``, the paper's eqs. 27-32): over the n recordings,

    F_g(c) = sum_r (E_r(c) + O_E,r) / S_E,r  +  sum_r (|D_r(c)| + O_D,r) / S_D,r
           = error part                     +  delay part,

E_r the RMS error against the LVT after the shift D_r (eqs. 23-24), D_r the
whole-sample delay of the normalised cross-correlation (``metric.py``), and
(O, S) the offsets and scales of eqs. 30 and 32 from the best and worst of
the estimators. LOWPASS (a 2nd-order Butterworth low-pass of the backward
difference, paper Sec. 3.1) is swept over its cut-off c with every other
estimator at the tuned file's values, under two scales:

- the tuned file's (the bounds over its thirteen estimators on these
  recordings: the scale the optimiser judged with at its end, as ``evaluate``
  computes it);
- Table 1's (the bounds over the thirteen at Table 1: iteration 0's scale,
  where the search starts).

Only the argmin over c is asked, so the offsets do not matter, only the
ratio of each recording's error scale to its delay scale: one sample of |D|
on recording r costs 1 / S_D,r, one m/s of E costs 1 / S_E,r.

What would move the minimum (printed and plotted):

- a weight w on the delay part, F = error part + w x delay part (the paper's
  eq. 27 has unit weights; w = 0 is the error alone): the argmin for w from
  0.01 to 10;
- more position noise: white Gaussian noise of ``--noise`` um RMS added to
  every recording's LVDT position (seeded), the thirteen tuned estimators
  re-run on it for the scale, and the sweep repeated.

Printed: the scale, each cut-off's median E (mm/s), median |D| (whole and
sub-sample, samples), the two parts and F_g; the argmins; the weight and the
noise each argmin needs. Plotted (``-o``): four panels of the same.
"""

import argparse
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from studyapp.estimators.registry import spec  # noqa: E402
from studyapp.evaluation import params_file  # noqa: E402
from studyapp.evaluation.dataset import Dataset, Take, expand_paths, load_takes, warm_up  # noqa: E402
from studyapp.evaluation.normalisation import bounds, per_objective  # noqa: E402
from studyapp.evaluation.space import PAPER_ESTIMATORS  # noqa: E402

PAPER_CUTOFF = 256.0  # Hz, the paper's Table 1
WEIGHTS = np.logspace(-2, 1, 31)


def scale_of(dataset, sets):
    """(offsets, scales) of eqs. 30 and 32 over ``sets`` (name -> parameters) on ``dataset``."""
    return bounds(np.array([dataset.raw_objectives(name, p) for name, p in sets.items()]))


def sweep(dataset, cutoffs, offsets, scales, subsample=True):
    """Per cut-off: median E (m/s), median |D| (samples), median sub-sample |d|, the error and delay parts."""
    rows = []
    for c in cutoffs:
        errors, delays = dataset.delays_and_errors("LOWPASS", {"cutoff_hz": float(c)})
        raw = np.empty(2 * errors.size)
        raw[0::2], raw[1::2] = errors, np.abs(delays)
        parts = per_objective(raw, offsets, scales)
        d = np.abs(dataset.subsample_delays("LOWPASS", {"cutoff_hz": float(c)})) if subsample else np.full(1, np.nan)
        rows.append({"cutoff": float(c), "E": float(np.median(errors)), "D": float(np.median(np.abs(delays))),
                     "d": float(np.median(d)), "error_part": float(parts[0::2].sum()),
                     "delay_part": float(parts[1::2].sum())})
    return rows


def argmin(rows, weight=1.0):
    values = [r["error_part"] + weight * r["delay_part"] for r in rows]
    return rows[int(np.argmin(values))]["cutoff"]


def noisy(takes, sigma, seed):
    """The takes with white Gaussian noise of ``sigma`` m RMS added to the LVDT position (one generator per take)."""
    out = []
    for i, t in enumerate(takes):
        rng = np.random.default_rng([seed, i])
        out.append(Take(t.name, t.rate, t.position + sigma * rng.standard_normal(t.position.size), t.acceleration,
                        t.velocity, t.reference, t.fmax, t.sha256))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings", help="the training recordings (a folder or files)")
    parser.add_argument("--params", required=True, help="the tuned PARAMS.toml (its thirteen set the scale)")
    parser.add_argument("--low", type=float, default=150.0)
    parser.add_argument("--high", type=float, default=1000.0)
    parser.add_argument("--step", type=float, default=10.0)
    parser.add_argument("--noise", default="0,15,30,60", help="added position noise, um RMS, comma separated")
    parser.add_argument("--seed", type=int, default=0, help="the added noise's seed")
    parser.add_argument("--delay", choices=("normalised", "paper"), default="normalised")
    parser.add_argument("-o", "--output", required=True, help="the figure (.png)")
    args = parser.parse_args()
    started = time.monotonic()

    takes = load_takes(expand_paths([args.recordings]))
    rate = takes[0].rate
    tuned = params_file.read(args.params)[0]
    table1 = {n: spec(n).validate(rate, {})[1] for n in PAPER_ESTIMATORS}
    warm_up(tuple(tuned), rate, True)
    dataset = Dataset(takes, fast=True, delay_method=args.delay)
    cutoffs = np.unique(np.concatenate([np.arange(args.low, args.high + args.step / 2, args.step),
                                        [PAPER_CUTOFF, tuned["LOWPASS"]["cutoff_hz"]]]))

    o_tuned, s_tuned = scale_of(dataset, tuned)
    o_t1, s_t1 = scale_of(dataset, table1)
    print(f"{len(takes)} recordings at {rate:g} Hz, delay {args.delay}; tuned LOWPASS {tuned['LOWPASS']['cutoff_hz']:.1f} Hz")
    print("scale of the tuned file, per recording: S_E (mm/s) " + " ".join(f"{1e3 * s:.2f}" for s in s_tuned[0::2]))
    print("                                        S_D (samples) " + " ".join(f"{s:g}" for s in s_tuned[1::2]))
    print("scale of Table 1, per recording:        S_E (mm/s) " + " ".join(f"{1e3 * s:.2f}" for s in s_t1[0::2]))
    print("                                        S_D (samples) " + " ".join(f"{s:g}" for s in s_t1[1::2]))

    rows = sweep(dataset, cutoffs, o_tuned, s_tuned)
    rows_t1 = sweep(dataset, cutoffs, o_t1, s_t1, subsample=False)
    print("\n| cut-off (Hz) | median E (mm/s) | median \\|D\\| | median \\|d\\| | error part | delay part | F_g "
          "| F_g, Table 1's scale |\n| --- | --- | --- | --- | --- | --- | --- | --- |")
    marked = {PAPER_CUTOFF, tuned["LOWPASS"]["cutoff_hz"], argmin(rows), argmin(rows_t1)}
    for r, r1 in zip(rows, rows_t1):
        if r["cutoff"] % 50 == 0 or r["cutoff"] in marked:
            print(f"| {r['cutoff']:.1f} | {1e3 * r['E']:.3f} | {r['D']:g} | {r['d']:.2f} | {r['error_part']:.3f} "
                  f"| {r['delay_part']:.3f} | {r['error_part'] + r['delay_part']:.3f} "
                  f"| {r1['error_part'] + r1['delay_part']:.3f} |")
    print(f"\nargmin F_g: {argmin(rows):g} Hz under the tuned scale, {argmin(rows_t1):g} Hz under Table 1's; "
          f"error part alone {argmin(rows, 0.0):g} Hz, delay part alone "
          f"{rows[int(np.argmin([r['delay_part'] for r in rows]))]['cutoff']:g} Hz (first of its minima)")
    by_weight = [argmin(rows, w) for w in WEIGHTS]
    print("argmin against the delay weight w (F = error part + w delay part, tuned scale): "
          + ", ".join(f"w {w:.3g}: {c:g} Hz" for w, c in zip(WEIGHTS[::3], by_weight[::3])))
    near = [w for w, c in zip(WEIGHTS, by_weight) if abs(c - PAPER_CUTOFF) <= 2 * args.step]
    print("weights putting the argmin within 20 Hz of 256 Hz: "
          + (f"{min(near):.3g} to {max(near):.3g}" if near else "none in 0.01-10"))

    noise_rows = {}
    for um in [float(v) for v in args.noise.split(",") if v.strip()]:
        data = dataset if um == 0 else Dataset(noisy(takes, um * 1e-6, args.seed), fast=True, delay_method=args.delay)
        o, s = scale_of(data, tuned)
        noise_rows[um] = sweep(data, cutoffs, o, s, subsample=False)
        r = noise_rows[um]
        print(f"added position noise {um:g} um RMS: argmin F_g {argmin(r):g} Hz (error part alone {argmin(r, 0.0):g} "
              f"Hz); median E at 256 Hz {1e3 * next(x['E'] for x in r if x['cutoff'] == PAPER_CUTOFF):.3f} mm/s")

    fig, axes = plt.subplots(2, 2, figsize=(12, 8.5))
    c = np.array([r["cutoff"] for r in rows])
    ax = axes[0, 0]
    ax.plot(c, [r["error_part"] + r["delay_part"] for r in rows], "k-", label="F_g (tuned scale)")
    ax.plot(c, [r["error_part"] for r in rows], "C0-", label="error part")
    ax.plot(c, [r["delay_part"] for r in rows], "C3-", label="delay part")
    ax.plot(c, [r["error_part"] + r["delay_part"] for r in rows_t1], "k:", label="F_g (Table 1's scale)")
    for x, style, label in ((PAPER_CUTOFF, "C2--", "paper 256 Hz"),
                            (tuned["LOWPASS"]["cutoff_hz"], "C1--", f"tuned {tuned['LOWPASS']['cutoff_hz']:.0f} Hz")):
        ax.axvline(x, color=style[:2], ls="--", label=label)
    ax.set_title(f"LOWPASS's objective over its cut-off; minimum at {argmin(rows):.0f} Hz")
    ax.set_xlabel("cut-off (Hz)")
    ax.set_ylabel("sum over the recordings")
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ax.plot(c, [1e3 * r["E"] for r in rows], "C0-")
    ax.set_xlabel("cut-off (Hz)")
    ax.set_ylabel("median E against the LVT (mm/s)", color="C0")
    twin = ax.twinx()
    twin.plot(c, [r["D"] for r in rows], "C3-", drawstyle="steps-mid", label="median |D| (whole samples)")
    twin.plot(c, [r["d"] for r in rows], "C3:", label="median |d| (sub-sample)")
    twin.set_ylabel("delay against the LVT (samples)", color="C3")
    twin.legend(fontsize=8, loc="upper right")
    ax.axvline(PAPER_CUTOFF, color="C2", ls="--")
    ax.set_title("error and delay against the LVT")
    ax = axes[1, 0]
    ax.semilogx(WEIGHTS, by_weight, "ko-", ms=3)
    ax.axhline(PAPER_CUTOFF, color="C2", ls="--", label="paper 256 Hz")
    ax.axvline(1.0, color="grey", ls=":", label="w = 1 (the objective)")
    ax.set_xlabel("weight w of the delay part")
    ax.set_ylabel("argmin cut-off (Hz)")
    ax.set_title("where the minimum goes as the delay weighs more or less")
    ax.legend(fontsize=8)
    ax = axes[1, 1]
    for k, (um, r) in enumerate(noise_rows.items()):
        f = np.array([x["error_part"] + x["delay_part"] for x in r])
        ax.plot(c, f - f.min(), f"C{k}-", label=f"+{um:g} um: minimum {argmin(r):.0f} Hz")
    ax.axvline(PAPER_CUTOFF, color="C2", ls="--")
    ax.set_xlabel("cut-off (Hz)")
    ax.set_ylabel("F_g - its minimum (each its own tuned scale)")
    ax.set_title("with white noise added to the LVDT position")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.output, dpi=80)
    print(f"\nwrote {args.output} in {time.monotonic() - started:.0f} s")


if __name__ == "__main__":
    main()

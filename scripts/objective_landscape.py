"""F_g of 2-parameter estimators over a log grid of (q, r_acc), under the common scale of parameter files.

    PYTHONPATH=. python scripts/objective_landscape.py DIR --params s0.toml s1.toml s2.toml \
        [--estimators KALMAN KALLEVACC KALFOAWACC] [--q 0:5] [--r -2:4] [--step 0.1] -o landscape.png
    PYTHONPATH=. python scripts/objective_landscape.py DIR --params s0.toml s1.toml s2.toml \
        --estimators KALMAN --ratio --q 1.75:2.1 --r 1.3:1.5 --step 0.005 -o pocket.png

Why the optimiser's result for the Kalman filters with the accelerometer hangs
on the seed (issue 23, item 3). The common scale is the one ``evaluate --params``
uses for its seed spread (``seed_spread.py``): the offsets and scales of eqs. 30
and 32 over every (file, estimator) pair of the files, so F_g (eq. 27) of any
set is comparable with the files' results. Every grid point sets q = 10^a and
r_acc = 10^b (the other parameters at their Table 1 values, as ``optimise
--tune paper`` keeps them) and is measured on the recordings of DIR.

With ``--ratio`` the second axis is log10(q / r_acc) instead of log10 r_acc
(``--r`` then gives its range): the ridge's lower part runs along it at a
nearly constant ratio, so a fine grid of a stretch of ridge stays small.

Printed: per file and estimator, its (q, r_acc), F_g, the delay part
sum_i (|D_i| + O_i) / S_i and the error part of F_g, and the per-recording |D|
(in samples). Where the tuned estimators' delays agree to a sample on a
recording, S_i = 1 there, so one sample of delay on that recording moves F_g by
a whole unit. Plotted: F_g per grid cell (clipped at 1.5 times the grid's
minimum), each file's set marked.
"""

import argparse
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from studyapp.evaluation import params_file  # noqa: E402
from studyapp.evaluation.dataset import Dataset, expand_paths, load_takes, warm_up  # noqa: E402
from studyapp.evaluation.normalisation import bounds, global_objective  # noqa: E402
from studyapp.evaluation.space import Space  # noqa: E402


def span(text):
    low, high = (float(v) for v in text.split(":"))
    return low, high


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings")
    parser.add_argument("--params", nargs="+", required=True)
    parser.add_argument("--estimators", nargs="+", default=["KALMAN", "KALLEVACC", "KALFOAWACC"])
    parser.add_argument("--q", type=span, default=(0.0, 5.0), help="log10 q range")
    parser.add_argument("--r", type=span, default=(-2.0, 4.0), help="log10 r_acc range")
    parser.add_argument("--step", type=float, default=0.1, help="grid step in decades")
    parser.add_argument("--ratio", action="store_true", help="second axis log10(q / r_acc) instead of log10 r_acc")
    parser.add_argument("-o", "--output", required=True)
    args = parser.parse_args()

    warm_up(tuple(args.estimators), 5000.0, True)
    dataset = Dataset(load_takes(expand_paths([args.recordings])), fast=True)
    files = {path: params_file.read(path)[0] for path in args.params}
    raws = {(path, name): dataset.raw_objectives(name, sets[name]) for path, sets in files.items() for name in sets}
    offsets, scales = bounds(np.array(list(raws.values())))
    delay_scales = scales[1::2]
    print("S_i of the delays per recording (samples):", " ".join(f"{s:g}" for s in delay_scales))
    for name in args.estimators:
        for path in files:
            raw = raws[path, name]
            parts = (raw + offsets) / scales
            p = files[path][name]
            print(f"{name} {path}: q {p['q']:.4g} r_acc {p['r_acc']:.4g} F_g {parts.sum():.3f} "
                  f"(delay part {parts[1::2].sum():.2f}, error part {parts[0::2].sum():.2f}) "
                  f"|D| {' '.join(str(int(d)) for d in raw[1::2])}")

    a = np.arange(args.q[0], args.q[1] + 1e-9, args.step)
    b = np.arange(args.r[0], args.r[1] + 1e-9, args.step)
    fig, axes = plt.subplots(1, len(args.estimators), figsize=(5.5 * len(args.estimators), 5), squeeze=False)
    for ax, name in zip(axes[0], args.estimators):
        start = Space(name, dataset.takes[0].rate).start
        def r_acc(x, y):
            return 10.0 ** (x - y) if args.ratio else 10.0 ** y

        grid = np.array([[global_objective(dataset.raw_objectives(name, {**start, "q": 10.0 ** x, "r_acc": r_acc(x, y)}),
                                           offsets, scales) for y in b] for x in a])
        i, j = np.unravel_index(np.argmin(grid), grid.shape)
        low = grid[i, j]
        mesh = ax.pcolormesh(b, a, np.minimum(grid, 1.5 * low), shading="nearest")
        fig.colorbar(mesh, ax=ax, label="F_g (common scale)")
        second = "log10 q/r_acc" if args.ratio else "log10 r_acc"
        for k, path in enumerate(files):
            p = files[path][name]
            x = math.log10(p["q"] / p["r_acc"]) if args.ratio else math.log10(p["r_acc"])
            ax.plot(x, math.log10(p["q"]), "o", mfc="none", mec="red", ms=8)
            ax.annotate(str(k), (x, math.log10(p["q"])), color="red", xytext=(5, 5), textcoords="offset points")
        digits = 3 if args.step < 0.01 else 2 if args.step < 0.1 else 1
        ax.set_title(f"{name}: grid minimum {low:.3f}\nat log10 q {a[i]:.{digits}f}, {second} {b[j]:.{digits}f}")
        ax.set_xlabel(second)
        ax.set_ylabel("log10 q")
        ax.set_xlim(b[0], b[-1])
        ax.set_ylim(a[0], a[-1])
        print(f"{name}: grid minimum {low:.3f} at log10 q {a[i]:.3f}, {second} {b[j]:.3f}; "
              f"cells within 2 % of it: {int(np.sum(grid <= 1.02 * low))} of {grid.size}")
    fig.tight_layout()
    fig.savefig(args.output, dpi=80)


if __name__ == "__main__":
    main()

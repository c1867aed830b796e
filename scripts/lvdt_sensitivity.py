"""How the nine adjustment conditions' breakdown F_max and the pilot's rho move with the LVDT's bandwidth and noise (issue 42).

    PYTHONPATH=. python scripts/lvdt_sensitivity.py -o OUT [--seeds 40-41] [--pilot-seeds 31-33]
        [--bands 100,250,500,1000,2000,inf] [--noises 5,10,20,30] [--pilot-bands 100,250,1000,inf]
        [--pilot-noises 5,30] [--no-pilot] [--workers 2]

Two sweeps around the documented sensors (studyapp/model/sensors.py, docs/model.md's sensor table):
the conditioner's bandwidth (Hz, ``inf``: no band limit, the former white model) at the paper's 15 um
RMS, and the noise at rest (um RMS) at the documented bandwidth. Each point sets
``STUDYAPP_LVDT_BAND`` and ``STUDYAPP_LVDT_NOISE`` (sensors.from_environment) for:

- the breakdown of the nine conditions of the paper's Fig. 7 (``breakdown_over_seeds``, bowing
  ``strokes``, 5 kHz, Table 1's parameters) on ``--seeds``, and Spearman's rho of their medians against
  the paper's Fig. 7 order (studyapp.analysis.pilot.rho_against_paper);
- the in-silico pilot (scripts/pilot.py, one set ``--pilot-seeds``) at the points of ``--pilot-bands``
  and ``--pilot-noises``: its rho.

The grid is small on purpose (a breakdown search is about 3.5 s per condition and seed at 5 kHz, a
pilot session 20-60 s, on the shared two-core machine): the default runs in about 15 min with 2
workers. Writes ``OUT/lvdt_sensitivity.csv`` (one row per point, condition and quantity) and
``OUT/lvdt_sensitivity.png`` (F_max median against band and noise, and rho), and prints the order of
the nine conditions at each point.
"""

import argparse
import csv
import datetime
import math
import multiprocessing
import os
import shlex
import subprocess
import sys
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studyapp.analysis.pilot import PAPER_FIG7_RANK, pilot_figures, rho_against_paper  # noqa: E402
from studyapp.model import sensors  # noqa: E402

CONDITIONS = tuple(PAPER_FIG7_RANK)
DOCUMENTED = sensors.SensorSpec()
FIELDS = ("sweep", "lvdt_band_hz", "lvdt_noise_um", "quantity", "condition", "value", "seeds")


class BadInput(Exception):
    pass


def parse_numbers(text, option, allow_inf=False):
    values = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            value = float("nan")
        if not value > 0 or (math.isinf(value) and not allow_inf):
            raise BadInput(f"{option} {text!r}: {part!r} is not allowed; allowed are numbers above 0, comma-separated"
                           + (" (inf: no band limit)" if allow_inf else ""))
        values.append(value)
    return values


def parse_seeds(text, option):
    bounds = text.split("-")
    if len(bounds) > 2 or not all(b.isdigit() for b in bounds) or int(bounds[0]) > int(bounds[-1]):
        raise BadInput(f"{option} {text!r}: allowed is A-B or N (non-negative whole numbers, A <= B), e.g. 40-41")
    return int(bounds[0]), int(bounds[-1])


def environment(band, noise_um):
    return {sensors.BAND_VARIABLE: repr(band) if math.isfinite(band) else "inf",
            sensors.NOISE_VARIABLE: f"{noise_um:g}e-6"}


def breakdown_point(task):
    """(sweep, band, noise_um, {condition: [F_max per seed]}) in a fresh process whose environment names the LVDT."""
    sweep, band, noise_um, first, last = task
    os.environ.update(environment(band, noise_um))
    from studyapp.model.breakdown import breakdown_over_seeds
    values = {c: breakdown_over_seeds(c, seeds=last - first + 1, first_seed=first)["fmax"] for c in CONDITIONS}
    print(f"lvdt_sensitivity: breakdown at {band:g} Hz, {noise_um:g} um done", file=sys.stderr, flush=True)
    return sweep, band, noise_um, values


def pilot_point(task):
    """(sweep, band, noise_um, rho, medians) of one pilot set played with the LVDT of the point."""
    sweep, band, noise_um, first, last, out = task
    folder = Path(out) / f"pilot-{band:g}Hz-{noise_um:g}um"
    env = dict(os.environ, **environment(band, noise_um))
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "pilot.py"), "--seeds", f"{first}-{last}",
                           "-o", str(folder)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"pilot at {band:g} Hz, {noise_um:g} um failed: {done.stderr.strip()[-400:]}")
    figures = pilot_figures(pd.read_csv(folder / "pilot.csv"))
    print(f"lvdt_sensitivity: pilot at {band:g} Hz, {noise_um:g} um: rho {figures['rho']:.2f}", file=sys.stderr,
          flush=True)
    return sweep, band, noise_um, figures["rho"], figures["medians"]


def points(bands, noises):
    """The two sweeps: bands at the documented noise, noises at the documented band (the documented point once)."""
    noise = DOCUMENTED.lvdt_noise * 1e6
    grid = [("band", b, noise) for b in bands]
    grid += [("noise", DOCUMENTED.lvdt_band, n) for n in noises]
    if DOCUMENTED.lvdt_band not in bands:
        grid.append(("band", DOCUMENTED.lvdt_band, noise))
    seen, unique = set(), []
    for point in grid:  # each point once (the documented one belongs to both sweeps)
        if point[1:] not in seen:
            seen.add(point[1:])
            unique.append(point)
    return unique


def order(medians):
    ranked = sorted(medians.items(), key=lambda kv: kv[1])
    return " < ".join(f"{c} {v:.3g}" for c, v in ranked)


def plot(rows, path, seeds):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    import numpy as np

    frame = pd.DataFrame(rows)
    white_at = 5000.0  # where "no band limit" is drawn on the band axis
    fig, axes = plt.subplots(2, 2, figsize=(11, 8), sharex="col")
    for col, (sweep, x_name, label) in enumerate((("band", "lvdt_band_hz", "LVDT conditioner bandwidth (Hz)"),
                                                  ("noise", "lvdt_noise_um", "LVDT noise at rest (um RMS)"))):
        at = (frame["lvdt_noise_um"] == DOCUMENTED.lvdt_noise * 1e6) if sweep == "band" else (
            frame["lvdt_band_hz"] == DOCUMENTED.lvdt_band)
        part = frame[at].drop_duplicates(["lvdt_band_hz", "lvdt_noise_um", "quantity", "condition"])
        fmax = part[part["quantity"] == "fmax_median"]
        for condition in CONDITIONS:
            one = fmax[fmax["condition"] == condition].copy()
            one["x"] = one[x_name].replace(np.inf, white_at)
            one = one.sort_values("x")
            axes[0, col].plot(one["x"], one["value"], marker="o", label=condition)
        for quantity, style in (("breakdown_rho", "o-"), ("pilot_rho", "s--")):
            one = part[part["quantity"] == quantity].copy()
            one["x"] = one[x_name].replace(np.inf, white_at)
            one = one.sort_values("x")
            axes[1, col].plot(one["x"], one["value"], style, label=quantity.replace("_", " "))
        documented = DOCUMENTED.lvdt_band if sweep == "band" else DOCUMENTED.lvdt_noise * 1e6
        for row in (0, 1):
            axes[row, col].axvline(documented, color="grey", lw=0.8, ls=":")
            if sweep == "band":
                axes[row, col].set_xscale("log")
        axes[0, col].set_yscale("log")
        axes[0, col].yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axes[0, col].yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
        axes[0, col].set_ylabel(f"breakdown F_max, median of seeds {seeds} (N)")
        axes[1, col].set_ylabel("Spearman's rho against the paper's Fig. 7")
        axes[1, col].set_xlabel(label)
        if sweep == "band":
            ticks = sorted({float(x) for x in part[x_name].replace(np.inf, white_at)})
            axes[1, col].set_xticks(ticks, [("white" if t == white_at else f"{t:g}") for t in ticks])
            axes[1, col].xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        rhos = part[part["quantity"].str.endswith("rho")]["value"]
        axes[1, col].set_ylim(min(-0.1, float(rhos.min()) - 0.05) if len(rhos) else -0.1, 1.0)
        axes[1, col].axhline(0.0, color="grey", lw=0.5)
        axes[1, col].legend(fontsize=8)
    axes[0, 0].legend(fontsize=7, ncol=2)
    fig.suptitle("The nine conditions against the LVDT (5 kHz, bowing; dotted: the documented sensor)")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", required=True, help="a new or empty folder")
    parser.add_argument("--seeds", default="40-41", help="the breakdown's seeds, A-B (default 40-41)")
    parser.add_argument("--pilot-seeds", default="31-33", help="the pilot's set of seeds, A-B (default 31-33)")
    parser.add_argument("--bands", default="100,250,500,1000,2000,inf", help="bandwidths (Hz; inf: no band limit)")
    parser.add_argument("--noises", default="5,10,20,30", help="noises at rest (um RMS)")
    parser.add_argument("--pilot-bands", default="100,250,1000,inf", help="the bands the pilot is played at")
    parser.add_argument("--pilot-noises", default="5,30", help="the noises the pilot is played at")
    parser.add_argument("--no-pilot", action="store_true", help="the breakdown only")
    parser.add_argument("--workers", type=int, default=2, help="processes in parallel (default 2)")
    args = parser.parse_args(argv)
    try:
        first, last = parse_seeds(args.seeds, "--seeds")
        pilot_first, pilot_last = parse_seeds(args.pilot_seeds, "--pilot-seeds")
        grid = points(parse_numbers(args.bands, "--bands", True), parse_numbers(args.noises, "--noises"))
        pilot_grid = [] if args.no_pilot else points(parse_numbers(args.pilot_bands, "--pilot-bands", True),
                                                     parse_numbers(args.pilot_noises, "--pilot-noises"))
        if not 1 <= args.workers <= 8:
            raise BadInput(f"--workers {args.workers}: allowed is a whole number from 1 to 8")
    except BadInput as error:
        parser.exit(2, f"lvdt_sensitivity: error: {error}\n")
    out = Path(args.output)
    if out.exists() and (not out.is_dir() or any(out.iterdir())):
        parser.exit(2, f"lvdt_sensitivity: error: -o {out}: not empty; allowed is a new or empty folder\n")
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    context = multiprocessing.get_context("spawn")  # a fresh process per point: its environment, its caches
    with context.Pool(args.workers, maxtasksperchild=1) as pool:
        pilots = pool.map_async(pilot_point, [(s, b, n, pilot_first, pilot_last, str(out)) for s, b, n in pilot_grid],
                                chunksize=1)
        breakdowns = pool.map(breakdown_point, [(s, b, n, first, last) for s, b, n in grid], chunksize=1)
        pilots = pilots.get()
    seeds = f"{first}-{last}"
    lines = []
    for sweep, band, noise, values in breakdowns:
        medians = {c: float(pd.Series(v).median()) for c, v in values.items()}
        for c in CONDITIONS:
            rows.append(dict(sweep=sweep, lvdt_band_hz=band, lvdt_noise_um=noise, quantity="fmax_median",
                             condition=c, value=medians[c], seeds=seeds))
        rho = rho_against_paper(medians)
        rows.append(dict(sweep=sweep, lvdt_band_hz=band, lvdt_noise_um=noise, quantity="breakdown_rho",
                         condition="", value=rho, seeds=seeds))
        lines.append(f"| {band:g} | {noise:g} | {rho:.2f} | {order(medians)} |")
    for sweep, band, noise, rho, medians in pilots:
        rows.append(dict(sweep=sweep, lvdt_band_hz=band, lvdt_noise_um=noise, quantity="pilot_rho", condition="",
                         value=rho, seeds=f"{pilot_first}-{pilot_last}"))
        for c, v in medians.items():
            rows.append(dict(sweep=sweep, lvdt_band_hz=band, lvdt_noise_um=noise, quantity="pilot_median",
                             condition=c, value=v, seeds=f"{pilot_first}-{pilot_last}"))
    with open(out / "lvdt_sensitivity.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, FIELDS)
        writer.writeheader()
        writer.writerows(rows)
    plot(rows, out / "lvdt_sensitivity.png", seeds)
    command = "PYTHONPATH=. python scripts/lvdt_sensitivity.py " + shlex.join(argv if argv is not None else sys.argv[1:])
    print(f"Generated on {datetime.date.today().isoformat()} by `{command}`.\n")
    print(f"Breakdown (5 kHz, strokes, seeds {seeds}): rho of the medians against the paper's Fig. 7, and the order.\n")
    print("| band (Hz) | noise (um RMS) | rho | the nine conditions' medians (N), lowest first |")
    print("| --- | --- | --- | --- |")
    print("\n".join(sorted(set(lines), key=lambda s: (float(s.split("|")[2]), float(s.split("|")[1])))))
    if pilots:
        print(f"\nPilot (seeds {pilot_first}-{pilot_last}): " + ", ".join(
            f"{band:g} Hz {noise:g} um: rho {rho:.2f}" for _, band, noise, rho, _ in pilots))


if __name__ == "__main__":
    main()

"""How far each quoted figure moves under one rounding step of the initial state (issue 39, item 2).

    PYTHONPATH=. python scripts/sensitivity.py -o OUT [--parts breakdown,signals,pilot,study] [--seeds 10]
        [--tables strokes,hold,strokes-48k] [--sources S,...] [--pilot-seeds 1-6,7-12] [--max-sets N] [--resume]

Every figure is computed twice by the command docs/ quotes it from, once plain
and once with the environment's ``STUDYAPP_NUDGE=1`` (studyapp/model/nudge.py:
every simulated device starts its end-effector one rounding step, 1.7e-18 m,
off rest), and the two are compared. What a figure does under that nudge is
what it may do on another libm, architecture or numpy: docs/reproducibility.md
holds the table this prints, dated, with the command.

- ``breakdown``: ``studyapp breakdown --all --seeds N --json`` per table of
  ``TABLES`` (``--tables``), plain and nudged. Per source: the median of the
  plain F_max over seeds 0..N-1, their range, the median and largest
  |nudged / plain - 1| of one seed, and that of the median over the seeds.
- ``signals``: docs/model.md's "paper's signals" (scripts/model_figures.py's
  ``paper_signals`` at 12.1 and 7.7 N, ``loop_pitch`` at 5, 20, 48 kHz) on the
  quoted seed and the next N - 1, plain and nudged (this script again,
  ``--signals-json N``, under each nudge): per figure its quoted seed's value,
  the median and range over the seeds, and the median and largest |move|.
- ``pilot``: scripts/pilot.py ``--seeds SETS`` plain and nudged; per set and
  figure (the Fig. 7 medians, rho, the between-participant share) its value and
  |move|.
- ``study``: ``studyapp simulate-set`` (training and validation) plain and
  nudged, ``studyapp evaluate`` of docs/study/params.toml on each with
  ``--compare-paper``: each estimator's objective (beside params.toml's) and
  each finding's verdict, plain and nudged; and, with
  ``--max-sets N`` (a reduced budget: the full search is about 20 min per seed),
  ``studyapp optimise --seed 0 --max-sets N`` on each training set: each Table 1
  parameter's value and |move|.

The pairs of commands run two at a time (plain beside nudged). Progress
(part, command, time so far) goes to stderr, each command's own output to
``OUT/log/``. Writes ``OUT/sensitivity.md`` (and prints it). ``OUT`` must be new
or empty; ``--resume`` goes on in the ``OUT`` of an interrupted run, skipping the
pairs it finished (each leaves ``OUT/log/NAME.done``). ``make figures
ONLY=sensitivity`` runs the command docs/reproducibility.md quotes; about 1-2 h
of wall time on the shared two-core machine, most of it the pilot's sessions.
"""

import argparse
import csv
import datetime
import json
import math
import os
import shlex
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studyapp.analysis.pilot import pilot_figures  # noqa: E402
from studyapp.model.nudge import VARIABLE  # noqa: E402

# name -> (rate, gesture, windows, sources or None for --all): docs/breakdown.md's tables
TABLES = {"strokes": (5000, "strokes", "seconds", None),
          "hold": (5000, "hold", "seconds", None),
          "strokes-48k": (48000, "strokes", "seconds", ("TRUE", "LVT", "FOAW", "LEASTSQ"))}
PARTS = ("breakdown", "signals", "pilot", "study")
NUDGES = (0, 1)
STARTED = time.monotonic()
PIPE = "\\|"  # a | inside a Markdown table's cell


def say(text):
    print(f"sensitivity: {text} ({time.monotonic() - STARTED:.0f} s so far)", file=sys.stderr, flush=True)


def environment(nudge):
    env = dict(os.environ, **{VARIABLE: str(nudge)})
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p])
    return env


def run_pair(out, name, make_argv):
    """Run ``make_argv(nudge)`` for each nudge, side by side; exits naming the log if one fails.

    A pair that succeeded leaves ``OUT/log/NAME.done``; with ``--resume`` it is not run again."""
    done = out / "log" / f"{name}.done"
    if done.exists():
        say(f"{name}: done before (--resume)")
        return
    say(f"{name}: $ {VARIABLE}=n {shlex.join(make_argv('n'))}")
    running = []
    for nudge in NUDGES:
        argv = [sys.executable if a == "python" else a for a in make_argv(nudge)]
        if argv[:1] == ["studyapp"]:
            argv = [sys.executable, "-m", "studyapp"] + argv[1:]
        log = open(out / "log" / f"{name}-nudge{nudge}.log", "w")
        running.append((nudge, log, subprocess.Popen(argv, cwd=ROOT, env=environment(nudge), stdout=log, stderr=log)))
    for nudge, log, process in running:
        code = process.wait()
        log.close()
        if code != 0:
            sys.exit(f"sensitivity: {name} with {VARIABLE}={nudge} failed ({code}); see {log.name}")
    done.write_text("")
    say(f"{name}: done")


def move(plain, nudged):
    """|nudged / plain - 1|; 0 when both are the same (inf or the search's bottom included), inf when one is inf."""
    if plain == nudged:
        return 0.0
    if math.isinf(plain) or math.isinf(nudged):
        return math.inf
    return abs(nudged / plain - 1.0)


def pct(x):
    return "inf" if math.isinf(x) else f"{100 * x:.2g} %" if x else "0"


def g3(x):
    return "> 200" if math.isinf(x) else f"{x:.3g}"


def breakdown_part(out, table, seeds, only=None):
    rate, gesture, windows, sources = TABLES[table]
    sources = only or sources

    def argv(nudge):
        which = ["--all"] if sources is None else []
        return ["studyapp", "breakdown", *which, "--rate", str(rate), "--seeds", str(seeds), "--first-seed", "0",
                "--gesture", gesture, "--duration", "5", "--windows", windows, "-o", str(out / f"breakdown-{table}-nudge{nudge}.json")]

    if sources is None:
        run_pair(out, f"breakdown-{table}", argv)
        results = [json.loads((out / f"breakdown-{table}-nudge{n}.json").read_text()) for n in NUDGES]
    else:  # one command per source (--source), gathered
        results = [[], []]
        for source in sources:
            run_pair(out, f"breakdown-{table}-{source}",
                     lambda n, source=source: argv(n)[:2] + ["--source", source] + argv(n)[2:-1]
                     + [str(out / f"breakdown-{table}-{source}-nudge{n}.json")])
            for i, n in enumerate(NUDGES):
                results[i].append(json.loads((out / f"breakdown-{table}-{source}-nudge{n}.json").read_text()))
    lines = [f"**Breakdown F_max (N), {gesture} at {rate / 1000:g} kHz, seeds 0-{seeds - 1}** "
             f"(`{VARIABLE}=n studyapp breakdown {'--all' if sources is None else '--source S'} --rate {rate} "
             f"--seeds {seeds} --first-seed 0 --gesture {gesture} --duration 5 --windows {windows} --json`):", "",
             "| source | median over seeds | range over seeds | one seed's \\|move\\|: median | max | the median's \\|move\\| |",
             "| --- | --- | --- | --- | --- | --- |"]
    for plain, nudged in zip(*results):
        p = [number(v) for v in plain["fmax"]]
        q = [number(v) for v in nudged["fmax"]]
        moves = [move(a, b) for a, b in zip(p, q)]
        lines.append(f"| {plain['source']} | {g3(float(np.median(p)))} | {g3(min(p))}-{g3(max(p))} | "
                     f"{pct(float(np.median(moves)))} | {pct(max(moves))} | {pct(move(float(np.median(p)), float(np.median(q))))} |")
    return "\n".join(lines) + "\n"


def number(v):
    return math.inf if v is None or v == "inf" else float(v)


def signal_values(seeds):
    """{figure: [value per seed]} of docs/model.md's paper's signals, seeds from each one's quoted seed on."""
    sys.path.insert(0, str(ROOT / "scripts"))
    import model_figures as mf
    values = {}
    for k in range(seeds):
        for fmax, index in mf.PAPER_SIGNALS:
            dvdt, high, at_max = mf.paper_signals(fmax, index, mf.TRAINING["seed"] * 1000 + index + k)
            for name, v in ((f"max |dv/dt| at {fmax:g} N (m/s^2)", dvdt), (f"RMS above 100 Hz at {fmax:g} N (mm/s)", high),
                            (f"FOAW at its maximum window at {fmax:g} N (%)", at_max)):
                values.setdefault(name, []).append(v)
        for rate in mf.PITCH_RATES:
            values.setdefault(f"pitch at {rate / 1000:g} kHz, LVT at 2 N (Hz)", []).append(mf.loop_pitch(rate, k))
        print(f"sensitivity: signals, seed {k + 1}/{seeds} done", file=sys.stderr, flush=True)
    return values


def signals_part(out, seeds):
    run_pair(out, "signals", lambda n: ["python", "scripts/sensitivity.py", "--signals-json", str(seeds), "-o",
                                        str(out / f"signals-nudge{n}.json")])
    plain, nudged = (json.loads((out / f"signals-nudge{n}.json").read_text()) for n in NUDGES)
    lines = [f"**The paper's signals** (docs/model.md; `{VARIABLE}=n PYTHONPATH=. python scripts/sensitivity.py "
             f"--signals-json {seeds} -o FILE`: scripts/model_figures.py's functions on the quoted seed and the next "
             f"{seeds - 1}):", "",
             "| figure | quoted seed | median over seeds | range over seeds | one seed's \\|move\\|: median | max |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, p in plain.items():
        moves = [move(a, b) for a, b in zip(p, nudged[name])]
        shown = name.replace("|", PIPE)
        lines.append(f"| {shown} | {p[0]:.4g} | {float(np.median(p)):.4g} | {min(p):.4g}-{max(p):.4g} | "
                     f"{pct(float(np.median(moves)))} | {pct(max(moves))} |")
    return "\n".join(lines) + "\n"


def pilot_part(out, sets):
    run_pair(out, "pilot", lambda n: ["python", "scripts/pilot.py", "--seeds", sets, "-o", str(out / f"pilot-nudge{n}")])
    data = [pd.read_csv(out / f"pilot-nudge{n}" / "pilot.csv", dtype={"set": str}) for n in NUDGES]
    lines = [f"**The in-silico pilot** (`{VARIABLE}=n PYTHONPATH=. python scripts/pilot.py --seeds {sets}`): "
             "each set's figure plain, nudged, and |move| (the medians relative, rho and the share absolute):", "",
             "| figure | " + " | ".join(f"seeds {s}: plain, nudged, \\|move\\|" for s in dict.fromkeys(data[0]["set"])) + " |",
             "| --- | " + " | ".join("---" for _ in dict.fromkeys(data[0]["set"])) + " |"]
    figures = {label: [pilot_figures(d[d["set"] == label]) for d in data] for label in dict.fromkeys(data[0]["set"])}
    first = next(iter(figures.values()))[0]
    for condition in first["medians"]:
        lines.append(f"| {condition} median (N) | " + " | ".join(
            f"{a['medians'][condition]:.3g}, {b['medians'][condition]:.3g}, {pct(move(a['medians'][condition], b['medians'][condition]))}"
            for a, b in figures.values()) + " |")
    lines.append("| rho against the paper's Fig. 7 order | " + " | ".join(
        f"{a['rho']:.2f}, {b['rho']:.2f}, {abs(b['rho'] - a['rho']):.2f}" for a, b in figures.values()) + " |")
    lines.append("| within lower than total, log10 F_max (%) | " + " | ".join(
        f"{a['mean_within_lower_pct']:.0f}, {b['mean_within_lower_pct']:.0f}, "
        f"{abs(b['mean_within_lower_pct'] - a['mean_within_lower_pct']):.0f}" for a, b in figures.values()) + " |")
    key = ["participant", "condition", "trial"]
    both = data[0].merge(data[1], on=key, suffixes=("", "_nudged"))
    moved = both.groupby("participant").apply(lambda d: float(np.mean(d["fmax"] != d["fmax_nudged"])),
                                              include_groups=False)
    medians = both.groupby(["participant", "condition"]).apply(
        lambda d: move(float(np.median(d["fmax"])), float(np.median(d["fmax_nudged"]))), include_groups=False)
    lines += ["", f"Of {len(both)} adjustment responses {int(np.sum(both['fmax'] == both['fmax_nudged']))} are the same "
              f"plain and nudged. One participant's share of moved responses: median {pct(float(moved.median()))}, "
              f"largest {pct(float(moved.max()))}; the move of one participant's median in one condition: median "
              f"{pct(float(medians.median()))}, largest {pct(float(medians.max()))}."]
    return "\n".join(lines) + "\n"


def study_part(out, max_sets):
    for kind, extra in (("train", []), ("valid", ["--validation"])):
        run_pair(out, f"simulate-set-{kind}", lambda n, kind=kind, extra=extra:
                 ["studyapp", "simulate-set", "-o", str(out / f"data-nudge{n}" / kind), *extra])
    run_pair(out, "evaluate", lambda n: ["studyapp", "evaluate", str(out / f"data-nudge{n}" / "train"), "--params",
                                         "docs/study/params.toml", "--validation", str(out / f"data-nudge{n}" / "valid"),
                                         "-o", str(out / f"evaluate-nudge{n}"), "--compare-paper"])
    quoted = tomllib.loads((ROOT / "docs" / "study" / "params.toml").read_text())["objective"]
    objective = [json.loads((out / f"evaluate-nudge{n}" / "evaluation.json").read_text())["estimators"] for n in NUDGES]
    lines = [f"**The objective of docs/study/params.toml** (`{VARIABLE}=n studyapp simulate-set -o train`, then "
             "`studyapp evaluate train --params docs/study/params.toml`; params.toml's [objective] is what `optimise` "
             "found on its data set):", "",
             "| estimator | params.toml's | plain | nudged | \\|move\\| | \\|plain / params.toml's - 1\\| |",
             "| --- | --- | --- | --- | --- | --- |"]
    for name, value in quoted.items():
        a, b = objective[0][name]["objective"], objective[1][name]["objective"]
        lines.append(f"| {name} | {value:.6g} | {a:.6g} | {b:.6g} | {pct(move(a, b))} | {pct(move(value, a))} |")
    found = []
    for n in NUDGES:
        with open(out / f"evaluate-nudge{n}" / "findings.csv", newline="") as f:
            found.append(list(csv.DictReader(f)))
    lines += ["", f"**The findings** (`{VARIABLE}=n studyapp simulate-set` (training, validation), then `studyapp evaluate "
             "train --params docs/study/params.toml --validation valid --compare-paper`):", "",
              "| finding | verdict plain | verdict nudged | ours plain | ours nudged |", "| --- | --- | --- | --- | --- |"]
    for a, b in zip(*found):
        lines.append(f"| {short(a['finding'], 200)} | {a['verdict']} | {b['verdict']} | {short(a['ours'])} | {short(b['ours'])} |")
    if max_sets:
        run_pair(out, "optimise", lambda n: ["studyapp", "optimise", str(out / f"data-nudge{n}" / "train"), "-o",
                                             str(out / f"optimise-nudge{n}.toml"), "--seed", "0", "--workers", "1",
                                             "--max-sets", str(max_sets), "--quiet"])
        tuned = [tomllib.loads((out / f"optimise-nudge{n}.toml").read_text()) for n in NUDGES]
        lines += ["", f"**Table 1's parameters, a reduced search** (`{VARIABLE}=n studyapp optimise train --seed 0 "
                  f"--max-sets {max_sets}`; the quoted ones come from the full search, about 20 min per seed):", "",
                  "| estimator | parameter | plain | nudged | \\|move\\| |", "| --- | --- | --- | --- | --- |"]
        for estimator, params in tuned[0].items():
            if estimator in ("provenance", "objective") or not isinstance(params, dict):
                continue
            for name, value in params.items():
                if isinstance(value, (int, float)) and not isinstance(value, bool):
                    other = tuned[1][estimator][name]
                    lines.append(f"| {estimator} | {name} | {value:.4g} | {other:.4g} | {pct(move(float(value), float(other)))} |")
    return "\n".join(lines) + "\n"


def short(text, n=60):
    """``text`` on one line, at most ``n`` characters, its | escaped for a Markdown cell."""
    text = " ".join(str(text).split())
    return (text if len(text) <= n else text[:n - 3] + "...").replace("|", PIPE)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", required=True, help="a new or empty folder")
    parser.add_argument("--parts", default=",".join(PARTS), help=f"comma separated, of {', '.join(PARTS)}")
    parser.add_argument("--seeds", type=int, default=10, help="breakdown seeds 0..N-1 (default 10)")
    parser.add_argument("--tables", default="strokes", help=f"breakdown tables, comma separated, of {', '.join(TABLES)}")
    parser.add_argument("--sources", help="breakdown: only these sources, comma separated (default: each table's)")
    parser.add_argument("--pilot-seeds", default="1-6,7-12", help="scripts/pilot.py's --seeds (default 1-6,7-12)")
    parser.add_argument("--resume", action="store_true", help="OUT holds an interrupted run: skip the pairs it finished")
    parser.add_argument("--signals-json", type=int, metavar="N", help=argparse.SUPPRESS)  # the signals part's worker
    parser.add_argument("--max-sets", type=int, default=0, help="also optimise each training set, this many sets per "
                                                                 "estimator (0, the default: no optimise)")
    args = parser.parse_args(argv)
    if args.signals_json:
        Path(args.output).write_text(json.dumps(signal_values(args.signals_json)))
        return 0
    parts = [p.strip() for p in args.parts.split(",")]
    tables = [t.strip() for t in args.tables.split(",")]
    for label, chosen, allowed in (("--parts", parts, PARTS), ("--tables", tables, TABLES)):
        bad = [c for c in chosen if c not in allowed]
        if bad:
            parser.exit(2, f"sensitivity: error: {label} {bad[0]!r}: allowed are {', '.join(allowed)}\n")
    if not 1 <= args.seeds <= 100 or args.max_sets < 0:
        parser.exit(2, f"sensitivity: error: --seeds {args.seeds} / --max-sets {args.max_sets}: allowed are "
                       "1 to 100 seeds and 0 or more sets\n")
    out = Path(args.output)
    if not args.resume and out.exists() and (not out.is_dir() or any(out.iterdir())):
        parser.exit(2, f"sensitivity: error: -o {out}: not empty; allowed is a new or empty folder (or --resume)\n")
    (out / "log").mkdir(parents=True, exist_ok=True)
    command = "PYTHONPATH=. python scripts/sensitivity.py " + shlex.join(
        ["-o", str(out), "--parts", ",".join(parts), "--seeds", str(args.seeds), "--tables", ",".join(tables),
         "--pilot-seeds", args.pilot_seeds, "--max-sets", str(args.max_sets)]
        + (["--sources", args.sources] if args.sources else []))
    sections = [f"Generated on {datetime.date.today().isoformat()} by `{command}`."]
    if "breakdown" in parts:
        sections += [breakdown_part(out, table, args.seeds, args.sources and args.sources.split(",")) for table in tables]
    if "signals" in parts:
        sections.append(signals_part(out, args.seeds))
    if "pilot" in parts:
        sections.append(pilot_part(out, args.pilot_seeds))
    if "study" in parts:
        sections.append(study_part(out, args.max_sets))
    text = "\n".join(sections)
    (out / "sensitivity.md").write_text(text)
    print(text, end="")
    say("done")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The in-silico pilot: simulated participants of sinclair2014 over disjoint sets of seeds, each set analysed (issue 30).

    PYTHONPATH=. python scripts/pilot.py --seeds 1-6,7-12 -o pilot/ [--protocol protocols/sinclair2014.toml]
        [--analyse-only]

For every seed N of every set (sets separated by commas, each ``A-B`` or
``N``; no seed in two sets) one headless session, as a person would run it:

    studyapp run --protocol P --participant SIM0N --simulated-participant --headless
        --results OUT/seeds-A-B --seed N

then per set ``studyapp analyse OUT/seeds-A-B -o OUT/seeds-A-B-report
--include-simulated``, and from its ``responses_analysed.csv`` the set's
figures (studyapp.analysis.pilot): the Fig. 7 medians, Spearman's rho against
the paper's Fig. 7 order, and the share of the spread that is between
participants (``within_lower_pct``, a one-way random-effects decomposition of
log10 F_max per condition), beside ``analyse``'s own ``intra_lower_pct`` (on
F_max in N). Writes ``OUT/pilot.csv`` (every adjustment response: set, seed,
participant, condition, trial, fmax) and ``OUT/pilot.md`` (the figures, dated,
with this command), prints the latter, and shows each session's progress
with the time left on stderr. ``OUT`` must be new or empty (nothing is
written over); ``--analyse-only`` analyses the sessions already in ``OUT``.
"""

import argparse
import csv
import datetime
import os
import shlex
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from studyapp.analysis.pilot import pilot_figures  # noqa: E402

PROTOCOL = ROOT / "protocols" / "sinclair2014.toml"
CSV_FIELDS = ("set", "seed", "participant", "condition", "trial", "fmax")


class BadInput(Exception):
    pass


def parse_sets(text):
    """[(label, [seeds])] from ``"1-6,7-12"``; BadInput naming the value if malformed or overlapping."""
    sets, seen = [], set()
    for part in text.split(","):
        bounds = part.strip().split("-")
        if len(bounds) > 2 or not all(b.strip().isdigit() for b in bounds):
            raise BadInput(f"--seeds {text!r}: {part!r} is not a seed range; allowed is A-B or N "
                           "(non-negative integers, A <= B), sets separated by commas, e.g. 1-6,7-12")
        first, last = int(bounds[0]), int(bounds[-1])
        if first > last:
            raise BadInput(f"--seeds {text!r}: {part!r} runs backwards; allowed is A-B with A <= B")
        seeds = list(range(first, last + 1))
        if seen & set(seeds):
            raise BadInput(f"--seeds {text!r}: seed {min(seen & set(seeds))} is in two sets; allowed are disjoint sets")
        seen |= set(seeds)
        sets.append((f"{first}-{last}" if first != last else f"{first}", seeds))
    return sets


def participant(seed):
    return f"SIM{seed:02d}"


def studyapp(*args):
    """Run ``python -m studyapp ARGS`` with this checkout first on the path; its stderr is kept for errors."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT)] + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    done = subprocess.run([sys.executable, "-m", "studyapp", *map(str, args)], env=env,
                          stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"pilot: studyapp {' '.join(map(str, args))} failed ({done.returncode}): {done.stderr.strip()[-400:]}")


def run_sessions(out, sets, protocol):
    jobs = [(label, seed) for label, seeds in sets for seed in seeds]
    started = time.monotonic()
    for i, (label, seed) in enumerate(jobs, 1):
        print(f"pilot: [{i}/{len(jobs)}] set {label}, seed {seed}: session of {participant(seed)}", file=sys.stderr, flush=True)
        studyapp("run", "--protocol", protocol, "--participant", participant(seed), "--simulated-participant",
                 "--headless", "--results", out / f"seeds-{label}", "--seed", seed)
        elapsed = time.monotonic() - started
        print(f"pilot:     done; {elapsed:.0f} s so far, about {elapsed / i * (len(jobs) - i):.0f} s left",
              file=sys.stderr, flush=True)


def analyse(out, label):
    print(f"pilot: analysing set {label}", file=sys.stderr, flush=True)
    report = out / f"seeds-{label}-report"
    studyapp("analyse", out / f"seeds-{label}", "-o", report, "--include-simulated")
    rows = pd.read_csv(report / "responses_analysed.csv")
    rows = rows[(rows["task"] == "adjustment") & ~rows["practice"].astype(bool)]
    analysed = pd.read_csv(report / "variance_adjustment.csv")
    return rows, float(analysed["intra_lower_pct"].mean())


def markdown(command, results):
    """The figures per set as Markdown: the medians (best first, by the first set), rho, the variance shares."""
    today = datetime.date.today().isoformat()
    labels = list(results)
    order = list(results[labels[0]][0]["medians"])
    lines = [f"Generated on {today} by `{command}`.", "",
             "| | " + " | ".join(f"seeds {label}" for label in labels) + " |",
             "| --- | " + " | ".join("---" for _ in labels) + " |"]
    for condition in order:
        lines.append(f"| {condition} median (N) | " + " | ".join(
            f"{results[label][0]['medians'].get(condition, float('nan')):.3g}" for label in labels) + " |")
    lines.append("| rho against the paper's Fig. 7 order | " + " | ".join(f"{results[label][0]['rho']:.2f}" for label in labels) + " |")
    lines.append("| within lower than total, log10 F_max, random effects (%) | " + " | ".join(
        f"{results[label][0]['mean_within_lower_pct']:.0f}" for label in labels) + " |")
    lines.append("| intra_lower_pct of `studyapp analyse`, F_max in N (%) | " + " | ".join(
        f"{results[label][1]:.0f}" for label in labels) + " |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1-6,7-12", help="disjoint sets of seeds, e.g. 1-6,7-12")
    parser.add_argument("-o", "--output", required=True, help="a new or empty folder")
    parser.add_argument("--protocol", default=str(PROTOCOL.relative_to(ROOT)))
    parser.add_argument("--analyse-only", action="store_true", help="analyse the sessions already in OUTPUT")
    args = parser.parse_args(argv)
    try:
        sets = parse_sets(args.seeds)
    except BadInput as error:
        parser.exit(2, f"pilot: error: {error}\n")
    out = Path(args.output)
    if not Path(args.protocol).is_file():
        parser.exit(2, f"pilot: error: --protocol {args.protocol}: no such file; allowed is a protocol .toml\n")
    if args.analyse_only:
        missing = [label for label, _ in sets if not (out / f"seeds-{label}").is_dir()]
        if missing:
            parser.exit(2, f"pilot: error: --analyse-only: {out / f'seeds-{missing[0]}'} is not a folder; "
                           "allowed is a folder a pilot with these --seeds ran into\n")
        if any((out / name).exists() for name in ("pilot.csv", "pilot.md")) or any(
                (out / f"seeds-{label}-report").exists() for label, _ in sets):
            parser.exit(2, f"pilot: error: --analyse-only: {out} holds an analysis already; allowed is a pilot's "
                           "folder not yet analysed (nothing is written over)\n")
    elif out.exists() and (not out.is_dir() or any(out.iterdir())):
        parser.exit(2, f"pilot: error: --output {out}: not empty; allowed is a new or empty folder (nothing is written over)\n")
    out.mkdir(parents=True, exist_ok=True)
    if not args.analyse_only:
        run_sessions(out, sets, args.protocol)
    results, rows = {}, []
    for label, seeds in sets:
        responses, analysed_pct = analyse(out, label)
        results[label] = (pilot_figures(responses), analysed_pct)
        by_name = {participant(s): s for s in seeds}
        for r in responses.sort_values(["participant", "condition", "trial"]).itertuples():
            rows.append((label, by_name[r.participant], r.participant, r.condition, int(r.trial), repr(float(r.fmax))))
    with open(out / "pilot.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(CSV_FIELDS)
        writer.writerows(rows)
    command = "PYTHONPATH=. python scripts/pilot.py " + shlex.join(["--seeds", args.seeds, "-o", str(out)]
                                                                 + (["--protocol", args.protocol] if args.protocol != str(PROTOCOL.relative_to(ROOT)) else []))
    text = markdown(command, results)
    (out / "pilot.md").write_text(text)
    print(text, end="")


if __name__ == "__main__":
    main()

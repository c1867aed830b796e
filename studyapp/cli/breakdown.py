"""``studyapp breakdown --source NAME | --all [--rate HZ] [--seeds N] [--first-seed K] [--gesture strokes|hold]
[--windows seconds|samples] [--latency SAMPLES] [--packet SAMPLES] [--jitter SAMPLES] [--json] [-o FILE]``.

Breakdown F_max (studyapp.model.breakdown) for one source or every source,
over seeds K..K+N-1 (K = 0 by default). Prints a table (or with ``--json`` one JSON object for
``--source``, a list of them for ``--all``); ``-o`` also writes it, by suffix:
``.csv`` (one row per source, the seeds' values ';'-joined in
``fmax_per_seed``, the seeds in the same order in ``seeds_used``), ``.md`` (the same table, headed by the date and the
command that regenerates it) or ``.json``. Each JSON object ends with its ``provenance``: the
command, when, and where (studyapp.provenance: versions, commit, CPU, BLAS). Stable up to the search's 200 N is
``inf`` in CSV, ``null`` in JSON and "> 200" in Markdown; broken already at
0.05 N is 0.05, "<= 0.05" in Markdown. Progress goes to stderr.

Each estimator runs with Table 1 made for ``--rate`` (estimators/at_rate.py):
``--windows seconds`` (the default) scales the parameters counted in samples
(LEASTSQ's and FOAW's windows, the FOAW hybrids', BDIFF's steps) by
rate / 5 kHz, so they keep the duration they were tuned for; ``--windows
samples`` keeps the counts as printed. At 5 kHz the two are the same.

``--latency``, ``--packet`` and ``--jitter`` (samples at ``--rate``, default 0: cli/link_options.py) put the
simulated device behind a link (studyapp.model.link); the JSON has their keys (seconds), the CSV their columns
(after today's), the Markdown a sentence naming them in samples and ms.
"""

from studyapp.cli import link_options

SUFFIXES = (".csv", ".md", ".json")
COLUMNS = ("source", "rate", "gesture", "seeds", "fmax_median", "fmax_min", "fmax_max", "fmax_per_seed", "first_seed",
           "seeds_used", "windows")
LINK_COLUMNS = ("latency", "packet", "jitter")  # s, the link's (studyapp.model.link.NAMES)


def register(subparsers):
    p = subparsers.add_parser(
        "breakdown",
        help="breakdown F_max of velocity sources over seeds (the adjustment task's measure, Fig. 7)",
        description="Find the largest F_max at which each velocity source keeps the simulated loop stable, "
                    "for seeds K..K+N-1.",
    )
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument("--source", metavar="NAME", help="an estimator name, LVT (the tachometer) or TRUE")
    which.add_argument("--all", action="store_true", help="every estimator, LVT and TRUE")
    p.add_argument("--rate", type=float, default=5000.0, metavar="HZ", help="sample rate in Hz, 1000..96000 and at least 6 x f0 (default 5000)")
    p.add_argument("--seeds", type=int, default=5, metavar="N", help="how many seeds (K..K+N-1), N at most 100 (default 5)")
    p.add_argument("--first-seed", type=int, default=0, metavar="K",
                   help="the first seed: seeds K..K+N-1, K a whole number >= 0, K+N at most 1000000 (default 0)")
    p.add_argument("--gesture", default="strokes", metavar="strokes|hold",
                   help="strokes (bowing, judged against TRUE's sound and feel) or hold (the hand at rest, with "
                        "tremor) (default strokes)")
    p.add_argument("--duration", type=float, default=5.0, metavar="SECONDS",
                   help="length of each trial, 0.5..60 s (default 5; shorter misses late onsets)")
    p.add_argument("--windows", default="seconds", metavar="seconds|samples",
                   help="Table 1's parameters counted in samples at --rate: seconds (scaled by rate / 5000, keeping the "
                        "duration Table 1 was tuned for) or samples (the counts as printed) (default seconds)")
    link_options.add(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of the table")
    p.add_argument("-o", "--output", metavar="FILE", help="also write the result: .csv, .md or .json")
    p.set_defaults(func=run)


def check_output(path):
    """Raise ``UserError`` unless ``path`` can be written (call before the search)."""
    from pathlib import Path

    from studyapp.cli import output_paths
    from studyapp.errors import UserError

    if Path(path).suffix.lower() not in SUFFIXES:
        raise UserError(f"-o {path}: allowed suffixes are {', '.join(SUFFIXES)}")
    output_paths.check_file(path)


def command_line(args):
    """The canonical command that reproduces ``args``, every setting spelled out."""
    import shlex

    which = "--all" if args.all else f"--source {shlex.quote(args.source)}"
    words = (f"studyapp breakdown {which} --rate {args.rate:g} --seeds {args.seeds} --first-seed {args.first_seed}"
             f" --gesture {args.gesture}")
    words += f" --duration {args.duration:g} --windows {args.windows}" + link_options.words(args)
    if args.output:
        words += f" -o {shlex.quote(str(args.output))}"
    return words


def run(args):
    import json
    import sys

    from studyapp.estimators.at_rate import check_windows
    from studyapp.estimators.spec import validate_rate
    from studyapp.evaluation.provenance import provenance
    from studyapp.model import breakdown, calibration
    from studyapp.model.playable import check_playable

    names = breakdown.sources() if args.all else [breakdown.check_source(args.source, "--source")]
    check_playable(validate_rate(args.rate, "--rate"), calibration.F0)
    breakdown.check_seeds(args.seeds, "--seeds")
    breakdown.check_first_seed(args.first_seed, args.seeds, "--first-seed")
    breakdown.check_gesture(args.gesture, "--gesture")
    breakdown.check_duration(args.duration, "--duration")
    check_windows(args.windows, "--windows")
    link = link_options.spec(args, args.rate)
    if args.output:
        check_output(args.output)

    results = []
    for i, name in enumerate(names):
        prefix = f"breakdown [{i + 1}/{len(names)}] {name}" if args.all else f"breakdown {name}"

        def progress(seed, trial, fmax, verdict, prefix=prefix):
            # one line per seed; the trials overwrite each other on it
            count = f"seed {seed - args.first_seed + 1}/{args.seeds}"
            if verdict == "result":
                line = f"{prefix}: {count}: F_max {_number(fmax)} N ({trial} trials)"
                print("\r" + line.ljust(72), file=sys.stderr, flush=True)
            else:
                line = f"{prefix}: {count}, trial {trial}: {fmax:.3g} N {verdict}"
                print("\r" + line.ljust(72), end="", file=sys.stderr, flush=True)

        results.append(breakdown.breakdown_over_seeds(name, rate=args.rate, seeds=args.seeds, gesture=args.gesture,
                                                      duration=args.duration, progress=progress, link=link,
                                                      first_seed=args.first_seed, windows=args.windows))

    made = provenance(command=command_line(args))
    results = [{**r, "provenance": made} for r in results]
    if args.json:
        json.dump(_json(results if args.all else results[0]), sys.stdout, indent=1, allow_nan=False)
        sys.stdout.write("\n")
    else:
        sys.stdout.write(text_table(results))
    if args.output:
        write(args.output, results, args)
        print(f"wrote {args.output} ({len(results)} source{'s' if len(results) > 1 else ''})", file=sys.stderr)
    return 0


def write(path, results, args):
    import csv
    import json
    from pathlib import Path

    from studyapp.io.atomic import atomic_open

    suffix = Path(path).suffix.lower()
    with atomic_open(path, "w", newline="", encoding="utf-8") as f:
        if suffix == ".csv":
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(COLUMNS + LINK_COLUMNS)
            writer.writerows([_cells(r, repr) + [repr(r[name]) for name in LINK_COLUMNS] for r in results])
        elif suffix == ".md":
            f.write(markdown(results, command_line(args)))
        else:
            json.dump(_json(results if args.all else results[0]), f, indent=1, allow_nan=False)
            f.write("\n")


def _json(value):
    """``value`` with inf (stable to the search's top) as null, since JSON has no infinity."""
    import math

    if isinstance(value, float) and math.isinf(value):
        return None
    if isinstance(value, list):
        return [_json(v) for v in value]
    if isinstance(value, dict):
        return {k: _json(v) for k, v in value.items()}
    return value


def _number(value):
    """F_max for people: 3 significant figures (the search's tolerance is 2 %), the search's bounds as bounds."""
    from studyapp.model.breakdown import HIGH, LOW

    if value == float("inf"):
        return f"> {HIGH:g}"
    if value <= LOW:
        return f"<= {LOW:g}"
    return f"{value:.3g}"


def _cells(result, fmt):
    """A result as the row of ``COLUMNS``, F_max values written with ``fmt``."""
    return [result["source"], f"{result['rate']:g}", result["gesture"], str(result["seeds"]),
            fmt(result["fmax_median"]), fmt(result["fmax_min"]), fmt(result["fmax_max"]),
            ";".join(fmt(v) for v in result["fmax"]), str(result["first_seed"]),
            ";".join(str(s) for s in result["seeds_used"]), result["windows"]]


def text_table(results):
    rows = [COLUMNS] + [_cells(r, _number) for r in results]
    widths = [max(len(row[i]) for row in rows) for i in range(len(COLUMNS))]
    return "".join("  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() + "\n" for row in rows)


def markdown(results, command):
    import datetime

    lines = [
        "# Breakdown F_max",
        "",
        f"Generated on {datetime.date.today().isoformat()} by `{command}`.",
        "",
        "The largest F_max (N) at which each velocity source keeps the simulated loop stable, judged by the "
        "stability monitor (`studyapp.model.breakdown`; see [model.md](model.md)). One search per seed (the sensors' "
        "noise and the hand's tremor); median, min and max over the seeds, then each seed's value, the first seed and "
        "the seeds in the order of the values. "
        f"\"{_number(float('inf'))}\": stable up to the search's top; \"{_number(0.0)}\": broken at its bottom.",
        "",
        _link_sentence(results[0]),
        "",
        "| " + " | ".join(COLUMNS) + " |",
        "|" + " --- |" * len(COLUMNS),
    ]
    lines += ["| " + " | ".join(_cells(r, _number)).replace(";", "; ") + " |" for r in results]
    return "\n".join(lines) + "\n"


def _link_sentence(result):
    """The link the device ran behind, from a result's ``LINK_COLUMNS`` (seconds)."""
    if not any(result[name] for name in LINK_COLUMNS):
        return "The simulated device is on an ideal link (latency, packet and jitter 0: the paper's loop)."
    times = ", ".join(f"{name} {round(result[name] * result['rate'])} samples ({result[name] * 1000:g} ms)"
                      for name in LINK_COLUMNS)
    return f"The simulated device is behind a link (`studyapp.model.link`): {times}."

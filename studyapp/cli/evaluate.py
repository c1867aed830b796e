"""``studyapp evaluate RECORDINGS... [--params PARAMS.toml] [--json] [-o DIR]`` (paper Sec. 7, Fig. 5).

Per estimator and recording: error E and delay D, both also as percent of
LOWPASS; the global objective and ranking; pairwise Wilcoxon rank-sum tests;
Fig. 5-style box plots (a: F_max 0-7.7 N, b: 2.2-12.1 N); and with
``--validation DIR`` the Sec. 7.3 comparison on an independent set. With
``--perceptual``, each estimator's ``audio_distance`` (the string's sound with
it in the loop against TRUE's, paper Sec. 10; cli/perceptual_options.py); with
``--compare-paper`` our Table 1 and findings beside the paper's, each finding
under the paper's Table 1 and under ``--params`` side by side
(``evaluation/paper_comparison.py``). Without ``--params`` the estimators
run with Table 1 made for the recordings' rate (``estimators/at_rate.py``).
"""

from studyapp.cli import delay_option, output_paths, perceptual_options


def register(sub):
    p = sub.add_parser("evaluate", help="error, delay, objective and ranking of estimators on recordings (Fig. 5)")
    p.add_argument("recordings", nargs="+", metavar="RECORDING",
                   help="recording files (.npz/.h5/.csv) or directories of them")
    p.add_argument("--params", nargs="+", metavar="PARAMS.toml",
                   help="tuned parameters (from studyapp optimise); with several files (e.g. optimise --seed 0, "
                        "1, 2) the first is evaluated and every file's F_g is compared under one common scale "
                        "(seed_spread.csv)")
    p.add_argument("--estimators", action="append", metavar="NAMES",  # one value: a list would swallow RECORDINGs
                   help="estimators to evaluate, comma separated (default: those in --params, else the paper's "
                        "thirteen)")
    p.add_argument("--reference", choices=("lvt", "true"), default="lvt",
                   help="reference velocity: the LVT tachometer (paper) or the true velocity (default lvt)")
    p.add_argument("--max-lag", type=float, default=0.02, metavar="SECONDS",
                   help="longest delay searched by the cross-correlation (default 0.02 s)")
    delay_option.add(p)
    p.add_argument("--json", action="store_true", help="print the results as one JSON object")
    p.add_argument("-o", "--output", metavar="DIR",
                   help="write evaluation.json, evaluation.csv, wilcoxon.csv and the Fig. 5 plots here")
    p.add_argument("--validation", metavar="DIR",
                   help="also evaluate this independent set and compare at matching F_max (Sec. 7.3)")
    p.add_argument("--perceptual", action="store_true",
                   help="also simulate each estimator in the loop and measure its audio against TRUE's "
                        "(audio_distance, perceptual.png)")
    perceptual_options.add_options(p, "--perceptual")
    p.add_argument("--compare-paper", action="store_true",
                   help="also write paper_comparison.csv (Table 1 beside ours) and findings.csv (each finding under "
                        "Table 1 and under --params side by side, and how many hold under each) to -o DIR; with "
                        "several --params files also their spread over the files: paper_comparison_seeds.csv, "
                        "metrics_seeds.csv and findings_seeds.csv")
    p.set_defaults(func=run)


def run(args):
    import json
    import sys
    from pathlib import Path

    from studyapp.errors import UserError
    from studyapp.evaluation.dataset import Dataset, expand_paths, load_takes
    from studyapp.evaluation.parameter_sets import parameter_sets
    from studyapp.evaluation.provenance import provenance
    from studyapp.evaluation.report import evaluate

    delay_option.check_max_lag(args.max_lag)
    output = Path(args.output) if args.output else None
    if output is not None:
        inputs = [*args.recordings, *(args.params or []), *filter(None, [args.validation])]  # --params: a list
        output_paths.check_folder(output, inputs=inputs)
    if args.compare_paper and output is None:
        raise UserError("--compare-paper: needs -o DIR, the folder its two tables are written to")
    params_files = args.params or [None]
    args.params = params_files[0]
    takes = load_takes(expand_paths(args.recordings), args.reference)
    unavailable = {}
    params, _ = parameter_sets(args.params, args.estimators, min(t.rate for t in takes), unavailable, for_rate=True)
    others = [parameter_sets(path, args.estimators, min(t.rate for t in takes)) for path in params_files[1:]]
    for name, reason in unavailable.items():
        print(f"studyapp evaluate: {name} skipped, {reason}", file=sys.stderr)
    cases = perceptual_options.cases(args, min(t.rate for t in takes), args.perceptual, "--perceptual")
    result = evaluate(Dataset(takes, args.max_lag, delay_method=args.delay), params)
    document = result.to_json()
    document["provenance"] = provenance(
        command="studyapp evaluate", reference=args.reference, max_lag_s=args.max_lag, delay=args.delay,
        params=args.params, recordings=[t.name for t in takes], recording_sha256=[t.sha256 for t in takes])
    if unavailable:
        document["unavailable"] = unavailable
    spread = None
    if others:
        from studyapp.evaluation.params_file import read
        from studyapp.evaluation.seed_spread import labels, seed_spread

        names = labels(params_files, [read(path)[1] for path in params_files])
        spread = seed_spread(Dataset(takes, args.max_lag, delay_method=args.delay),
                             dict(zip(names, [params] + [o[0] for o in others])))
        document["seed_spread"] = spread
    validation = None
    other = load_takes(expand_paths([args.validation]), args.reference) if args.validation else None
    if args.validation:
        from studyapp.evaluation.validation import compare

        summary, rows = compare(result, evaluate(Dataset(other, args.max_lag, delay_method=args.delay), params))
        summary["provenance"] = {**document["provenance"], "validation_recordings": [t.name for t in other],
                                 "validation_recording_sha256": [t.sha256 for t in other]}
        validation = (summary, rows)
        document["validation"] = summary
    perceptual = None if cases is None else perceptual_options.add_to_evaluation(cases, result, document)
    findings = None
    if args.compare_paper:
        findings = _findings_of_both_sets(args, takes, other, params, result, validation[0] if validation else None)
        from studyapp.evaluation.paper_comparison import counts

        document["findings"] = {**counts(findings), "rows": findings}
    over_seeds = None
    if args.compare_paper and others:
        over_seeds = _study_over_seeds(args, takes, other, dict(zip(names, [params] + [o[0] for o in others])),
                                       result, validation[0] if validation else None)
        document["study_over_seeds"] = over_seeds
    if output is not None:
        _write_outputs(output, result, document, validation)
        if spread is not None:
            from studyapp.evaluation.tables import write_csv

            write_csv(output / "seed_spread.csv", spread)
        if perceptual is not None:
            perceptual_options.write_outputs(output, perceptual, result.names)
    if args.compare_paper:
        from studyapp.evaluation import paper_comparison

        paper_comparison.write(output, result, findings)
        if over_seeds is not None:
            from studyapp.evaluation.tables import write_csv

            for key, rows in over_seeds.items():
                write_csv(output / f"{key}_seeds.csv", rows)
    if args.json:
        json.dump(document, sys.stdout, indent=1, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _print_table(result, validation)
        if perceptual is not None:
            perceptual_options.print_table(perceptual, result.names)
        if findings is not None:
            _print_findings(findings, args.params)
        if over_seeds is not None:
            print("findings over the parameter files (holds / fails on every one, else undecided):")
            for row in over_seeds["findings"]:
                print(f"  {row['verdict']:<16} ({row['holds_on']} holds, {row['fails_on']} fails, "
                      f"{row['undecided_on']} undecided)  {row['finding']}")
        if spread is not None:
            print("F_g of each parameter file under one common scale:")
            for row in spread:
                cells = "  ".join(f"{k[4:]} {v:.4g}" if v is not None else f"{k[4:]} inf"
                                  for k, v in row.items() if k.startswith("F_g "))
                pct = "-" if row["spread_pct"] is None else f"{row['spread_pct']:.2f} %"
                apart = "" if row["delays_apart"] is None else (
                    f"  |D| apart on {row['delays_apart']} recordings (at most {row['max_delay_apart']}),"
                    f" E apart {row['error_spread_pct']:.1f} %")
                print(f"  {row['estimator']:<11} {cells}  spread {pct}{apart}")
    return 0


def _findings_of_both_sets(args, takes, validation_takes, params, result, summary):
    """findings.csv's rows: the evaluated set's findings and, with --params, Table 1's beside them (issue 42).

    Table 1 is made for the recordings' rate, as ``evaluate`` without ``--params`` runs it, for the same
    estimators, on the same recordings (and the same validation recordings).
    """
    import sys

    from studyapp.errors import UserError
    from studyapp.evaluation import paper_comparison
    from studyapp.evaluation.dataset import Dataset
    from studyapp.evaluation.parameter_sets import parameter_sets
    from studyapp.evaluation.report import evaluate
    from studyapp.evaluation.validation import compare

    positions = [t.position for t in takes]
    own = paper_comparison.finding_rows(result, positions, summary)
    if args.params is None:
        return paper_comparison.both_sets(own)
    unavailable = {}
    try:
        table1, _ = parameter_sets(None, [",".join(params)], min(t.rate for t in takes), unavailable, for_rate=True)
    except UserError as exc:  # Table 1 cannot exist at this rate for any of these estimators: the tuned set alone
        print(f"studyapp evaluate: --compare-paper: no finding under Table 1, {exc}", file=sys.stderr)
        return paper_comparison.both_sets([], own)
    for name, reason in unavailable.items():
        print(f"studyapp evaluate: {name} skipped under Table 1, {reason}", file=sys.stderr)
    paper = evaluate(Dataset(takes, args.max_lag, delay_method=args.delay), table1)
    paper_summary = None
    if validation_takes is not None:
        paper_summary, _ = compare(paper, evaluate(Dataset(validation_takes, args.max_lag,
                                                           delay_method=args.delay), table1))
    return paper_comparison.both_sets(paper_comparison.finding_rows(paper, positions, paper_summary), own)


def _print_findings(rows, params_path):
    from studyapp.evaluation.paper_comparison import counts as count

    counts = count(rows)
    table1 = (f"{counts['holds_table1']} of {counts['judged_table1']} hold with the paper's Table 1"
              if counts["holds_table1"] is not None else "none judged with the paper's Table 1")
    if counts["holds_tuned"] is None:
        print(f"findings (findings.csv): {table1}; one parameter set (no --params): nothing tuned beside it")
    else:
        print(f"findings (findings.csv): {table1}, {counts['holds_tuned']} of {counts['judged_tuned']} "
              f"with the tuned parameters ({params_path})")
    for row in rows:
        tuned = "" if row.get("verdict_tuned") is None else f"  tuned {row['verdict_tuned']:<16}"
        print(f"  Table 1 {row.get('verdict_table1') or '-':<16}{tuned}  {row['finding']}")


def _study_over_seeds(args, takes, validation_takes, sets, first, first_validation):
    """Table 1, the metrics and the findings of every parameter file (label -> parameters), and their spread."""
    from studyapp.evaluation import paper_comparison, study_over_seeds
    from studyapp.evaluation.dataset import Dataset
    from studyapp.evaluation.report import evaluate
    from studyapp.evaluation.validation import compare

    positions = [t.position for t in takes]
    results, findings = {}, {}
    for i, (label, params) in enumerate(sets.items()):
        result, summary = first, first_validation
        if i:
            result = evaluate(Dataset(takes, args.max_lag, delay_method=args.delay), params)
            if validation_takes is not None:
                summary, _ = compare(result, evaluate(Dataset(validation_takes, args.max_lag,
                                                              delay_method=args.delay), params))
        results[label] = result
        findings[label] = paper_comparison.finding_rows(result, positions, summary)
    return {"paper_comparison": study_over_seeds.parameter_rows(sets),
            "metrics": study_over_seeds.metric_rows(results),
            "findings": study_over_seeds.finding_rows(findings)}


def _write_outputs(output, result, document, validation):
    import json
    import sys

    from studyapp.io.atomic import atomic_open
    from studyapp.evaluation import figures
    from studyapp.evaluation.report import GROUP_TITLES, GROUPS
    from studyapp.evaluation.significance import pairwise
    from studyapp.evaluation.tables import write_csv

    output.mkdir(parents=True, exist_ok=True)
    with atomic_open(output / "evaluation.json", "w", encoding="utf-8") as f:
        json.dump(document, f, indent=1, allow_nan=False)
    write_csv(output / "evaluation.csv", result.rows())
    tests = []
    for group in GROUPS:
        if not result.group_mask(group).any():
            print(f"studyapp evaluate: no recording in group {group} ({GROUP_TITLES[group]}): "
                  f"no fig5{group}", file=sys.stderr)
            continue
        measures = result.measures(group)
        for measure, samples in measures.items():
            tests += [{"group": group, "measure": measure, **row} for row in pairwise(samples)]
        figures.boxplots(measures, f"Fig. 5{group}: {GROUP_TITLES[group]}", output / f"fig5{group}")
    write_csv(output / "wilcoxon.csv", tests, ["group", "measure", "a", "b", "n_a", "n_b", "median_a",
                                               "median_b", "statistic", "p", "significant"])
    if validation is not None:
        summary, rows = validation
        with atomic_open(output / "validation.json", "w", encoding="utf-8") as f:
            json.dump(summary, f, indent=1, allow_nan=False)
        write_csv(output / "validation.csv", rows)


def _print_table(result, validation):
    import numpy as np

    from studyapp.evaluation.report import finite_median

    print(f"{'rank':>4}  {'estimator':<11} {'objective':>10} {'E median':>11} {'E %LP':>7} "
          f"{'D median':>8} {'D %LP':>7}")
    for rank, name in enumerate(result.ranking, 1):
        e, d = result.errors[name], result.delays[name]
        print(f"{rank:>4}  {name:<11} {result.objective[name]:>10.4g} {np.median(e):>11.4g} "
              f"{finite_median(result.error_pct(name)):>7.1f} {np.median(d):>8.1f} "
              f"{finite_median(result.delay_pct(name)):>7.1f}")
    if validation is not None:
        s = validation[0]
        print(f"validation ({s['matched_recordings']} matched recordings): error difference "
              f"{s['error_difference_pct_mean']:.3g} +- {s['error_difference_pct_std'] or 0:.3g} %, "
              f"delay difference {s['delay_difference_mean']:.3g} +- {s['delay_difference_std'] or 0:.3g} samples")

"""``studyapp analyse RESULTS_DIR [--evaluation DIR] [--holm] [--include-practice] [--include-simulated]
[--pooled-letters] -o REPORT_DIR``: the paper's Sec. 9-10.

RESULTS_DIR is a results folder or an exported responses .csv. Writes the
paper's pooled Wilcoxon rank-sum tables, the within-subject Friedman and
signed-rank tables, the summary and Spearman tables, Figs. 7-9 (PNG and SVG)
and report.html into REPORT_DIR (see studyapp/analysis/report_folder.py);
with --evaluation, the numerical comparisons and perceptual_correlation.csv.
Practice trials are left out unless --include-practice, and the sessions of
the simulated participant (export's ``simulated`` column) unless
--include-simulated; with nothing but simulated sessions that is one line and
exit 2. The letters on Figs. 7-8 come from the within-subject tests; with
--pooled-letters from the paper's pooled rank-sum tests, labelled so.
Participants short of responses, and too few participants for a test, are
listed on stderr and in the report. An unreadable session or damaged log line
in RESULTS_DIR is skipped with a warning (refused with --strict).
"""

import sys


def register(subparsers):
    parser = subparsers.add_parser(
        "analyse",
        help="Wilcoxon, Friedman and Spearman analyses, Figs. 7-9 and report.html from study responses",
        description="Analyse study responses as the paper's Sec. 9-10: pairwise Wilcoxon rank-sum tests on "
        "trials pooled across participants (the paper's), the within-subject Friedman and Holm-corrected "
        "signed-rank tests on per-participant medians, medians and quartiles, per-participant Spearman rho, "
        "Figs. 7-9 and one self-contained report.html.",
    )
    parser.add_argument("results", metavar="RESULTS_DIR", help="a results folder, or a responses .csv from 'studyapp export'")
    parser.add_argument("-o", "--output", metavar="REPORT_DIR", required=True, help="folder for the tables, figures and report.html")
    parser.add_argument("--evaluation", metavar="DIR", help="an 'studyapp evaluate -o DIR' folder (or its evaluation.json): compare with the numerical rankings, "
                        "and noisiness with audio_distance (perceptual_correlation.csv)")
    parser.add_argument("--holm", action="store_true", help="Holm-correct the p-values of each task's pooled rank-sum tests (the signed-rank tests always are)")
    parser.add_argument("--alpha", type=float, default=0.05, help="significance threshold (default 0.05, the paper's)")
    parser.add_argument("--trials", type=int, metavar="N", help="adjustment trials each participant owes per condition (default: the most any participant has)")
    parser.add_argument("--include-practice", action="store_true",
                        help="analyse the practice trials too (by default their rows, practice = True, are left out)")
    parser.add_argument("--include-simulated", action="store_true",
                        help="analyse the simulated participants' sessions too (by default their rows, "
                             "simulated = True, are left out)")
    parser.add_argument("--pooled-letters", action="store_true",
                        help="letters on Figs. 7-8 from the paper's rank-sum tests on trials pooled across "
                             "participants (labelled so) instead of the within-subject tests")
    parser.add_argument("--strict", action="store_true",
                        help="refuse (exit 2) a results folder with an unreadable session or log line; by default "
                             "such data is skipped with a warning")
    parser.set_defaults(func=run)


def run(args):
    from studyapp.analysis.counted import counted
    from studyapp.analysis.numerical import load_evaluation
    from studyapp.analysis.report_folder import write_report_folder
    from studyapp.analysis.responses import load_responses
    from studyapp.analysis.study import analyse
    from studyapp.cli import output_paths
    from studyapp.errors import ParameterError, UserError
    from studyapp.experiment.records import TRIAL_MAX

    if not 0.0 < args.alpha < 1.0:
        raise ParameterError(f"--alpha {args.alpha:g}: allowed 0 < alpha < 1")
    if args.trials is not None and not 1 <= args.trials <= TRIAL_MAX:
        raise ParameterError(f"--trials {args.trials}: allowed an integer from 1 to {TRIAL_MAX}")

    def say(message):
        print(f"studyapp analyse: {message}", file=sys.stderr, flush=True)

    output_paths.check_folder(args.output, inputs=[args.results, *filter(None, [args.evaluation])])
    # read before saying anything: bad input is then the one line on stderr
    problems = []
    responses, label = load_responses(args.results, problems, include_practice=args.include_practice,
                                      include_simulated=args.include_simulated)
    for problem in problems:
        say(f"warning: {problem}")
    if problems and args.strict:
        raise UserError(f"{args.results}: {len(problems)} unreadable session(s) or log line(s), listed above; "
                        "nothing written: allowed without --strict (the readable data is analysed, with warnings)")
    evaluation = load_evaluation(args.evaluation) if args.evaluation else None
    say(f"read {args.results}")
    expected = {"adjustment": args.trials} if args.trials else None
    study = analyse(responses, source=label, evaluation=evaluation, holm=args.holm, alpha=args.alpha, expected=expected,
                    pooled_letters=args.pooled_letters, include_simulated=args.include_simulated)
    say(f"{counted(len(study.participants), 'participant')}, {counted(len(responses), 'response')}")
    if study.simulated_left_out:
        say(f"left out {counted(len(study.simulated_left_out), 'simulated participant')} "
            f"({', '.join(study.simulated_left_out)}): "
            "--include-simulated analyses them too")
    for line in study.warnings() + study.sample_size_warnings():
        say(f"warning: {line}")
    if study.perceptual_note:
        say(f"note: {study.perceptual_note}")
    if not study.missing.empty:
        say(f"{len(study.missing)} short participant/condition combinations listed in missing_trials.csv")
    write_report_folder(study, args.output, progress=say, evaluation_path=args.evaluation, expected=expected)
    say(f"report: {args.output}/report.html")
    return 0

"""``studyapp export RESULTS_DIR [-o responses.csv] [--strict]``: every response as one tidy CSV.

One row per response (long format), first the columns ``participant, session,
task, condition, trial, fmax, rating, time, protocol_hash``; see
``studyapp.experiment.export`` for their meaning. RESULTS_DIR may be the
results folder, one study's folder, a participant's or a session's.

A session that cannot be read is skipped and a damaged log line left out,
each with a warning on stderr naming the file (and line); the export goes on
with everything readable. With ``--strict`` any such problem refuses the
export instead (exit 2, nothing written).
"""


def register(sub):
    parser = sub.add_parser("export", help="export study responses as a tidy CSV")
    parser.add_argument("results", metavar="RESULTS_DIR", help="results folder (or any folder inside it)")
    parser.add_argument("-o", "--output", default="responses.csv", metavar="FILE.csv",
                        help="output CSV (default: responses.csv)")
    parser.add_argument("--strict", action="store_true",
                        help="refuse (exit 2, nothing written) if any session or log line cannot be read; "
                             "by default such data is skipped with a warning")
    parser.set_defaults(func=run)


def run(args):
    import sys

    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.experiment.export import export_responses, save_responses

    output_paths.check_file(args.output)  # never into a session folder, whose files are the export's inputs
    problems = []
    frame = export_responses(args.results, problems)
    for problem in problems:
        print(f"studyapp export: warning: {problem}", file=sys.stderr)
    if problems and args.strict:
        raise UserError(f"{args.results}: {len(problems)} unreadable session(s) or log line(s), listed above; "
                        "nothing written: allowed without --strict (the readable data is exported, with warnings)")
    save_responses(frame, args.results, args.output)
    sessions = frame.groupby(["study", "participant", "session"]).ngroups
    print(f"studyapp export: {len(frame)} responses from {sessions} sessions -> {args.output}", file=sys.stderr)
    return 0

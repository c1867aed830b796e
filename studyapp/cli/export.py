"""``studyapp export RESULTS_DIR [-o responses.csv]``: every response as one tidy CSV.

One row per response (long format), first the columns ``participant, session,
task, condition, trial, fmax, rating, time, protocol_hash``; see
``studyapp.experiment.export`` for their meaning. RESULTS_DIR may be the
results folder, one study's folder, a participant's or a session's.
"""


def register(sub):
    parser = sub.add_parser("export", help="export study responses as a tidy CSV")
    parser.add_argument("results", metavar="RESULTS_DIR", help="results folder (or any folder inside it)")
    parser.add_argument("-o", "--output", default="responses.csv", metavar="FILE.csv",
                        help="output CSV (default: responses.csv)")
    parser.set_defaults(func=run)


def run(args):
    import sys

    from studyapp.cli import output_paths
    from studyapp.experiment.export import write_responses

    output_paths.check_file(args.output)
    frame = write_responses(args.results, args.output)
    sessions = frame.groupby(["study", "participant", "session"]).ngroups
    print(f"studyapp export: {len(frame)} responses from {sessions} sessions -> {args.output}", file=sys.stderr)
    return 0

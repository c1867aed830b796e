"""``studyapp plan --protocol FILE --participant ID [--results DIR] [--order-row N] [--simulated-participant]
[--blind] [-o FILE]``: the session's run sheet, before Start.

Prints the plan (order row, conditions in order per task, every step with
its estimated duration: ``studyapp.experiment.run_plan``) as Markdown on
stdout, or writes it to FILE with ``-o`` (atomically): Markdown reads as
plain text on paper and renders in any Markdown viewer. Reads the results
folder only to predict the participant's order row and to estimate
durations from recorded trials; writes nothing there. ``--blind`` leaves out
every condition name.
"""


def register(sub):
    parser = sub.add_parser("plan", help="print a session's run sheet (order, conditions, steps, duration) before Start")
    parser.add_argument("--protocol", required=True, metavar="FILE", help="study protocol (TOML)")
    parser.add_argument("--participant", required=True, metavar="ID",
                        help="participant pseudonym: 1 to 32 letters, digits, '_' or '-'")
    parser.add_argument("--results", default=None, metavar="DIR",
                        help="results folder (default: $STUDYAPP_RESULTS, else ~/.local/share/studyapp/results; made absolute)")
    parser.add_argument("--order-row", metavar="N",
                        help="the Latin-square order row, from 0 (default: from the participant's enrolment)")
    parser.add_argument("--simulated-participant", action="store_true",
                        help="plan a simulated participant's session (simulated runs have order rows of their own)")
    parser.add_argument("--blind", action="store_true", help="name no condition (for a blinded experimenter)")
    parser.add_argument("-o", "--output", metavar="FILE", help="write the run sheet (Markdown) to FILE")
    parser.set_defaults(func=run)


def run(args):
    import sys
    from pathlib import Path

    from studyapp.io.atomic import atomic_open
    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.experiment.protocol import load_protocol
    from studyapp.experiment.run_plan import make_plan, plan_markdown
    from studyapp.experiment.session import check_participant

    check_participant(args.participant)
    from studyapp.experiment.results_folder import absolute

    results = absolute(args.results)
    if results.exists() and not results.is_dir():
        raise UserError(f"--results {results}: is not a folder: allowed is a results folder (or one not made yet)")
    if args.output is not None:
        output_paths.check_file(args.output, inputs=(args.protocol,))
    protocol = load_protocol(args.protocol)
    text = plan_markdown(make_plan(protocol, args.participant, results, order_row=args.order_row,
                                   simulated=args.simulated_participant), blind=args.blind)
    if args.output is None:
        sys.stdout.write(text)
        return 0
    with atomic_open(args.output, encoding="utf-8") as f:
        f.write(text)
    print(f"studyapp plan: run sheet -> {args.output}", file=sys.stderr)
    return 0

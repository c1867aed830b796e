"""``studyapp simulate-set``: the paper's data set (Sec. 6.1), or its validation twin (Sec. 7.3)."""


def register(subparsers):
    p = subparsers.add_parser(
        "simulate-set",
        help="simulate the paper's 15 recordings (7 s, F_max 0..12.1 N, LVT in the loop)",
        description="Write DIR/fmax_<value>.npz for each of the paper's 15 F_max values plus DIR/index.json.",
    )
    p.add_argument("-o", "--output", required=True, help="output directory")
    p.add_argument("--validation", action="store_true",
                   help="the independent second set (another seed, slightly different strokes)")
    p.add_argument("--rate", type=float, default=5000.0, help="sample rate in Hz (default 5000, the paper's)")
    p.add_argument("--duration", type=float, default=7.0, help="seconds per recording (default 7)")
    p.set_defaults(func=run)


def run(args):
    import sys

    from studyapp.cli import output_paths
    from studyapp.errors import ParameterError
    from studyapp.estimators.spec import validate_rate
    from studyapp.model import calibration
    from studyapp.model.data_set import write_set
    from studyapp.model.playable import check_playable
    from studyapp.model.simulate import DURATION_MAX

    # checked before write_set makes the folder, so a bad value leaves nothing behind
    check_playable(validate_rate(args.rate, "--rate"), calibration.F0)
    if not 0 < args.duration <= DURATION_MAX:
        raise ParameterError(f"--duration {args.duration:g}: allowed is a number of seconds above 0 and at most "
                             f"{DURATION_MAX:g}")
    output_paths.check_folder(args.output)

    def progress(i, total, name):
        print(f"\rsimulate-set: {i}/{total} {name}   ", end="", file=sys.stderr, flush=True)

    index = write_set(args.output, validation=args.validation, rate=args.rate, duration=args.duration,
                      progress=progress)
    print("", file=sys.stderr)
    print(f"wrote {len(index['files'])} recordings and index.json to {args.output}", file=sys.stderr)
    return 0

"""``studyapp simulate``: one simulated recording of bowing the string through the closed loop."""

from studyapp.cli import link_options, number_options

SOURCES_HELP = "velocity source in the loop: an estimator name, LVT or TRUE (default LVT)"


def register(subparsers):
    p = subparsers.add_parser(
        "simulate",
        help="simulate one recording (position, LVT, acceleration, ground truth, force, audio)",
        description="Simulate bowing the string through the closed haptic loop and write a recording "
                    "(.h5, .npz or .csv).",
    )
    p.add_argument("--fmax", type=float, default=1.0, help="peak friction force F_max in N (default 1)")
    p.add_argument("--rate", type=float, default=5000.0, help="sample rate in Hz, 1000..96000 (default 5000)")
    p.add_argument("--duration", type=float, default=7.0, help="seconds (default 7)")
    p.add_argument("--source", default=None, help=SOURCES_HELP)
    p.add_argument("--gesture", default="strokes", help="strokes, strokes-validation or hold (default strokes)")
    p.add_argument("--f0", type=float, default=None, help="string pitch in Hz (default: the model's)")
    p.add_argument("--seed", type=number_options.seed, default=0, help="random seed (default 0)")
    link_options.add(p)
    p.add_argument("-o", "--output", required=True, help="output file: .h5, .npz or .csv")
    p.set_defaults(func=run)


def check_source(name):
    from studyapp.errors import ParameterError
    from studyapp.estimators import names
    from studyapp.model.sources import with_pseudo_sources

    allowed = with_pseudo_sources(names())
    if name not in allowed:
        raise ParameterError(f"--source {name!r}: allowed are {', '.join(allowed)}")


def check_gesture(name):
    from studyapp.errors import ParameterError

    allowed = ("strokes", "strokes-validation", "hold")
    if name not in allowed:
        raise ParameterError(f"--gesture {name!r}: allowed are {', '.join(allowed)}")


def run(args):
    import sys

    from studyapp.io import recording
    from studyapp.cli import output_paths
    from studyapp.estimators.spec import validate_rate
    from studyapp.model.simulate import simulate
    from studyapp.model.loop import check_fmax
    from studyapp.model.sources import LVT_SENSOR

    if args.source is None:
        args.source = LVT_SENSOR
    recording.check_path(args.output)
    output_paths.check_file(args.output)
    rate = validate_rate(args.rate)
    if 0 < args.duration and round(args.duration * rate) < 1:  # would write a recording with no samples
        from studyapp.errors import ParameterError

        raise ParameterError(f"--duration {args.duration:g}: allowed is at least one sample, {1 / rate:g} s at "
                             f"{rate:g} Hz")
    check_fmax(args.fmax)
    check_source(args.source)
    check_gesture(args.gesture)
    link = link_options.spec(args)

    def progress(done, total):
        print(f"\rsimulate: {100 * done // total:3d}%", end="", file=sys.stderr, flush=True)

    rec = simulate(args.fmax, rate=args.rate, duration=args.duration, source=args.source,
                   gesture=args.gesture, f0=args.f0, seed=args.seed, progress=progress, link=link)
    print("", file=sys.stderr)
    recording.save(rec, args.output)
    print(f"wrote {args.output} ({len(rec)} samples at {rec.rate:g} Hz, F_max {args.fmax:g} N, source {args.source})",
          file=sys.stderr)
    return 0

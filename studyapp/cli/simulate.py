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
    p.add_argument("--rate", type=float, default=5000.0, help="sample rate in Hz, 1000..96000 and at least 6 x f0 (default 5000)")
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


def check_disk(path, suffix, samples, columns):
    """One-line ``UserError`` when the output's folder has not the room the recording needs (before any work)."""
    import shutil
    from pathlib import Path

    from studyapp.errors import UserError
    from studyapp.io.recording_writer import bytes_needed

    need = bytes_needed(suffix, samples, columns)
    folder = Path(path).resolve().parent
    free = shutil.disk_usage(folder).free
    if need > free:
        raise UserError(f"-o {path}: the recording needs about {need / 1e6:,.0f} MB and {folder} has "
                        f"{free / 1e6:,.0f} MB free: allowed is a shorter --duration, a lower --rate or "
                        f"another folder")


def run(args):
    import sys
    import time
    from pathlib import Path

    from studyapp.cli import output_paths
    from studyapp.errors import ParameterError
    from studyapp.estimators.spec import validate_rate
    from studyapp.io import recording
    from studyapp.io.recording_writer import RecordingWriter
    from studyapp.model import calibration
    from studyapp.model.loop import check_f0, check_fmax
    from studyapp.model.playable import check_playable
    from studyapp.model.simulate import DURATION_MAX, Simulation
    from studyapp.model.sources import LVT_SENSOR

    if args.source is None:
        args.source = LVT_SENSOR
    recording.check_path(args.output)
    output_paths.check_file(args.output)
    rate = validate_rate(args.rate, "--rate")
    if not 0 < args.duration <= DURATION_MAX:
        raise ParameterError(f"--duration {args.duration:g}: allowed is a number of seconds above 0 and at most "
                             f"{DURATION_MAX:g}")
    if round(args.duration * rate) < 1:  # would write a recording with no samples
        raise ParameterError(f"--duration {args.duration:g}: allowed is at least one sample, {1 / rate:g} s at "
                             f"{rate:g} Hz")
    fmax = check_fmax(args.fmax)
    check_playable(rate, check_f0(calibration.F0 if args.f0 is None else args.f0))
    check_source(args.source)
    check_gesture(args.gesture)
    link = link_options.spec(args, rate)
    samples = int(round(args.duration * rate))
    check_disk(args.output, Path(args.output).suffix.lower(), samples, len(recording.COLUMNS))

    sim = Simulation(fmax, rate=rate, duration=args.duration, source=args.source, gesture=args.gesture,
                     f0=args.f0, seed=args.seed, link=link)
    started = time.monotonic()

    def progress(done, total):
        elapsed = time.monotonic() - started
        left = elapsed * (total - done) / done if done else 0.0
        print(f"\rsimulate: {100 * done // total:3d}% ({done / rate:,.2f} of {total / rate:,.2f} s, "
              f"about {left:,.0f} s left)", end="", file=sys.stderr, flush=True)

    try:
        with RecordingWriter(args.output, recording.COLUMNS) as writer:
            for block in sim.blocks(progress):
                writer.write(block)
            writer.finish(sim.rate, sim.meta())
    finally:
        print("", file=sys.stderr)  # ends the progress line, before a success's or an error's line
    print(f"wrote {args.output} ({sim.total} samples at {sim.rate:g} Hz, F_max {fmax:g} N, source {args.source})",
          file=sys.stderr)
    return 0

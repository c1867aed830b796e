"""``studyapp optimise RECORDINGS... -o PARAMS.toml``: tune estimators (paper Sec. 6.3, our Table 1).

Runs the objective-sum optimiser with adaptive normalisation over the
recordings and writes the tuned parameters with their provenance. Progress
(best objective per estimator) goes to stderr; a checkpoint beside the output
lets ``--resume`` continue an interrupted run to the same result.

``--objective perceptual`` (paper Sec. 10's future work) tunes each estimator
for the least ``audio_distance`` instead: every candidate set is simulated in
the closed loop on the perceptual cases (cli/perceptual_options.py), so no
recordings are read; the default patience is then ``PERCEPTUAL_PATIENCE``.
"""

from studyapp.cli import delay_option, number_options, output_paths, perceptual_options

PAPER_PATIENCE = 1000  # the paper's stopping rule
# Lanes of each search that start from drawn points, within the same patience (evaluation/search.py):
# with 2, seeds 0-2 gave F_g within 2 % of each other for 10 of the 13 estimators (docs/evaluation.md).
RESTARTS = 2
RESTARTS_MAX = 50  # lanes share the patience: more only split it thinner
RIDGE = 0.5  # share of proposals drawn along the lane's elite (search.py); measured in docs/evaluation.md
# Each set costs a closed-loop simulation per case (eight by default): at a tenth of the paper's rule a run
# of the thirteen took 2549 sets, 170 s of CPU (docs/evaluation.md).
PERCEPTUAL_PATIENCE = 100


def register(sub):
    p = sub.add_parser("optimise", help="tune estimators on recordings (objective sum, pure adaptive search)")
    p.add_argument("recordings", nargs="*", metavar="RECORDING",
                   help="recording files (.npz/.h5/.csv) or directories of them (e.g. from simulate-set); "
                        "none with --objective perceptual")
    p.add_argument("-o", "--output", required=True, metavar="PARAMS.toml", help="where to write the tuned parameters")
    # one value per option (comma separated, the option repeatable): a list of values would swallow the
    # RECORDING after it ("--estimators LOWPASS rec.npz")
    p.add_argument("--estimators", action="append", metavar="NAMES",
                   help="estimators to tune, comma separated, e.g. LOWPASS,KALMAN (default: the paper's thirteen)")
    p.add_argument("--objective", choices=("paper", "perceptual"), default="paper",
                   help="what to minimise: the paper's objective sum of error and delay over the recordings, or "
                        "the audio distance to TRUE in the closed loop (default paper)")
    p.add_argument("--rate", type=float, metavar="HZ",
                   help="sample rate of the perceptual simulations (--objective perceptual; default 5000)")
    p.add_argument("--patience", type=int,
                   help=f"stop an estimator after this many new sets without improvement "
                        f"(default {PAPER_PATIENCE}; {PERCEPTUAL_PATIENCE} with --objective perceptual)")
    p.add_argument("--seed", type=number_options.seed, default=0, help="random seed (default 0)")
    p.add_argument("--restarts", type=int, default=RESTARTS, metavar="N",
                   help=f"restarts of each estimator's search from drawn points, sharing the patience "
                        f"(default {RESTARTS}; 0: one search from Table 1, as before restarts)")
    p.add_argument("--ridge", type=number_options.finite_float, default=RIDGE, metavar="FRACTION",
                   help=f"share of draws made along the ridge of the best sets found "
                        f"(default {RIDGE}; 0: none, as before ridge draws)")
    p.add_argument("--reference", choices=("lvt", "true"), default="lvt",
                   help="reference velocity: the LVT tachometer (paper) or the true velocity (default lvt)")
    p.add_argument("--tune", choices=("paper", "all"), default="paper",
                   help="parameters to tune: the paper's Table 2 list, or every numeric one (default paper)")
    p.add_argument("--max-lag", type=float, default=0.02, metavar="SECONDS",
                   help="longest delay searched by the cross-correlation (default 0.02 s)")
    delay_option.add(p)
    p.add_argument("--range", action="append", default=[], metavar="NAME.PARAM=LOW:HIGH",
                   help="search range of one parameter, within its allowed range (e.g. FOAW.window=2:128)")
    p.add_argument("--max-sets", type=int, metavar="N", help="also stop an estimator after N new sets")
    p.add_argument("--workers", type=int, metavar="N", help="worker processes (default: all cores; 1: in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a dask.distributed cluster (e.g. tcp://host:8786) instead of local processes")
    p.add_argument("--checkpoint", metavar="FILE", help="checkpoint file (default: OUTPUT.checkpoint.json)")
    p.add_argument("--resume", action="store_true", help="continue from the checkpoint")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    perceptual_options.add_options(p, "--objective perceptual")
    p.set_defaults(func=run)


def run(args):
    import sys
    from functools import partial
    from pathlib import Path

    from studyapp.errors import UserError
    from studyapp.evaluation import checkpoint as checkpoints
    from studyapp.evaluation import params_file
    from studyapp.evaluation.dataset import (
        RawObjectives, RecordingFiles, estimator_names, expand_paths, load_takes, warm_up,
    )
    from studyapp.evaluation.executors import check_workers, make_executor
    from studyapp.evaluation.optimiser import Optimiser
    from studyapp.evaluation.progress import Progress
    from studyapp.evaluation.provenance import provenance
    from studyapp.evaluation.space import PAPER_ESTIMATORS, Space

    perceptual = args.objective == "perceptual"
    if args.patience is None:
        args.patience = PERCEPTUAL_PATIENCE if perceptual else PAPER_PATIENCE
    output = Path(args.output)
    if output.suffix.lower() != ".toml":
        raise UserError(f"-o {output}: expected a .toml file")
    checkpoint = Path(args.checkpoint) if args.checkpoint else output.with_name(output.name + ".checkpoint.json")
    output_paths.check_file(args.output, inputs=args.recordings)  # as spelled: Path() drops a trailing '/'
    output_paths.check_file(args.checkpoint or checkpoint, "--checkpoint", inputs=[*args.recordings, output])
    delay_option.check_max_lag(args.max_lag)
    if args.patience < 1:
        raise UserError(f"--patience {args.patience}: allowed is an integer of at least 1")
    if args.max_sets is not None and args.max_sets < 1:
        raise UserError(f"--max-sets {args.max_sets}: allowed is an integer of at least 1")
    if not 0 <= args.restarts <= RESTARTS_MAX:
        raise UserError(f"--restarts {args.restarts}: allowed is an integer from 0 to {RESTARTS_MAX}")
    if not 0.0 <= args.ridge <= 1.0:
        raise UserError(f"--ridge {args.ridge:g}: allowed is a fraction from 0 to 1")
    check_workers(args.workers)
    names = estimator_names(args.estimators, PAPER_ESTIMATORS)
    cases = perceptual_options.cases(args, 5000.0 if args.rate is None else args.rate, perceptual,
                                     "--objective perceptual")
    if perceptual:
        if args.recordings:
            raise UserError(f"{args.recordings[0]}: --objective perceptual reads no recordings (it simulates "
                            "its own cases: --perceptual-fmax, --perceptual-seeds, --rate)")
        paths, takes, rate = [], [], cases.rate
    else:
        if args.rate is not None:
            raise UserError("--rate: only with --objective perceptual (the recordings give the rate)")
        if not args.recordings:
            raise UserError("no recordings given: --objective paper needs RECORDING files or directories")
        paths = expand_paths(args.recordings)
        # the files a folder holds are inputs too: --checkpoint DIR/b.npz overwrote a recording (issue 33)
        output_paths.check_file(output, inputs=paths)
        output_paths.check_file(checkpoint, "--checkpoint", inputs=[*paths, output])
        takes = load_takes(paths, args.reference)  # checks every file before any work starts
        rate = min(t.rate for t in takes)
    ranges = parse_ranges(args.range)
    spaces = {name: Space(name, rate, args.tune, ranges=ranges.get(name)) for name in names}
    if args.resume and not checkpoint.is_file():
        raise UserError(f"--resume: no checkpoint at {checkpoint}")
    if not args.resume:
        _refuse_an_unfinished_checkpoint(checkpoint)

    if perceptual:
        from studyapp.evaluation import perceptual_scores

        objective = partial(perceptual_scores.perceptual_objective_task, cases)
        fingerprint = {"objective": "perceptual", "perceptual": cases.describe(), "tune": args.tune}
        initializer, initargs = perceptual_scores.warm_up, (cases, tuple(names))
    else:
        objective = RawObjectives(RecordingFiles(tuple(paths), args.reference, args.max_lag, tuple(names),
                                                 delay_method=args.delay))
        fingerprint = {
            "recordings": [t.sha256 for t in takes], "reference": args.reference,
            "max_lag_s": args.max_lag, "delay": args.delay, "tune": args.tune,
        }
        initializer, initargs = warm_up, (tuple(names), rate, True)
    optimiser = Optimiser(
        spaces, objective, None, patience=args.patience, seed=args.seed, restarts=args.restarts,
        ridge=args.ridge, max_sets=args.max_sets, checkpoint=checkpoint, fingerprint=fingerprint,
        progress=None if args.quiet else Progress(sys.stderr),
    )
    if perceptual and not args.quiet:
        optimiser.progress = perceptual_options.distance_progress(optimiser.progress, optimiser)
    if args.resume:
        optimiser.resume(checkpoint)
    optimiser.executor = make_executor(args.workers, args.scheduler, initializer, initargs)
    try:
        if not args.scheduler:
            # Compile the fast loops once here, before the first task starts the worker processes:
            # forked workers inherit them (spawned ones run the initializer).
            initializer(*initargs)
        result = optimiser.run()
    finally:
        optimiser.executor.shutdown(wait=True, cancel_futures=True)
    if perceptual:
        settings = {f"perceptual_{k}": v for k, v in cases.describe().items() if k != "rate"}
        objective_values = {name: raw[0] for name, raw in result.raw.items()}  # audio_distance
    else:
        settings = {"reference": args.reference, "max_lag_s": args.max_lag, "delay": args.delay, "recordings": paths,
                    "recording_sha256": [t.sha256 for t in takes]}
        objective_values = result.objectives
    info = provenance(
        command="studyapp optimise", objective=args.objective, seed=args.seed, patience=args.patience,
        restarts=args.restarts, ridge=args.ridge,
        tune=args.tune, rate=rate, **settings, iterations=result.iterations,
        parameter_sets_evaluated=result.evaluated, seconds=round(result.seconds, 3), resumed=result.resumed,
    )
    params_file.write(
        output, result.params, provenance=info, objective=objective_values,
        comment="Estimator parameters tuned by studyapp optimise (paper Sec. 6.3; our Table 1).\n"
                "Use with: studyapp evaluate RECORDINGS... --params " + output.name,
    )
    checkpoints.write(checkpoint, {**checkpoints.read(checkpoint), "complete": True})
    if not args.quiet:
        print(f"studyapp optimise: wrote {output} ({result.iterations} iterations, "
              f"{result.evaluated} parameter sets, {result.seconds:.1f} s)", file=sys.stderr)
    return 0


def parse_ranges(items):
    """``NAME.PARAM=LOW:HIGH`` items as {NAME: {PARAM: (low, high)}}."""
    from studyapp.errors import UserError
    from studyapp.estimators.registry import spec
    from studyapp.number_text import to_float

    ranges = {}
    for item in items:
        key, _, bounds = item.partition("=")
        name, _, param = key.partition(".")
        low, _, high = bounds.partition(":")
        try:
            pair = (to_float(low), to_float(high))
        except ValueError:
            raise UserError(f"--range {item!r}: expected NAME.PARAM=LOW:HIGH, e.g. FOAW.window=2:128") from None
        if not name or not param:
            raise UserError(f"--range {item!r}: expected NAME.PARAM=LOW:HIGH, e.g. FOAW.window=2:128")
        ranges.setdefault(spec(name).name, {})[param] = pair
    return ranges


def _refuse_an_unfinished_checkpoint(checkpoint):
    """A new run (no ``--resume``) writes over a checkpoint only when it is a finished run's: an interrupted
    run's was overwritten after 30 s (issue 33, item 6)."""
    from studyapp.errors import UserError
    from studyapp.evaluation import checkpoint as checkpoints

    if not checkpoint.exists():
        return
    try:
        state = checkpoints.read(checkpoint)
    except (UserError, OSError):
        raise UserError(f"--checkpoint {checkpoint}: exists and is not a checkpoint of studyapp optimise: "
                        "allowed is another --checkpoint file") from None
    if state.get("complete") is not True:
        raise UserError(f"--checkpoint {checkpoint}: the checkpoint of an interrupted run: allowed is --resume to "
                        "continue it, or to remove it (or another --checkpoint) to start anew")

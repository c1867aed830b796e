"""``studyapp tradeoff [--rates HZ ...] [--tune] -o DIR``: cost against accuracy, at several sample rates.

Simulates short recordings at each rate, evaluates every estimator on them
(re-tuned at that rate with ``--tune``, else with ``--params`` or Table 1),
times each one, and writes ``tradeoff.csv`` and ``tradeoff.json`` (one row per
rate and estimator; the JSON adds the provenance, the estimators not available
at a rate and the tuning runs), ``tradeoff.png/svg`` (cost against the global
objective with the Pareto front, a panel per rate), ``pareto_<RATE>Hz.png/svg``
(per rate: median error against median delay, colour = cost) and
``tradeoff_rates.png/svg`` (error, delay and CPU load against rate). Progress
goes to stderr; the Pareto fronts and the estimators not available go to stdout.
"""

from studyapp.cli import number_options

# A short run: a full default run took 4 min 17 s on 2 shared cores (docs/evaluation.md, 2026-11-22).
DEFAULT_PATIENCE = 20


def register(sub):
    from studyapp.cli import delay_option

    p = sub.add_parser("tradeoff", help="speed/accuracy trade of the estimators at several sample rates")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    p.add_argument("--rates", nargs="+", type=float, metavar="HZ",
                   help="sample rates, 1000 to 96000 (default 5000 10000 20000 40000)")
    p.add_argument("--tune", action="store_true",
                   help="re-tune every estimator at each rate (the optimiser, starting from Table 1)")
    p.add_argument("--patience", type=int, metavar="N",
                   help="with --tune: stop an estimator after N new sets without improvement "
                        f"(default {DEFAULT_PATIENCE})")
    p.add_argument("--workers", type=int, metavar="N",
                   help="with --tune: worker processes (default: all cores; 1: in this process)")
    p.add_argument("--params", metavar="PARAMS.toml", help="tuned parameters (default: Table 1; not with --tune)")
    p.add_argument("--estimators", nargs="+", metavar="NAMES",
                   help="estimators, comma or space separated (default: those in --params, "
                        "else the paper's thirteen)")
    delay_option.add(p)
    p.add_argument("--fmax", nargs="+", type=float, metavar="N",
                   help="F_max of the simulated recordings, one recording each (default 0.5 1.4 2.2 4.4 7.7)")
    p.add_argument("--duration", type=float, default=2.0, metavar="SECONDS",
                   help="length of each simulated recording (default 2 s)")
    p.add_argument("--seed", type=number_options.seed, default=0,
                   help="seed of the first simulated recording and of the tuning (default 0)")
    p.add_argument("--reference", choices=("lvt", "true"), default="lvt", help="reference velocity (default lvt)")
    p.add_argument("--windows", choices=("seconds", "samples"), default="seconds",
                   help="keep window lengths in seconds (scaled with the rate) or in samples (default seconds)")
    p.add_argument("--cost-samples", type=int, default=100_000, metavar="N",
                   help="samples per timing run of the cost benchmark (default 100000)")
    p.set_defaults(func=run)


def run(args):
    import sys
    import time
    from pathlib import Path

    from studyapp.cli import output_paths
    from studyapp.errors import UserError
    from studyapp.estimators.spec import RATE_MAX, validate_rate
    from studyapp.model import calibration
    from studyapp.model.playable import check_playable
    from studyapp.model.simulate import DURATION_MAX
    from studyapp.evaluation.dataset import file_sha256, warm_up
    from studyapp.evaluation.executors import check_workers, make_executor
    from studyapp.evaluation.parameter_sets import parameter_sets
    from studyapp.evaluation.progress import Progress
    from studyapp.evaluation.provenance import provenance
    from studyapp.evaluation.tradeoff import DEFAULT_FMAX, DEFAULT_RATES, check_available, tradeoff

    started = time.monotonic()
    output = Path(args.output)
    output_paths.check_folder(output, inputs=[args.params] if args.params else [])
    if not 0 < args.duration <= DURATION_MAX:
        raise UserError(f"--duration {args.duration:g}: allowed is a number of seconds above 0 and at most "
                        f"{DURATION_MAX:g}")
    rates = [validate_rate(r, "--rates") for r in (args.rates or DEFAULT_RATES)]
    for rate in rates:  # the recordings are simulated: the string must play at each rate
        check_playable(rate, calibration.F0)
    fmax = list(args.fmax or DEFAULT_FMAX)
    for f in fmax:
        if not 0 <= f <= 1000:
            raise UserError(f"--fmax {f:g}: allowed is a number of newtons from 0 to 1000")
    if not 1000 <= args.cost_samples <= 10**8:  # allocated at once for the timing
        raise UserError(f"--cost-samples {args.cost_samples}: allowed is an integer from 1000 to 100000000")
    if args.tune and args.params:
        raise UserError("--params with --tune: allowed is one of them (--tune starts from Table 1 at each rate)")
    for option, value in (("--patience", args.patience), ("--workers", args.workers)):
        if value is not None and not args.tune:
            raise UserError(f"{option} {value}: allowed only with --tune")
        if value is not None and value < 1:
            raise UserError(f"{option} {value}: allowed is an integer of at least 1")
    check_workers(args.workers)
    patience = args.patience or DEFAULT_PATIENCE
    # Validated at the highest rate: a value that can exist at no rate is an error in the file;
    # one that cannot exist at some of the rates makes the estimator not available there.
    params, file_provenance = parameter_sets(args.params, args.estimators, RATE_MAX)
    params_rate = float(file_provenance.get("rate", 5000.0))
    check_available(params, rates, params_rate, args.windows)
    delay = args.delay

    def say(line):
        print(line, file=sys.stderr, flush=True)

    executor = None
    if args.tune:
        # Compiled once here, before the worker processes fork from this one (at the highest rate,
        # where every estimator's defaults exist).
        warm_up(list(params), RATE_MAX, fast=True)
        executor = make_executor(args.workers, None, warm_up, (tuple(params), RATE_MAX, True))
    try:
        trade = tradeoff(
            params, rates=rates, fmax_values=fmax, duration=args.duration, seed=args.seed, reference=args.reference,
            params_rate=params_rate, windows=args.windows,
            cost_samples=args.cost_samples, delay_method=delay, tune_patience=patience if args.tune else None,
            executor=executor, source_name="tuned" if args.tune else "params" if args.params else "table1",
            progress=say,
            tuning_progress=lambda rate: Progress(sys.stderr, prefix=f"tradeoff: {rate:g} Hz: tuning: "),
        )
    finally:
        if executor is not None:
            executor.shutdown(wait=True, cancel_futures=True)
    info = provenance(
        command="studyapp tradeoff", rates=rates, fmax=fmax, duration_s=args.duration, seed=args.seed,
        reference=args.reference, windows=args.windows, cost_samples=args.cost_samples, delay_method=delay,
        parameters="tuned at each rate" if args.tune else args.params or "Table 1",
        **({"params_sha256": file_sha256(args.params)} if args.params else {}),
        tune=bool(args.tune), **({"patience": patience} if args.tune else {}),
        seconds=round(time.monotonic() - started, 1),
    )
    write_outputs(output, trade, info)
    for rate in rates:
        rows = [r for r in trade.rows if r["rate"] == rate and r["available"]]
        front = [r["estimator"] for r in sorted(rows, key=lambda r: r["cost_ns_per_sample"]) if r["pareto"]]
        print(f"{rate:g} Hz: Pareto front of cost and F_g (cheapest first): {', '.join(front) or 'none'}")
        for r in trade.not_available:
            if r["rate"] == rate:
                print(f"{rate:g} Hz: {r['estimator']} not available: {r['reason']}")
    say(f"tradeoff: wrote {output} in {info['seconds']:g} s")
    return 0


def write_outputs(output, trade, info):
    """tradeoff.csv, tradeoff.json and the figures, into ``output``."""
    import json
    import math

    from studyapp.io.atomic import atomic_open
    from studyapp.evaluation import figures
    from studyapp.evaluation.tables import write_csv
    from studyapp.evaluation.tradeoff import COLUMNS

    def plain(value):
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, dict):
            return {k: plain(v) for k, v in value.items()}
        return value

    output.mkdir(parents=True, exist_ok=True)
    csv_rows = [{**r, "parameters": " ".join(f"{k}={v}" for k, v in r.get("parameters", {}).items())}
                for r in trade.rows]
    write_csv(output / "tradeoff.csv", csv_rows, COLUMNS)
    document = {
        "provenance": info,
        "rows": [plain(r) for r in trade.rows],
        "not_available": trade.not_available,
        "tuning": {f"{rate:g}": run for rate, run in trade.tuning.items()},
    }
    with atomic_open(output / "tradeoff.json", "w", encoding="utf-8") as f:
        json.dump(document, f, indent=2)
        f.write("\n")
    figures.written(figures.tradeoff_figure(trade.rows), output / "tradeoff")
    for rate in sorted({r["rate"] for r in trade.rows}):
        figures.written(figures.pareto_figure(trade.rows, rate), output / f"pareto_{rate:g}Hz")
    figures.written(figures.rate_figure(trade.rows), output / "tradeoff_rates")

"""``studyapp tradeoff [--rates HZ ...] -o DIR``: cost against accuracy, at several sample rates.

Simulates short recordings at each rate, evaluates every estimator on them,
times each one, and writes ``tradeoff.csv`` (one row per rate and estimator),
``tradeoff.png/svg`` (cost against global objective with the Pareto front, a
panel per rate) and ``tradeoff_rates.png/svg`` (error, delay and CPU load
against rate).
"""


def register(sub):
    p = sub.add_parser("tradeoff", help="speed/accuracy trade of the estimators at several sample rates")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    p.add_argument("--rates", nargs="+", type=float, metavar="HZ",
                   help="sample rates (default 5000 10000 20000 40000)")
    p.add_argument("--params", metavar="PARAMS.toml", help="tuned parameters (default: Table 1)")
    p.add_argument("--estimators", nargs="+", metavar="NAMES",
                   help="estimators (default: those in --params, else the paper's thirteen)")
    p.add_argument("--fmax", nargs="+", type=float, metavar="N",
                   help="F_max of the simulated recordings, one recording each (default 0.5 1.4 2.2 4.4 7.7)")
    p.add_argument("--duration", type=float, default=2.0, metavar="SECONDS",
                   help="length of each simulated recording (default 2 s)")
    p.add_argument("--seed", type=int, default=0, help="seed of the first simulated recording (default 0)")
    p.add_argument("--reference", choices=("lvt", "true"), default="lvt", help="reference velocity (default lvt)")
    p.add_argument("--windows", choices=("seconds", "samples"), default="seconds",
                   help="keep window lengths in seconds (scaled with the rate) or in samples (default seconds)")
    p.add_argument("--cost-samples", type=int, default=100_000, metavar="N",
                   help="samples per timing run of the cost benchmark (default 100000)")
    p.set_defaults(func=run)


def run(args):
    import sys
    from pathlib import Path

    from studyapp.errors import UserError
    from studyapp.estimators.spec import validate_rate
    from studyapp.evaluation import figures
    from studyapp.evaluation.parameter_sets import parameter_sets
    from studyapp.evaluation.tables import write_csv
    from studyapp.evaluation.tradeoff import COLUMNS, DEFAULT_FMAX, DEFAULT_RATES, tradeoff

    output = Path(args.output)
    if output.exists() and not output.is_dir():
        raise UserError(f"-o {output}: exists and is not a directory")
    rates = [validate_rate(r) for r in (args.rates or DEFAULT_RATES)]
    fmax = list(args.fmax or DEFAULT_FMAX)
    for f in fmax:
        if not 0 <= f <= 1000:
            raise UserError(f"--fmax {f:g}: allowed is a number of newtons from 0 to 1000")
    if args.cost_samples < 1000:
        raise UserError(f"--cost-samples {args.cost_samples}: allowed is an integer of at least 1000")
    params, provenance = parameter_sets(args.params, args.estimators, max(rates))
    rows = tradeoff(
        params, rates=rates, fmax_values=fmax, duration=args.duration, seed=args.seed, reference=args.reference,
        params_rate=float(provenance.get("rate", 5000.0)), windows=args.windows, cost_samples=args.cost_samples,
        progress=lambda line: print(line, file=sys.stderr),
    )
    output.mkdir(parents=True, exist_ok=True)
    write_csv(output / "tradeoff.csv", rows, COLUMNS)
    figures.tradeoff_plot(rows, output / "tradeoff")
    figures.rate_plot(rows, output / "tradeoff_rates")
    for rate in rates:
        front = [r["estimator"] for r in sorted(rows, key=lambda r: r["cost_ns_per_sample"])
                 if r["rate"] == rate and r["pareto"]]
        print(f"{rate:g} Hz: Pareto front (cheapest first): {', '.join(front)}")
    return 0


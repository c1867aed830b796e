"""``studyapp estimate INPUT --estimator NAME --rate HZ [--set key=value ...] [-o OUTPUT.csv]``.

INPUT is a CSV with a ``position`` column and optionally ``acceleration`` and
``velocity`` (SI units, one row per sample), or a recording (``.npz``/``.h5``/
``.csv`` from ``studyapp simulate``, whose tachometer column is
``velocity_lvt``). OUTPUT is the input plus a ``velocity_estimate`` column.
"""


def register(sub):
    parser = sub.add_parser("estimate", help="apply one estimator to a file of samples")
    parser.add_argument("input", metavar="INPUT", help="CSV with a position column, or a recording (.npz/.h5)")
    parser.add_argument("--estimator", required=True, metavar="NAME", help="estimator name (see 'studyapp estimators')")
    parser.add_argument("--rate", required=True, type=str, metavar="HZ", help="sample rate in Hz")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a parameter")
    parser.add_argument("-o", "--output", metavar="OUTPUT.csv", help="output file (default: stdout)")
    parser.set_defaults(func=run)


def parse_settings(items):
    from studyapp.errors import ParameterError

    params = {}
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise ParameterError(f"--set {item!r}: expected KEY=VALUE, e.g. --set cutoff_hz=300")
        params[key.strip()] = value.strip()
    return params


def _columns(path, reads):
    """Header, rows of cell text, and float columns for position/acceleration/velocity."""
    from pathlib import Path

    from studyapp import sample_table
    from studyapp.errors import InputDataError

    suffix = Path(path).suffix.lower()
    if suffix in (".npz", ".h5", ".hdf5"):
        from studyapp import recording

        rec = recording.load(path)
        header = list(rec.columns)
        n = len(rec.columns["position"])
        rows = [[repr(float(rec.columns[h][i])) for h in header] for i in range(n)]
        cols = {"position": rec.columns["position"], "acceleration": rec.columns.get("acceleration"),
                "velocity": rec.columns.get("velocity", rec.columns.get("velocity_lvt"))}
        return header, rows, cols
    table = sample_table.read_csv(path)
    velocity_name = "velocity" if "velocity" in table.header else "velocity_lvt"
    names = {"position": "position", "acceleration": "acceleration", "velocity": velocity_name}
    cols = {}
    for key, name in names.items():
        if name in table.header:
            cols[key] = table.column(name)
        elif key in reads:
            raise InputDataError(f"{path}: column {name!r} missing; this estimator reads {', '.join(reads)}")
        else:
            cols[key] = None
    return table.header, table.rows, cols


def run(args):
    import sys

    from studyapp import estimators
    from studyapp.atomic import atomic_open
    from studyapp.sample_table import write_csv

    est = estimators.create(args.estimator, args.rate, **parse_settings(args.set))
    header, rows, cols = _columns(args.input, est.spec.inputs)
    estimate = est.process(cols["position"], cols["acceleration"], cols["velocity"])
    if args.output:
        with atomic_open(args.output, "w", newline="") as f:
            write_csv(f, header, rows, "velocity_estimate", estimate)
    else:
        write_csv(sys.stdout, header, rows, "velocity_estimate", estimate)
    if est.bad_samples:
        print(f"note: {est.bad_samples} bad input samples (NaN, inf or beyond the physical bounds) "
              "were replaced by the last good one", file=sys.stderr)
    return 0

"""``studyapp estimate INPUT --estimator NAME [--rate HZ] [--set key=value ...] [--block N] [-o OUTPUT.csv]``.

INPUT is a CSV with a ``position`` column and optionally ``acceleration`` and
``velocity`` (SI units, one row per sample; ``--rate`` is then required), or a
recording (``.npz``/``.h5`` from ``studyapp simulate``, whose tachometer
column is ``velocity_lvt``), which carries its own rate: ``--rate`` may be
left out, and a different one is refused. OUTPUT is the input plus a
``velocity_estimate`` column.

The input is read, estimated and written ``--block`` samples at a time
(``sample_table``, ``recording_blocks``): the estimators keep their state
across blocks, so the output equals one pass over the whole input exactly,
and memory stays that of one block. OUTPUT is written atomically (a failure
leaves no partial file); to stdout, lines already written before a bad cell
further down stay written.
"""

DEFAULT_BLOCK = 1 << 16  # samples: about 5 MB of a 9-column recording as text
BLOCK_MAX = 1 << 24  # samples: ~1.3 GB of such text; a larger --block is a typo, not a wish


def register(sub):
    parser = sub.add_parser("estimate", help="apply one estimator to a file of samples")
    parser.add_argument("input", metavar="INPUT", help="CSV with a position column, or a recording (.npz/.h5)")
    parser.add_argument("--estimator", required=True, metavar="NAME", help="estimator name (see 'studyapp estimators')")
    parser.add_argument("--rate", type=str, metavar="HZ",
                        help="sample rate in Hz (required for a CSV; a recording's own rate otherwise)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="override a parameter")
    parser.add_argument("--block", type=int, default=DEFAULT_BLOCK, metavar="N",
                        help=f"samples read and written at a time (default {DEFAULT_BLOCK})")
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


def _recording_rate(path, recorded, given):
    """The recording's rate; ``--rate``, if given, must agree with it."""
    import math

    from studyapp.errors import ParameterError

    if given is None:
        return recorded
    from studyapp.number_text import to_float

    try:
        value = to_float(given)
    except ValueError:
        value = math.nan
    if not math.isclose(value, recorded, rel_tol=1e-6):
        raise ParameterError(f"--rate {given}: {path} was recorded at {recorded:g} Hz: allowed is to leave out "
                             f"--rate or give {recorded:g}")
    return recorded


class _Input:
    """The input file as blocks of (header cells, float columns by estimator input)."""

    def __init__(self, path, rate):
        from pathlib import Path

        from studyapp.io import recording_blocks, sample_table
        from studyapp.errors import ParameterError
        from studyapp.estimators.spec import validate_rate

        self.path = path
        if Path(path).suffix.lower() in recording_blocks.SUFFIXES:
            self.source = recording_blocks.RecordingBlocks(path)
            validate_rate(self.source.rate, f"{path}: sample rate (metadata 'rate' or the 't' column)")
            self.rate = _recording_rate(path, self.source.rate, rate)
            self.header = list(self.source.names)
            self.is_table = False
        else:
            if rate is None:
                raise ParameterError(f"--rate: required for {path} (a CSV carries no sample rate): allowed is "
                                     "a number of Hz from 1000 to 96000")
            self.rate = validate_rate(rate, "--rate")
            self.source = sample_table.SampleTable(path)
            self.header = self.source.header
            self.is_table = True
        velocity = "velocity" if "velocity" in self.header else "velocity_lvt"
        self.columns = {"position": "position", "acceleration": "acceleration", "velocity": velocity}

    def check(self, reads):
        from studyapp.errors import InputDataError

        for key in ("position", *reads):
            name = self.columns[key]
            if name not in self.header:
                raise InputDataError(f"{self.path}: column {name!r} missing; this estimator reads {', '.join(reads)}")

    def blocks(self, size):
        """Yield (rows, {position, acceleration, velocity}: array or None) per block."""
        present = [name for name in self.columns.values() if name in self.header]
        if self.is_table:
            for rows, cols in self.source.blocks(size, present):
                yield rows, {k: cols.get(name) for k, name in self.columns.items()}
            return
        for cols in self.source.blocks(size):
            rows = list(zip(*(cols[name].tolist() for name in self.header)))
            yield rows, {k: cols.get(name) for k, name in self.columns.items()}

    def close(self):
        self.source.close()


class _StartWatch:
    """A note when an observer started at x = 0 (``start = 'zero'``) meets an input that starts far from 0.

    The Levant differentiator (paper eqs. 10-12) and the filters built on it
    start their position estimate at 0 unless ``start = 'first'``: on a handle
    resting at a travel's end (11 mm) LEVANT's first estimates spike to about
    0.57 m/s while the observer catches up. That is the paper's observer doing
    what it does, so it is kept, and said.
    """

    FAR = 1e-3  # m from 0 at the first sample
    SPAN = 0.1  # s: the spike's window

    def __init__(self, est):
        self.watch = est.params.get("start") == "zero"
        self.first = None
        self.peak = 0.0
        self.seen = 0
        self.window = int(self.SPAN * est.rate)

    def see(self, position, estimate):
        import numpy as np

        if not self.watch or self.seen >= self.window or len(position) == 0:
            return
        if self.first is None:
            self.first = float(position[0])
        part = estimate[: self.window - self.seen]
        finite = part[np.isfinite(part)]
        if finite.size:
            self.peak = max(self.peak, float(np.abs(finite).max()))
        self.seen += part.size

    def note(self, name):
        import sys

        if self.watch and self.first is not None and abs(self.first) > self.FAR:
            print(f"note: {name} starts its observer at position 0 (start = 'zero', the paper's eqs. 10-12) and the "
                  f"input starts at {1e3 * self.first:.3g} mm: its first {self.SPAN:g} s reach "
                  f"{self.peak:.3g} m/s while it catches up; --set start=first starts it at the first sample",
                  file=sys.stderr)


def run(args):
    import contextlib
    import sys

    from studyapp import estimators
    from studyapp.io.atomic import atomic_open
    from studyapp.cli import output_paths
    from studyapp.errors import ParameterError
    from studyapp.io.sample_table import write_header, write_rows

    if not 1 <= args.block <= BLOCK_MAX:  # a block's rows are held in memory at once
        raise ParameterError(f"--block {args.block}: allowed is an integer from 1 to {BLOCK_MAX}")
    settings = parse_settings(args.set)
    if args.output:
        output_paths.check_file(args.output, inputs=[args.input])
    source = _Input(args.input, args.rate)
    with contextlib.closing(source):
        est = estimators.create(args.estimator, source.rate, **settings)
        source.check(est.spec.inputs)
        with (atomic_open(args.output, "w", newline="") if args.output else contextlib.nullcontext(sys.stdout)) as f:
            write_header(f, source.header, "velocity_estimate")
            start = _StartWatch(est)
            for rows, cols in source.blocks(args.block):
                estimate = est.process(cols["position"], cols["acceleration"], cols["velocity"])
                start.see(cols["position"], estimate)
                write_rows(f, rows, estimate)
    start.note(args.estimator)
    if est.bad_samples:
        print(f"note: {est.bad_samples} bad input samples (NaN, inf or beyond the physical bounds) "
              "were replaced by the last good one", file=sys.stderr)
    return 0

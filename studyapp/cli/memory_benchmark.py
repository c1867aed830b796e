"""``studyapp bench memory``: peak memory of ``studyapp estimate`` (issue 14, item 8) or ``simulate`` (issue 30, item 4).

``--command estimate`` (the default; ``--rows N --block N``) writes a CSV of
``--rows`` samples (position, acceleration, velocity) and a recording ``.npz``
of as many samples (the nine columns of ``studyapp simulate``) into a
temporary folder, runs ``studyapp estimate --estimator KALLEV`` on each in a
child process, and reports the child's peak resident memory beside the input
file's size. The target: at most twice the input and at most 500 MB for a CSV
of 10^7 rows.

``--command simulate`` (``--rate HZ --duration S [S ...] --format npz|h5|csv``)
runs ``studyapp simulate`` for each duration into the temporary folder and
reports its peak beside the output's size: flat in the duration, and under
200 MB at 96 kHz for 600 s (the target).

The peak is the child's own ``VmHWM`` (/proc/self/status, the kernel's high
water mark of its resident memory since it started the interpreter), which
the child prints as it exits. Not ``ru_maxrss`` from ``os.wait4``: CPython
starts children with vfork, and Linux counts the parent's peak in the child's
``ru_maxrss`` (a ``python -c pass`` started by a process of 400 MB reads
427 MB), so a child of a large process (a test run) read its parent's peak.
Measured here; tests assert only bounds that hold with room.
"""

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from studyapp.cli.estimate import BLOCK_MAX
from studyapp.errors import ParameterError, UserError

ROWS_MAX = 10**9  # samples per input: ~70 GB of CSV, the most a disk here is asked to hold

COLUMNS = ("t", "position", "velocity_lvt", "acceleration", "velocity_true", "acceleration_true", "force",
           "string_velocity", "audio")
WRITE_BLOCK = 1 << 18


def _signal(start, n, rate):
    """A smooth stroke with a 110 Hz ripple: values of every column (not physics, just realistic digits)."""
    t = (start + np.arange(n)) / rate
    x = 0.01 * np.sin(2 * np.pi * 0.5 * t) + 1e-5 * np.sin(2 * np.pi * 110 * t)
    v = np.gradient(x, 1 / rate) if n > 1 else np.zeros(n)
    return {"t": t, "position": x, "velocity_lvt": v, "acceleration": -x * 40.0, "velocity_true": v,
            "acceleration_true": -x * 40.0, "force": 0.5 * np.tanh(v), "string_velocity": v, "audio": np.sin(t)}


def write_csv(path, rows, rate):
    with open(path, "w") as f:
        f.write("position,acceleration,velocity\n")
        for start in range(0, rows, WRITE_BLOCK):
            s = _signal(start, min(WRITE_BLOCK, rows - start), rate)
            np.savetxt(f, np.column_stack([s["position"], s["acceleration"], s["velocity_lvt"]]), fmt="%.17g",
                       delimiter=",")


def write_npz(path, rows, rate):
    """An uncompressed .npz like ``recording.save`` writes, built a block at a time (np.savez would need it all)."""
    import zipfile

    from numpy.lib import format as npy

    meta = json.dumps({"rate": rate, "format": 1, "source": "bench memory"})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
        with z.open("__meta__.npy", "w") as f:
            npy.write_array(f, np.array(meta))
        for name in COLUMNS:
            with z.open(f"{name}.npy", "w", force_zip64=True) as f:
                npy.write_array_header_1_0(f, {"descr": "<f8", "fortran_order": False, "shape": (rows,)})
                for start in range(0, rows, WRITE_BLOCK):
                    f.write(_signal(start, min(WRITE_BLOCK, rows - start), rate)[name].astype("<f8").tobytes())


# ``python -m studyapp ARGV``, then its own peak as the last line of its stderr
_CHILD = """import runpy, sys
sys.argv = ["studyapp", *sys.argv[1:]]
try:
    runpy.run_module("studyapp", run_name="__main__", alter_sys=True)
finally:
    with open("/proc/self/status") as status:
        print(next(line for line in status if line.startswith("VmHWM:")).strip(), file=sys.stderr)
"""


def peak_rss(argv):
    """(peak resident bytes, seconds) of ``studyapp ARGV`` run in a child; ``UserError`` with its last line if it fails."""
    started = time.monotonic()
    # its stderr goes to a file, not a pipe: simulate's progress line would fill a pipe no one reads until the end
    with tempfile.TemporaryFile() as err:
        code = subprocess.run([sys.executable, "-c", _CHILD, *argv], stdout=subprocess.DEVNULL, stderr=err).returncode
        seconds = time.monotonic() - started
        err.seek(0)
        lines = err.read().decode(errors="replace").replace("\r", "\n").strip().splitlines()
    if code != 0 or not lines or not lines[-1].startswith("VmHWM:"):
        message = [line for line in lines if not line.startswith("VmHWM:")]
        raise UserError(f"studyapp {argv[0]} failed ({code}): {message[-1] if message else 'no message'}")
    return int(lines[-1].split()[1]) * 1024, seconds  # kB in /proc


def measure(input_path, output_path, block, rate):
    argv = ["estimate", str(input_path), "--estimator", "KALLEV", "--block", str(block), "-o", str(output_path)]
    if Path(input_path).suffix == ".csv":
        argv += ["--rate", f"{rate:g}"]
    peak, seconds = peak_rss(argv)
    size = Path(input_path).stat().st_size
    return {"input": Path(input_path).suffix[1:], "input_bytes": size, "peak_rss_bytes": peak,
            "peak_over_input": round(peak / size, 3), "seconds": round(seconds, 2)}


def measure_simulate(output_path, rate, duration):
    """The peak of ``studyapp simulate --rate RATE --duration DURATION -o OUTPUT`` and the output's size."""
    peak, seconds = peak_rss(["simulate", "--rate", f"{rate:g}", "--duration", f"{duration:g}", "-o", str(output_path)])
    return {"duration": duration, "output_bytes": Path(output_path).stat().st_size, "peak_rss_bytes": peak,
            "seconds": round(seconds, 2)}


def _check_dir(args):
    if args.dir is not None:  # it writes and deletes there: never in a session folder (issue 33, item 6)
        from studyapp.cli import output_paths

        if not Path(args.dir).is_dir():
            raise UserError(f"--dir {args.dir}: no such folder: allowed is an existing folder")
        output_paths.check_folder(args.dir, "--dir")


def run_simulate(args):
    from studyapp.estimators.spec import validate_rate
    from studyapp.model.simulate import DURATION_MAX

    rate = validate_rate(args.rate, "--rate")
    for d in args.duration:
        if not 0 < d <= DURATION_MAX:
            raise ParameterError(f"--duration {d:g}: allowed is a number of seconds above 0 and at most "
                                 f"{DURATION_MAX:g}")
    _check_dir(args)
    results = []
    with tempfile.TemporaryDirectory(prefix="studyapp-bench-memory-", dir=args.dir) as folder:
        output = Path(folder) / f"output.{args.format}"
        for duration in args.duration:
            if not args.json:
                print(f"bench memory: simulate {duration:g} s at {rate:g} Hz", file=sys.stderr, flush=True)
            results.append(measure_simulate(output, rate, duration))
            output.unlink()
    if args.json:
        print(json.dumps({"command": "simulate", "rate": rate, "format": args.format, "results": results}))
        return 0
    print(f"studyapp simulate --rate {rate:g} -o output.{args.format} (source LVT, F_max 1 N)")
    print(f"{'duration s':>10}{'output MB':>11}{'peak RSS MB':>13}{'seconds':>9}")
    for r in results:
        print(f"{r['duration']:>10g}{r['output_bytes'] / 1e6:>11.1f}{r['peak_rss_bytes'] / 1e6:>13.1f}"
              f"{r['seconds']:>9.1f}")
    return 0


def run_cli(args):
    if args.command == "simulate":
        return run_simulate(args)
    if not 1 <= args.rows <= ROWS_MAX:  # the inputs are written to disk first
        raise ParameterError(f"--rows {args.rows}: allowed is an integer from 1 to {ROWS_MAX}")
    if not 1 <= args.block <= BLOCK_MAX:
        raise ParameterError(f"--block {args.block}: allowed is an integer from 1 to {BLOCK_MAX}")
    _check_dir(args)
    rate = 5000.0
    results = []
    with tempfile.TemporaryDirectory(prefix="studyapp-bench-memory-", dir=args.dir) as folder:
        for suffix, write in ((".csv", write_csv), (".npz", write_npz)):
            path = Path(folder) / f"input{suffix}"
            if not args.json:
                print(f"bench memory: writing {args.rows} rows to {path.name}", file=sys.stderr, flush=True)
            write(path, args.rows, rate)
            results.append(measure(path, Path(folder) / "output.csv", args.block, rate))
            path.unlink()
            (Path(folder) / "output.csv").unlink()
    if args.json:
        print(json.dumps({"command": "estimate", "rows": args.rows, "block": args.block, "results": results}))
        return 0
    print(f"studyapp estimate --estimator KALLEV, {args.rows} rows, --block {args.block}")
    print(f"{'input':<6}{'input MB':>10}{'peak RSS MB':>13}{'peak/input':>12}{'seconds':>9}")
    for r in results:
        print(f"{r['input']:<6}{r['input_bytes'] / 1e6:>10.1f}{r['peak_rss_bytes'] / 1e6:>13.1f}"
              f"{r['peak_over_input']:>12.2f}{r['seconds']:>9.1f}")
    return 0

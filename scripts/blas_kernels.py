"""The model's numbers under every OpenBLAS kernel: are they the same bits? (issue 39, item 1)

OpenBLAS picks its kernels by CPU; ``OPENBLAS_CORETYPE`` forces a kernel set.
For each value given (default: Haswell SkylakeX Sandybridge Nehalem Prescott)
this script runs itself in a child process with the variable set (and only
there) and has it compute, on the model's path:

- the loop's hash cases: the 3 cases x 2 links of
  tests/model/test_model_link_device.py (every output column, 5 kHz, 4000
  samples in blocks of 1000, 37, 1963, 1000);
- the parameter builds: the device's ZOH discretisation (1-96 kHz), LEASTSQ's
  taps at the corners of its range, every estimator's parameters as a loop at
  5 and 48 kHz builds them (Table 1 made for the rate);
- one breakdown of LVT and of TRUE (``studyapp breakdown --source S --seeds 1
  --json``, seed 0, 5 kHz);
- the optimiser's ridge axis on random elites (d = 1..6), a short optimiser run
  with ridge draws and ``evaluate`` on two short simulated recordings;
- the simulated participant's noise measure (experiment/noisiness.py).

Each item is a sha256 of its bits (floats as IEEE doubles). It prints one
Markdown table: an item per row, a kernel per column; a row is "equal" when
every kernel that ran gave the same digest. A kernel the CPU cannot run (the
child dies of SIGILL, e.g. SkylakeX without AVX-512) is reported as "not
supported by this CPU", not as a difference. Progress goes to stderr.

    python scripts/blas_kernels.py [CORETYPE ...]
"""

import argparse
import contextlib
import hashlib
import io
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ("Haswell", "SkylakeX", "Sandybridge", "Nehalem", "Prescott")


def digest(value):
    """sha256 (16 hex digits) of an array, a number, a string or a nested list/tuple/dict of them."""
    import numpy as np

    h = hashlib.sha256()

    def feed(v):
        if isinstance(v, dict):
            for k in sorted(v):
                h.update(str(k).encode())
                feed(v[k])
        elif isinstance(v, (list, tuple)):
            h.update(b"[")
            for x in v:
                feed(x)
            h.update(b"]")
        elif isinstance(v, str):
            h.update(v.encode())
        elif v is None:
            h.update(b"None")
        else:
            h.update(np.ascontiguousarray(np.asarray(v, dtype=np.float64)).tobytes())

    feed(value)
    return h.hexdigest()[:16]


def _cli(args):
    from studyapp.cli import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main(args)
    if code != 0:
        raise RuntimeError(f"studyapp {' '.join(args)}: exit {code}")
    return out.getvalue()


def _loop_cases():
    import numpy as np

    from studyapp.model.link import LinkSpec
    from studyapp.model.loop import OUTPUTS, ClosedLoop, LoopConfig

    sys.path.insert(0, str(ROOT / "tests" / "model"))
    from test_model_link_device import BLOCKS, CASES, RATE

    for case, settings in CASES.items():
        for link in (None, LinkSpec()):
            loop = ClosedLoop(LoopConfig(rate=RATE, audio=True, link=link, **settings))
            parts = [loop.run(n) for n in BLOCKS]
            columns = {k: np.concatenate([p[k] for p in parts], axis=-1) for k in list(OUTPUTS) + ["estimates"]}
            yield f"loop `{case}`, link {'default' if link else 'none'} (all columns)", digest(columns)


def _builds():
    import numpy as np

    from studyapp.estimators import leastsq
    from studyapp.estimators.at_rate import table1
    from studyapp.estimators.registry import SPECS
    from studyapp.evaluation import principal_axis
    from studyapp.model import calibration as cal
    from studyapp.model.loop import ClosedLoop, LoopConfig
    from studyapp.model.simulated_device import discretise

    yield "device discretisation, 1-96 kHz", digest(
        [discretise(cal.DEVICE_MASS, cal.HAND_MASS, cal.GRIP_STIFFNESS, cal.GRIP_DAMPING, 1.0 / r)
         for r in (1000.0, 5000.0, 44100.0, 48000.0, 96000.0)])
    yield "LEASTSQ taps, orders 1-6, windows to 512", digest(
        [leastsq.taps(o, w, r) for o in range(1, 7) for w in (o + 1, 33, 257, 512) for r in (5000.0, 96000.0)])
    for rate in (5000.0, 48000.0):
        loop = ClosedLoop(LoopConfig(rate=rate, estimators={n: table1(n, rate, "seconds") for n in SPECS},
                                     source="LVT", fmax=5.0, audio=True))
        yield f"every estimator's parameters and the loop's arrays, {rate / 1000:g} kHz", digest(
            [list(loop.control.arrays), loop.device._dp, loop.device._hp, loop.device._snp])
    rng = np.random.default_rng(0)
    yield "ridge axis of random elites, d = 1-6", digest(
        [principal_axis.principal_axis(rng.random((12, d))) for d in range(1, 7)])


def _noisiness():
    from studyapp.experiment.noisiness import velocity_noise
    from studyapp.model.loop import ClosedLoop, LoopConfig

    block = ClosedLoop(LoopConfig(rate=5000.0, estimators={"LEASTSQ": {}}, source="LEASTSQ", fmax=3.0)).run(5000)
    yield "simulated participant's noise measure", digest(
        velocity_noise(block["source_velocity"], block["velocity_true"], 5000.0))


def _breakdowns():
    for source in ("LVT", "TRUE"):
        doc = json.loads(_cli(["breakdown", "--source", source, "--seeds", "1", "--json"]))
        yield f"`breakdown --source {source} --seeds 1` F_max (N)", f"{doc['fmax_median']:.17g}"


def _optimise_and_evaluate():
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        for fmax, seed in ((2.0, 1), (6.0, 2)):
            _cli(["simulate", "--fmax", str(fmax), "--duration", "1.5", "--seed", str(seed), "-o",
                  str(folder / f"rec_{seed}.npz")])
        params = folder / "params.toml"
        _cli(["optimise", str(folder / "rec_1.npz"), str(folder / "rec_2.npz"), "-o", str(params), "--estimators",
              "LEASTSQ,KALMAN", "--patience", "40", "--max-sets", "80", "--ridge", "0.5", "--quiet"])
        tables = tomllib.loads(params.read_text())
        yield "`optimise` LEASTSQ,KALMAN (80 sets, ridge draws): params.toml", digest(
            {k: repr(v) for k, v in tables.items() if k != "provenance"})
        doc = json.loads(_cli(["evaluate", str(folder / "rec_1.npz"), str(folder / "rec_2.npz"), "--params",
                               str(params), "--json"]))
        kept = json.dumps({k: v for k, v in doc.items() if k not in ("provenance", "created")}, sort_keys=True)
        yield "`evaluate` with those params (JSON; provenance, creation time, folder left out)", digest(
            kept.replace(str(folder), "FOLDER"))


PARTS = (_builds, _loop_cases, _noisiness, _breakdowns, _optimise_and_evaluate)


def child():
    """Compute every item here (under this process's OPENBLAS_CORETYPE) and print them as JSON."""
    items = {}
    for part in PARTS:
        for name, value in part():
            items[name] = value
            print(f"  {os.environ.get('OPENBLAS_CORETYPE', 'default')}: {name}", file=sys.stderr, flush=True)
    json.dump(items, sys.stdout)


def run_kernel(coretype):
    """(items or None, note): the child's items under ``coretype``; None with the reason when it did not run."""
    env = dict(os.environ, OPENBLAS_CORETYPE=coretype, PYTHONPATH=str(ROOT))
    proc = subprocess.run([sys.executable, __file__, "--child"], env=env, stdout=subprocess.PIPE, text=True,
                          cwd=ROOT)
    if proc.returncode == -signal.SIGILL:
        return None, "not supported by this CPU (illegal instruction)"
    if proc.returncode != 0:
        return None, f"failed (exit {proc.returncode})"
    return json.loads(proc.stdout), "ran"


def table(results):
    """The Markdown table of ``results``: {coretype: (items or None, note)}."""
    ran = [c for c, (items, _) in results.items() if items is not None]
    lines = ["| item | " + " | ".join(results) + " | verdict |", "|---|" + "---|" * len(results) + "---|"]
    names = list(results[ran[0]][0]) if ran else []
    for name in names:
        values = [results[c][0][name] for c in ran]
        cells = [f"`{results[c][0][name]}`" if results[c][0] is not None else "-" for c in results]
        verdict = "equal" if len(set(values)) == 1 else "**differ**"
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {verdict} |")
    notes = [f"- {c}: {note}" for c, (items, note) in results.items() if items is None]
    return "\n".join(lines + ([""] + notes if notes else []))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("coretypes", nargs="*", default=list(DEFAULT), metavar="CORETYPE")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child()
        return 0
    results = {}
    for coretype in args.coretypes:
        start = time.monotonic()
        print(f"OPENBLAS_CORETYPE={coretype} ...", file=sys.stderr, flush=True)
        results[coretype] = run_kernel(coretype)
        print(f"OPENBLAS_CORETYPE={coretype}: {results[coretype][1]} ({time.monotonic() - start:.0f} s)",
              file=sys.stderr, flush=True)
    print(table(results))
    ran = [items for items, _ in results.values() if items is not None]
    return 0 if ran and all(items == ran[0] for items in ran) else 1


if __name__ == "__main__":
    sys.exit(main())

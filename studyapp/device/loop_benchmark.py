"""What the loop costs in C and in numba: ``studyapp bench loop --core c,numba [--rate HZ] [--json]``.

Both cores run on the same recorded sensor stream (the simulated device
bowed on the strokes with the LVT at F_max 1 N, ``SECONDS`` at the rate but
at least ``SAMPLES_MIN`` samples, accelerometer on), from identical arrays built once by the host
(``ClosedLoop``: the bank of every position/acceleration estimator the rate
allows, all but LVT: fourteen from 4.6 kHz up, COMP2's Table 1 high-pass
needing that; the LVT sensor in the loop). Two figures per core, in ns per
sample:

- loop: one sample of the controller (sensors, source, string, force, motor
  limits, fault latch) and every estimator of the bank on it. C: sl_run
  (device/c_loop.py); numba: control.run_sensors, control.sample per sample
  then observe_others, which also advances the stability monitor (the C
  leaves the monitor to the host) and writes the audio row (switched off
  here: no body filter, no contact microphone);
- bank: the estimators alone over the stream, each in turn: C se_run
  (device/c_estimators.py), numba dispatch.run_bank (what ``Bank.process``
  calls).

Each figure is the median over ``REPEATS`` runs of the whole stream in one
call (so no per-call overhead is counted: a firmware's per-sample cost), in
the process's CPU time (on a shared machine wall time would count other
processes too), the cores taking turns within each repeat. The first repeat's
outputs of the two loops are compared bit for bit and the answer printed.
``bench estimators``'s bank figure (Python calls on blocks of 256) includes
its calls' overhead; this one does not.
"""

import json
import statistics
import sys
import time

import numpy as np

from studyapp.device import c_core
from studyapp.errors import ParameterError
from studyapp.estimators import lvt, names
from studyapp.estimators.dispatch import run_bank
from studyapp.estimators.registry import spec
from studyapp.estimators.spec import validate_rate
from studyapp.model import calibration, control
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.playable import check_playable
from studyapp.model.sources import LVT_SENSOR

CORES = ("c", "numba")
SECONDS = 1.0
SAMPLES_MIN = 100_000  # per run: at low rates a second is too short to time
REPEATS = 7


def parse_cores(values):
    """``--core`` values (each "c", "numba" or a comma list; repeatable) -> the cores in CORES's order."""
    chosen = set()
    for value in values or ():
        for core in value.split(","):
            if core.strip() not in CORES:
                raise ParameterError(f"--core {value!r}: allowed are {', '.join(CORES)} or c,numba")
            chosen.add(core.strip())
    return [core for core in CORES if core in chosen]


def bank_names(rate):
    return [name for name in names() if name != lvt.NAME and spec(name).not_available(rate) is None]


def _loop(rate, bank, seed=0):
    return ClosedLoop(LoopConfig(rate=rate, estimators={name: {} for name in bank}, source=LVT_SENSOR, fmax=1.0,
                                 seed=seed, audio=False, accelerometer=True), judge=False)


def stream(rate, n):
    """n sensor samples (x, a, v) of the simulated device bowed on the strokes."""
    out = _loop(rate, []).run(n)
    return tuple(np.ascontiguousarray(out[k]) for k in ("position", "acceleration", "velocity_lvt"))


class _Numba:
    def __init__(self, rate, bank, n):
        self.loop = _loop(rate, bank)
        self.out = np.zeros((len(control.OUTPUTS), n))
        self.est = np.zeros((len(bank), n))

    def run_loop(self, x, a, v):
        control.run_sensors(self.loop.control.arrays, x, a, v, self.out, self.est)
        return self.out[control.O_FORCE], self.est

    def run_bank(self, bank, x, a, v):
        run_bank(bank.kinds, bank.states, bank.params, x, a, v, self.est)


class _C:
    def __init__(self, rate, bank, n):
        from studyapp.device import c_estimators, c_loop

        self.loop = _loop(rate, bank)
        self.c = c_loop.CLoop(self.loop.control.arrays)
        self.out = np.zeros((len(c_loop.OUT_ROWS), n))
        self.est = np.zeros((n, len(bank)))
        self.est_rows = np.zeros(n)
        self.se_run = c_estimators.library().se_run

    def run_loop(self, x, a, v):
        out, est = self.c.run(x, a, v, out=self.out, est=self.est)
        return out[0], est

    def run_bank(self, bank, x, a, v):
        for e, kind in enumerate(bank.kinds):
            self.se_run(int(kind), bank.states[e], bank.params[e], x, a, v, self.est_rows, x.shape[0])


def _cpu_ns(fn):
    start = time.process_time_ns()
    fn()
    return time.process_time_ns() - start


def measure(rate, cores, seconds=None, repeats=None, progress=True):
    """({core: {"loop_ns_per_sample", "bank_ns_per_sample"}} (medians), the bank's names, the samples per run,
    whether the two loops gave the same bits (None with one core)); ``SECONDS`` and ``REPEATS`` by default."""
    seconds = SECONDS if seconds is None else seconds
    repeats = REPEATS if repeats is None else repeats
    def say(text):
        if progress:
            print(f"bench loop: {text}", file=sys.stderr, flush=True)

    from studyapp.estimators import Bank

    bank = bank_names(rate)
    n = max(SAMPLES_MIN, int(round(seconds * rate)))
    say(f"recording {n} sensor samples at {rate:g} Hz ...")
    x, a, v = stream(rate, n)
    runners = {core: (_C if core == "c" else _Numba)(rate, bank, n) for core in cores}
    banks = {core: Bank(rate, bank) for core in cores}
    first = {}
    for core, r in runners.items():  # warm: compile, caches; and the outputs compared below
        force, est = r.run_loop(x, a, v)
        first[core] = (force.copy(), np.ascontiguousarray(est).copy())
        r.run_bank(banks[core], x, a, v)
    times = {core: {"loop": [], "bank": []} for core in cores}
    for repeat in range(repeats):
        say(f"repeat {repeat + 1} of {repeats} ...")
        for core, r in runners.items():
            times[core]["loop"].append(_cpu_ns(lambda: r.run_loop(x, a, v)))
            times[core]["bank"].append(_cpu_ns(lambda: r.run_bank(banks[core], x, a, v)))
    result = {core: {f"{what}_ns_per_sample": statistics.median(t) / n for what, t in times[core].items()}
              for core in cores}
    same = None
    if len(first) == 2:
        (f1, e1), (f2, e2) = first.values()
        same = bool(np.array_equal(f1.view(np.uint64), f2.view(np.uint64))
                    and np.array_equal(e1.view(np.uint64), e2.view(np.uint64)))
    return result, bank, n, same


def run_cli(args):
    cores = parse_cores(args.core)
    rate = validate_rate(args.rate, "--rate")
    check_playable(rate, calibration.F0)
    try:
        result, bank, n, same = measure(rate, cores)
    except c_core.BuildError as exc:
        print(f"studyapp: error: {exc}", file=sys.stderr)
        return 1
    if getattr(args, "json", False):
        print(json.dumps({"rate": rate, "samples": n, "repeats": REPEATS, "bank": bank, "cores": result,
                          "same_bits": same}))
        return 0
    print(f"loop cost at {rate:g} Hz: the controller and {len(bank)} estimators, the LVT sensor in the loop "
          f"(CPU ns per sample, median of {REPEATS} runs of {n} samples)")
    print(f"{'core':<8}{'loop':>10}{'bank':>10}")
    for core, r in result.items():
        print(f"{core:<8}{r['loop_ns_per_sample']:>10.1f}{r['bank_ns_per_sample']:>10.1f}")
    if same is not None:
        print(f"the two loops' forces and estimates: {'the same bits' if same else 'DIFFERENT'}")
    print("numba's loop also runs the stability monitor, which the C leaves to the host")
    return 0

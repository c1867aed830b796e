"""What the loop costs in C and in numba: ``studyapp bench loop --core c,numba [--rate HZ] [--json]``.

Both cores run on the same recorded sensor stream (the simulated device
bowed on the strokes with the LVT at F_max 1 N, ``SECONDS`` at the rate but
at least ``SAMPLES_MIN`` samples, accelerometer on), from identical arrays built once by the host
(``ClosedLoop``: the bank of every position/acceleration estimator the rate
allows, all but LVT: fourteen from 4.6 kHz up, COMP2's Table 1 high-pass
needing that; the LVT sensor in the loop). Three figures per core, in ns per
sample:

- loop: one sample of the controller (sensors, source, string, force, motor
  limits, fault latch) and every estimator of the bank on it. C: sl_run
  (device/c_loop.py); numba: the host's shadow of a device loop
  (device/shadow.py run_rows: control.sample and every other estimator per
  row), which also advances the stability monitor (the C leaves the monitor
  to the host) and writes the audio row (switched off here: no body filter,
  no contact microphone);
- controller: the same with no estimator (the string, the force and the
  limits: what a sample costs besides the bank);
- bank: the estimators alone over the stream, each in turn: C se_run
  (device/c_estimators.py), numba dispatch.run_bank (what ``Bank.process``
  calls).

Each figure is the median over ``REPEATS`` runs of the whole stream in one
call (so no per-call overhead is counted: a firmware's per-sample cost), in
the process's CPU time (on a shared machine wall time would count other
processes too), the cores taking turns within each repeat. The numba loop's
first run checks every row's force and bridge velocity against the C loop's
(the shadow's own comparison, tolerance 0), the estimates are compared bit
for bit, and the answer printed.
``bench estimators``'s bank figure (Python calls on blocks of 256) includes
its calls' overhead; this one does not.
"""

import json
import statistics
import sys
import time

import numpy as np

from studyapp.device import c_core, shadow
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


def sensor_rows(x, a, v, force=None, bridge=None):
    """The sensors as the shadow's rows (device/shadow.py); with the C loop's force and bridge velocity to check."""
    rows = np.zeros((x.shape[0], shadow.ROW_WIDTH))
    rows[:, shadow.R_X], rows[:, shadow.R_A], rows[:, shadow.R_V] = x, a, v
    if force is not None:
        rows[:, shadow.R_LOOP_FORCE], rows[:, shadow.R_BRIDGE] = force, bridge
    return rows


class _Numba:
    """The numba loop on recorded sensors: the host's compiled shadow of a device loop (device/shadow.py), every
    estimator stepped per row as the device does."""

    def __init__(self, rate, bank, n):
        self.loop = _loop(rate, bank)
        self.alone = _loop(rate, [])
        self.out = np.zeros((len(control.OUTPUTS), n))
        self.est = np.zeros((len(bank), n))
        self.none = np.zeros((0, n))
        self.differs = np.zeros(2)

    def run_loop(self, rows, mode=shadow.MODEL):
        return shadow.run_rows(self.loop.control.arrays, 0, rows, 0.0, mode, self.out, self.est, self.differs)

    def run_controller(self, rows):
        shadow.run_rows(self.alone.control.arrays, 0, rows, 0.0, shadow.MODEL, self.out, self.none, self.differs)

    def run_bank(self, bank, x, a, v):
        run_bank(bank.kinds, bank.states, bank.params, x, a, v, self.est)


class _C:
    def __init__(self, rate, bank, n):
        from studyapp.device import c_estimators, c_loop

        self.loop = _loop(rate, bank)
        self.c = c_loop.CLoop(self.loop.control.arrays)
        self.alone = c_loop.CLoop(_loop(rate, []).control.arrays)
        self.out = np.zeros((len(c_loop.OUT_ROWS), n))
        self.bridge_row = c_loop.OUT_ROWS.index("bridge_velocity")
        self.est = np.zeros((n, len(bank)))
        self.none = np.zeros((n, 0))
        self.est_rows = np.zeros(n)
        self.se_run = c_estimators.library().se_run

    def run_loop(self, x, a, v):
        out, est = self.c.run(x, a, v, out=self.out, est=self.est)
        return out[0], out[self.bridge_row], est

    def run_controller(self, x, a, v):
        self.alone.run(x, a, v, out=self.out, est=self.none)

    def run_bank(self, bank, x, a, v):
        for e, kind in enumerate(bank.kinds):
            self.se_run(int(kind), bank.states[e], bank.params[e], x, a, v, self.est_rows, x.shape[0])


FIGURES = ("loop", "controller", "bank")


def _cpu_ns(fn):
    start = time.process_time_ns()
    fn()
    return time.process_time_ns() - start


def measure(rate, cores, seconds=None, repeats=None, progress=True):
    """({core: {"loop_ns_per_sample", "controller_ns_per_sample", "bank_ns_per_sample"}} (medians), the bank's names, the samples per run,
    whether the two loops gave the same bits (None with one core), the bytes of the C loop's arrays (None without
    the C core)); ``SECONDS`` and ``REPEATS`` by default."""
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
    same, c_est, rows = None, None, sensor_rows(x, a, v)
    if "c" in runners:  # warm: the library, caches; and the C loop's outputs, which the numba loop checks
        force, bridge, est = runners["c"].run_loop(x, a, v)
        c_est = np.ascontiguousarray(est).copy()
        checked = sensor_rows(x, a, v, force, bridge)
    if "numba" in runners:  # warm: compile; with the C core, every row's force and bridge velocity compared
        r = runners["numba"]
        differs = r.run_loop(checked, shadow.CHECK) if c_est is not None else r.run_loop(rows)
        if c_est is not None:
            same = bool(differs == -1 and np.array_equal(r.est.view(np.uint64), c_est.view(np.uint64)))
    for core, r in runners.items():
        r.run_controller(*((x, a, v) if core == "c" else (rows,)))
        r.run_bank(banks[core], x, a, v)
    times = {core: {what: [] for what in FIGURES} for core in cores}
    for repeat in range(repeats):
        say(f"repeat {repeat + 1} of {repeats} ...")
        for core, r in runners.items():
            sensors = (x, a, v) if core == "c" else (rows,)
            times[core]["loop"].append(_cpu_ns(lambda: r.run_loop(*sensors)))
            times[core]["controller"].append(_cpu_ns(lambda: r.run_controller(*sensors)))
            times[core]["bank"].append(_cpu_ns(lambda: r.run_bank(banks[core], x, a, v)))
    result = {core: {f"{what}_ns_per_sample": statistics.median(t) / n for what, t in times[core].items()}
              for core in cores}
    arrays = _C(rate, bank, 1).c.nbytes if "c" in cores else None
    return result, bank, n, same, arrays


def run_cli(args):
    cores = parse_cores(args.core)
    rate = validate_rate(args.rate, "--rate")
    check_playable(rate, calibration.F0)
    try:
        result, bank, n, same, arrays = measure(rate, cores)
    except c_core.BuildError as exc:
        print(f"studyapp: error: {exc}", file=sys.stderr)
        return 1
    if getattr(args, "json", False):
        print(json.dumps({"rate": rate, "samples": n, "repeats": REPEATS, "bank": bank, "cores": result,
                          "same_bits": same, "c_arrays_bytes": arrays}))
        return 0
    print(f"loop cost at {rate:g} Hz: the controller and {len(bank)} estimators, the LVT sensor in the loop "
          f"(CPU ns per sample, median of {REPEATS} runs of {n} samples)")
    print(f"{'core':<8}" + "".join(f"{what:>12}" for what in FIGURES))
    for core, r in result.items():
        print(f"{core:<8}" + "".join(f"{r[what + '_ns_per_sample']:>12.1f}" for what in FIGURES))
    if same is not None:
        print(f"the two loops' forces and estimates: {'the same bits' if same else 'DIFFERENT'}")
    if "numba" in result:
        print("numba's loop also runs the stability monitor, which the C leaves to the host")
    if arrays is not None:
        print(f"the C loop's arrays (parameters and state): {arrays:,} bytes")
    return 0

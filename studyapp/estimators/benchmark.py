"""What each estimator costs: nanoseconds per sample, medians of repeated runs.

Two forms are timed on a synthetic stick-slip signal (``studyapp.synthetic``):

- block: ``Estimator.process`` called from Python on consecutive blocks of
  ``block`` samples (the haptic loop's block size), so the per-call overhead of
  a real block-wise caller is included;
- stream: the compiled streaming step (``dispatch.step_guarded``) called once
  per sample inside a compiled loop, as the closed loop calls it.

The bank figure is ``Bank.process`` with every position/acceleration estimator
(all but LVT) on the same blocks. An estimator whose Table 1 defaults cannot
exist at the rate (COMP2's 2,254 Hz high-pass below 4.6 kHz) is reported as
not available, with the reason, and left out of both. Timings are wall-clock medians: run on an
otherwise idle machine, and don't compare figures across machines.
"""

import json
import statistics
import sys
import time

import numpy as np
from numba import njit

from studyapp import estimators
from studyapp.estimators import lvt
from studyapp.estimators.dispatch import step_guarded
from studyapp.estimators.registry import spec
from studyapp.errors import ParameterError
from studyapp.estimators.spec import validate_rate
from studyapp.synthetic import stick_slip

BLOCK = 256
SAMPLES_MAX = 10**8  # per timed run: 0.8 GB an array


@njit(cache=True)
def _stream(kind, s, p, xs, acc, vel, out):
    for i in range(xs.shape[0]):
        out[i] = step_guarded(kind, s, p, xs[i], acc[i], vel[i])


def _signal(rate, n):
    sig = stick_slip(rate, n / rate)
    return sig["position"], sig["acceleration"], sig["velocity_lvt"]


def _median_ns(fn, n, repeats):
    fn()  # compile and warm caches
    times = []
    for _ in range(repeats):
        start = time.perf_counter_ns()
        fn()
        times.append(time.perf_counter_ns() - start)
    return statistics.median(times) / n


def _blockwise(process, x, a, v, block):
    def run():
        for i in range(0, x.shape[0], block):
            process(x[i:i + block], a[i:i + block], v[i:i + block])
    return run


def cost(name, rate, params=None, n=100_000, repeats=5, block=BLOCK):
    """Median ns/sample of estimator ``name`` in its block and streaming forms."""
    x, a, v = _signal(rate, n)
    est = estimators.create(name, rate, **(params or {}))
    block_ns = _median_ns(_blockwise(est.process, x, a, v, block), n, repeats)
    out = np.empty(n)
    stream_ns = _median_ns(lambda: _stream(est.kind, est.state, est.p, x, a, v, out), n, repeats)
    return {"block_ns_per_sample": block_ns, "stream_ns_per_sample": stream_ns}


def bank_cost(rate, names=None, n=100_000, repeats=5, block=BLOCK):
    """Median ns/sample of a Bank of ``names`` (default: all but LVT) on blocks."""
    names = names or [e for e in estimators.names() if e != lvt.NAME]
    x, a, v = _signal(rate, n)
    bank = estimators.Bank(rate, names)
    return _median_ns(_blockwise(bank.process, x, a, v, block), n, repeats)


def run(rate, progress=True, n=100_000):
    result = {"rate": rate, "samples": n, "estimators": {}, "unavailable": {}}
    for name in estimators.names():
        reason = spec(name).not_available(rate)
        if reason is not None:
            result["unavailable"][name] = reason
            continue
        if progress:
            print(f"bench estimators: {name} ...", file=sys.stderr, flush=True)
        result["estimators"][name] = cost(name, rate, n=n)
    bank = [name for name in result["estimators"] if name != lvt.NAME]
    result["bank"] = bank
    if progress:
        print(f"bench estimators: bank of {len(bank)} ...", file=sys.stderr, flush=True)
    result["bank_ns_per_sample"] = bank_cost(rate, bank, n=n)
    return result


def run_cli(args):
    rate = validate_rate(args.rate)
    if not BLOCK <= args.samples <= SAMPLES_MAX:  # every estimator's input and output are allocated at once
        raise ParameterError(f"--samples {args.samples}: allowed is an integer from {BLOCK} to {SAMPLES_MAX}")
    result = run(rate, n=args.samples)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    print(f"estimator cost at {rate:g} Hz (median ns per sample)")
    print(f"{'name':<12}{'block':>10}{'stream':>10}")
    for name, r in result["estimators"].items():
        print(f"{name:<12}{r['block_ns_per_sample']:>10.1f}{r['stream_ns_per_sample']:>10.1f}")
    for name, reason in result["unavailable"].items():
        print(f"{name:<12}{reason}")
    bank = result["bank_ns_per_sample"]
    print(f"bank of {len(result['bank'])} (all but LVT): {bank:.1f} ns/sample = "
          f"{1e9 / bank / rate:.1f}x real time at {rate:g} Hz")
    return 0

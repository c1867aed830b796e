"""``studyapp bench live``: the highest rate at which the engine holds real time.

"Holds real time": the worker, paced by the monotonic timer, runs the closed
loop with all fourteen estimators active (every estimator but LVT, which is
a sensor), the string rendered and resampled to 48 kHz (the ``discard`` sink:
everything a device sink costs but the device), and finishes every block
before its deadline (zero deadline misses) with the achieved rate within 1% of
the nominal one.

Search: probes of ``PROBE_SECONDS`` at rising rates (5, 10, 20, 40, 48, 96 kHz,
96 kHz being the loop's top rate) until one fails; bisection between the last
pass and the first failure to within 5%; then a confirmation run of
``--seconds`` (default 30 s) at the best rate, stepping down 10% while the
confirmation fails. The load figures (compute time of a block over its period:
mean, 99th percentile, largest) come from each run's every block; 48 kHz is
always among the runs, for the load with all fourteen at that rate.

Blocks last ``--block-ms`` (default: the engine's 2 ms). A block's deadline
is the end of its own period, so the OS's wake-up jitter counts in full: on a
machine that wakes a real-time thread late by more than a block period, no
rate holds however light the load (then the load figures are the measure).

A run whose misses were all the machine's (late starts and stalls, no block
overran its period on the CPU: the OS, not the engine, was late) is run once
more at the same rate before it counts as failed; every run is listed in the result with its overruns, stalls and
the worst wake-up delay, so a busy machine shows as such. Speed depends on the
machine and on what else runs on it; the result is a measurement, never a
test.
"""

import json
import sys
import time

from studyapp import estimators
from studyapp.engine.config import BLOCK_PERIOD, EngineConfig, block_samples
from studyapp.engine.engine import Engine
from studyapp.errors import ParameterError
from studyapp.estimators import lvt

LADDER = (5000.0, 10000.0, 20000.0, 40000.0, 48000.0, 96000.0)
PROBE_SECONDS = 3.0
RESOLUTION = 0.05
CHECK_RATE = 48000.0


def all_fourteen():
    return {n: {} for n in estimators.names() if n != lvt.NAME}


def probe(rate, seconds, progress=print, block_period=BLOCK_PERIOD):
    """Run the engine for ``seconds`` at ``rate`` in blocks of ``block_period`` s; the worker's summary plus ``passed``."""


    config = EngineConfig(rate=rate, estimators=all_fourteen(), source="KALLEV", fmax=1.0,
                          audio="discard", midi="none", block=block_samples(rate, block_period))
    engine = Engine(config).start()
    try:
        time.sleep(seconds)
    finally:
        summary = engine.stop() or {}
    result = {
        "rate": rate, "seconds": summary.get("seconds", 0.0), "block": summary.get("block"),
        "achieved_rate": summary.get("achieved_rate", 0.0),
        "deadline_misses": summary.get("deadline_misses", -1),
        "load_mean": summary.get("load_mean", 0.0), "load_p99": summary.get("load_p99", 0.0),
        "load_max": summary.get("load_max", 0.0), "faults": list(engine.faults),
        "overruns": summary.get("overruns", 0), "stalls": summary.get("stalls", 0),
        "wake_late_max": summary.get("wake_late_max", 0.0),
        "realtime_priority": summary.get("realtime", False),
    }
    result["passed"] = (
        result["deadline_misses"] == 0 and not engine.tripped
        and abs(result["achieved_rate"] - rate) <= 0.01 * rate
    )
    progress(f"bench live: {rate:8.0f} Hz for {seconds:g} s: "
             f"{'holds' if result['passed'] else 'FAILS'} (misses {result['deadline_misses']}, "
             f"load mean {100 * result['load_mean']:.0f}% p99 {100 * result['load_p99']:.0f}% "
             f"max {100 * result['load_max']:.0f}%, overruns {result['overruns']}, stalls {result['stalls']}, "
             f"worst wake-up {1e3 * result['wake_late_max']:.1f} ms late)")
    return result


def search(confirm_seconds=30.0, probe_seconds=PROBE_SECONDS, progress=print, block_period=BLOCK_PERIOD):
    probes = []

    def attempt(rate, seconds):
        for _ in range(2):
            r = probe(rate, seconds, progress, block_period)
            probes.append(r)
            if r["passed"] or r["overruns"] > 0 or r["faults"]:
                break
        return r["passed"]

    best, failed = None, None
    for rate in LADDER:
        if attempt(rate, probe_seconds):
            best = rate
        else:
            failed = rate
            break
    if best is not None and failed is not None:
        low, high = best, failed
        while (high - low) / high > RESOLUTION:
            mid = round((low + high) / 2, -2)
            if attempt(mid, probe_seconds):
                low = mid
            else:
                high = mid
        best = low
    confirmed = None
    rate = best
    first_confirm = len(probes)
    for _ in range(3):
        if rate is None:
            break
        if attempt(rate, confirm_seconds):
            confirmed = rate
            break
        rate = round(rate * 0.9, -2)
    confirms = probes[first_confirm:]
    check = next((p for p in probes if p["rate"] == CHECK_RATE), None)
    if check is None:
        check = probe(CHECK_RATE, probe_seconds, progress, block_period)
        probes.append(check)
    return {
        "realtime_rate": confirmed,
        "best_probe_rate": best,
        "confirm_seconds": confirm_seconds,
        "block_period": block_period,
        "confirm_overruns": sum(p["overruns"] for p in confirms),
        "confirm_stalls": sum(p["stalls"] for p in confirms),
        "confirm_wake_late_max": max((p["wake_late_max"] for p in confirms), default=0.0),
        "estimators": list(all_fourteen()),
        "load_at_48k": None if check is None else {
            k: check[k] for k in ("load_mean", "load_p99", "load_max", "deadline_misses", "block")
        },
        "probes": probes,
    }


def run_cli(args):

    seconds = float(getattr(args, "seconds", 30.0))
    if not seconds > 0:
        raise ParameterError(f"--seconds {seconds:g}: allowed is a positive number")
    block_ms = float(getattr(args, "block_ms", 1e3 * BLOCK_PERIOD))
    if not 0.1 <= block_ms <= 100.0:
        raise ParameterError(f"--block-ms {block_ms:g}: allowed is a block period from 0.1 to 100 ms")

    def progress(text):
        print(text, file=sys.stderr, flush=True)

    result = search(confirm_seconds=seconds, progress=progress, block_period=block_ms / 1e3)
    if args.json:
        print(json.dumps(result, indent=2))
        return 0
    rate = result["realtime_rate"]
    if rate is None:
        print(f"no rate held {seconds:g} s without a deadline miss in {block_ms:g} ms blocks "
              f"(best {PROBE_SECONDS:g} s probe: {result['best_probe_rate']} Hz; in the confirmation runs "
              f"{result['confirm_overruns']} blocks overran their period on the CPU, {result['confirm_stalls']} "
              f"were stalled off it, and the OS woke the worker up to "
              f"{1e3 * result['confirm_wake_late_max']:.1f} ms late)")
    else:
        print(f"highest real-time rate with all fourteen estimators: {rate:g} Hz "
              f"(zero deadline misses over {seconds:g} s in {block_ms:g} ms blocks)")
    check = result["load_at_48k"]
    if check is not None:
        print(f"at 48 kHz (block {check['block']}): load mean {100 * check['load_mean']:.0f}%, "
              f"p99 {100 * check['load_p99']:.0f}%, max {100 * check['load_max']:.0f}% of the block period")
    return 0

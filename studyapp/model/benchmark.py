"""Closed-loop throughput: ``studyapp bench loop --rate HZ [--json]``.

The loop runs with all fourteen position/acceleration estimators active (every
name but LVT), the LVT in the loop, the string, body filter and stability
monitor running, in blocks of ``BLOCK`` samples. Reported: the median over
``REPEATS`` timed runs of ``SECONDS`` simulated seconds each, after a warm-up
that compiles everything. Time is the process's CPU time: on a shared machine
wall time would also count other processes' use of the core.
"""

import json
import sys
import time

import numpy as np

from studyapp.estimators import lvt, names
from studyapp.estimators.spec import validate_rate
from studyapp.model import calibration
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.playable import check_playable
from studyapp.model.sources import LVT_SENSOR

BLOCK = 1024
SECONDS = 1.0
REPEATS = 5


def measure(rate, block=BLOCK, seconds=SECONDS, repeats=REPEATS):
    """Samples per second (median over repeats) of the full closed loop at ``rate``."""
    estimators = {name: {} for name in names() if name != lvt.NAME}
    loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=LVT_SENSOR, fmax=1.0, gesture="strokes"))
    loop.run(block)
    n = max(block, int(round(seconds * loop.rate)))
    rates = []
    for _ in range(repeats):
        done = 0
        start = time.process_time()
        while done < n:
            loop.run(block)
            done += block
        rates.append(done / max(time.process_time() - start, 1e-9))
    return float(np.median(rates))


def run_cli(args):
    rate = validate_rate(args.rate)
    check_playable(rate, calibration.F0)
    sps = measure(rate)
    result = {"rate": rate, "samples_per_second": sps, "realtime_factor": sps / rate}
    if getattr(args, "json", False):
        print(json.dumps(result))
    else:
        print(f"closed loop at {rate:g} Hz, 14 estimators + string: {sps:,.0f} samples/s, "
              f"{sps / rate:.1f} x real time (median of {REPEATS}, blocks of {BLOCK})")
    sys.stdout.flush()
    return 0

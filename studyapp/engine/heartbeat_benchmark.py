"""``studyapp bench heartbeat``: the heartbeat silences a running engine shows under this machine's load.

One run: an engine (simulated device, LVT, 1 N, null audio, no MIDI) runs for
``--seconds`` with a bound it never reaches (so nothing trips), while this
process watches its heartbeat as the force guard does (guard.py: a look every
``guard.POLL`` = 2 ms). For each heartbeat it records the longest silence
seen before the next one (now - heartbeat, at each look): what the guard
would have compared with its bound. It reports the machine's load per core
(load_margin.py) at the start and the end, the largest silence, its 99.9th
percentile, and the trips per minute the fixed 80 ms bound and the
load-following bound (``load_margin.hang_timeout_for``) would have made. A
measurement of this machine under its load, never a test.
"""

import json
import time

import numpy as np

from studyapp.engine import guard
from studyapp.engine.config import HANG_TIMEOUT, EngineConfig
from studyapp.engine.engine import Engine
from studyapp.engine.load_margin import hang_timeout_for, load_per_core
from studyapp.errors import ParameterError

BASE = HANG_TIMEOUT


def silences(status, seconds):
    """The longest silence seen before each new heartbeat over ``seconds`` (s, one per heartbeat)."""
    out, last, peak = [], None, 0.0
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        state, beat = status.worker_beat()
        now = time.monotonic()
        if state == "running":
            if beat != last:
                if last is not None:
                    out.append(peak)
                last, peak = beat, now - beat
            else:
                peak = max(peak, now - beat)
        time.sleep(guard.POLL)
    return np.array(out)


def measure(seconds):
    load = load_per_core()
    engine = Engine(EngineConfig(rate=5000.0, source="LVT", fmax=1.0, audio="null", midi="none",
                                 hang_timeout=5.0)).start()
    try:
        deadline = time.monotonic() + 120.0
        while engine.status()["samples"] < 1000 and time.monotonic() < deadline:
            time.sleep(0.01)
        gaps = silences(engine.status_block, seconds)
    finally:
        engine.stop()
    end_load = load_per_core()
    adaptive = hang_timeout_for(load, BASE)
    minutes = seconds / 60.0
    return {
        "seconds": seconds, "load_per_core_start": round(load, 2), "load_per_core_end": round(end_load, 2),
        "heartbeats": int(gaps.size),
        "largest_silence_ms": round(1e3 * float(gaps.max()), 1) if gaps.size else None,
        "p999_silence_ms": round(1e3 * float(np.quantile(gaps, 0.999)), 1) if gaps.size else None,
        "fixed_bound_ms": round(1e3 * BASE), "fixed_trips_per_min": round(float((gaps > BASE).sum()) / minutes, 2),
        "load_bound_ms": round(1e3 * adaptive), "load_trips_per_min": round(float((gaps > adaptive).sum()) / minutes, 2),
    }


def run_cli(args):
    if not 1.0 <= args.seconds <= 3600.0:
        raise ParameterError(f"--seconds {args.seconds:g}: allowed is 1 to 3600")
    result = measure(args.seconds)
    if args.json:
        print(json.dumps(result))
    else:
        for key, value in result.items():
            print(f"{key}: {value}")
    return 0

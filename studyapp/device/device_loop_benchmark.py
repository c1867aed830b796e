"""``studyapp bench device --loop device``: a device that runs the loop (protocol 2) over a pty, in real time.

The emulator (``studyapp device-emulator --loop device``: the C loop on its
own sample clock, its keep-alive watchdog ``--keepalive-ms``) in its own
process, and this process as its host (loop_link.py): the closed loop's
shadow of every estimator the device runs, on the TELEMETRY rows, for
``--seconds`` after a warm-up, with a knob turn every ``KNOB_EVERY`` s
(F_max between ``FMAX`` values: a CONTROL). The device is armed without a
ramp; a device fault (its watchdog, a shadow difference, a silent link) is
counted and the run re-arms and goes on. The figures are defined in
benchmark.py's text; per run, and the medians over ``--runs``.
"""

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.loop_link import DEFAULT_PACKET, LoopLink

WARMUP = 0.5  # s of loop before the timed run
BLOCK = 10  # samples per loop.run: the engine's 2 ms at 5 kHz
KNOB_EVERY = 0.25  # s between knob turns
FMAX = (1.0, 2.0)  # N: the knob's two positions


def _quantiles(values):
    a = np.asarray(values, dtype=float)
    if not a.size:
        return {"p50": float("nan"), "p99": float("nan"), "max": float("nan")}
    return {"p50": float(np.percentile(a, 50)), "p99": float(np.percentile(a, 99)), "max": float(a.max())}


def one_run(rate, seconds, packet, keepalive_ms, seed):
    """One timed run; a dict of its figures."""
    from studyapp.device.loop_bank import names_of
    from studyapp.model.loop import ClosedLoop, LoopConfig
    from studyapp.model.sources import LVT_SENSOR

    with tempfile.TemporaryDirectory(prefix="studyapp-bench-device-loop-") as folder:
        link = Path(folder) / "device"
        options = ["--rate", f"{rate:g}", "--seed", seed, "--loop", "device"]
        if keepalive_ms is not None:
            options += ["--keepalive-ms", keepalive_ms]
        emulator = EmulatorProcess(link, *options)
        emulator.start()
        try:
            device = LoopLink(link, rate, packet=packet, ramp_ms=0)
            estimators = {name: {} for name in names_of(device.loop_info.kinds)}
            loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=LVT_SENSOR, fmax=FMAX[0],
                                         gesture="strokes", seed=seed), device=device, judge=False)
            device.arm(0)
            for _ in range(int(WARMUP * rate / BLOCK)):
                loop.run(BLOCK)
            health = dict(device.health)
            device.control_delays.clear()
            trips, shadow, faults = 0, 0, []
            started = last = time.monotonic()
            longest = 0.0
            turns = 0
            while (now := time.monotonic()) - started < seconds:
                if now - started >= (turns + 1) * KNOB_EVERY:
                    turns += 1
                    loop.set_fmax(FMAX[turns % 2])
                loop.run(BLOCK)
                after = time.monotonic()
                longest = max(longest, after - last)
                last = after
                if device.fault is not None:
                    faults.append(device.fault)
                    trips += "WATCHDOG" in device.fault
                    shadow += "differs from the host's shadow" in device.fault
                    loop.clear_device_fault()
                    device.rearm(0)
            elapsed = time.monotonic() - started
            delays = list(device.control_delays)
            run_health = {k: device.health[k] - health.get(k, 0) for k in device.health}
            device.stop_stream()
            device.close()
        finally:
            stats = emulator.stop() or {}
    return {
        "seconds": elapsed, "samples": run_health["samples"], "frames": run_health["frames"],
        "watchdog": trips, "shadow_faults": shadow, "device_faults": len(faults), "faults": faults[:5],
        "force_gaps": run_health["force_gaps"],
        "telemetry": {"missing": run_health["missing"], "gaps": run_health["gaps"], "lost": run_health["lost"],
                      "corrupt": run_health["corrupt"], "unchecked": run_health["unchecked"],
                      "longest_block_ms": 1e3 * longest, "device_tx_dropped": stats.get("tx_dropped")},
        "control": {"sent": run_health["controls"], "late": run_health["late"],
                    "device_ms": _quantiles([1e3 * d / rate for d, _ in delays]),
                    "host_ms": _quantiles([1e3 * t for _, t in delays])},
        "device_counters": {k: stats.get(k) for k in ("late", "lost", "corrupt", "missing", "samples")},
    }


def measure(rate=5000.0, seconds=60.0, runs=1, packet=DEFAULT_PACKET, keepalive_ms=None, seed=0):
    results = [one_run(rate, seconds, packet, keepalive_ms, seed + i) for i in range(runs)]

    def median(get):
        return float(np.median([get(r) for r in results]))

    summary = {
        "watchdog": median(lambda r: r["watchdog"]), "force_gaps": median(lambda r: r["force_gaps"]),
        "shadow_faults": median(lambda r: r["shadow_faults"]),
        "missing": median(lambda r: r["telemetry"]["missing"]), "gaps": median(lambda r: r["telemetry"]["gaps"]),
        "longest_block_ms": median(lambda r: r["telemetry"]["longest_block_ms"]),
        "control_device_ms": {q: median(lambda r: r["control"]["device_ms"][q]) for q in ("p50", "p99", "max")},
        "control_host_ms": {q: median(lambda r: r["control"]["host_ms"][q]) for q in ("p50", "p99", "max")},
    }
    return {"rate": rate, "seconds": seconds, "runs": runs, "packet": packet, "loop": "device",
            "knob_every_s": KNOB_EVERY, "median": summary, "each": results}


def run_cli(args):
    packet = DEFAULT_PACKET if args.packet is None else args.packet
    result = measure(args.rate, args.seconds, args.runs, packet, getattr(args, "keepalive_ms", None))
    if args.json:
        print(json.dumps(result))
    else:
        m = result["median"]
        c, h = m["control_device_ms"], m["control_host_ms"]
        print(f"device loop over a pty at {args.rate:g} Hz, telemetry packets of {packet}, {args.seconds:g} s x "
              f"{args.runs}: watchdog trips {m['watchdog']:g}, force gaps {m['force_gaps']:g}, shadow faults "
              f"{m['shadow_faults']:g}; telemetry: {m['missing']:g} samples missing in {m['gaps']:g} gaps, longest "
              f"block {m['longest_block_ms']:.1f} ms; CONTROL delivery: device {c['p50']:.1f} / {c['p99']:.1f} / "
              f"{c['max']:.1f} ms, host {h['p50']:.1f} / {h['p99']:.1f} / {h['max']:.1f} ms (p50 / p99 / max; "
              "medians over runs)")
    sys.stdout.flush()
    return 0

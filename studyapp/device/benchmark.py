"""``studyapp bench device``: the host loop over a pty to the device emulator, in real time.

Host and device are separate processes, as on a rig: the emulator
(``studyapp device-emulator``, its own sample clock at ``--rate``) on a pty,
and this process running the closed loop with all fourteen position and
acceleration estimators active (every name but LVT; the LVT in the loop) on a
``LinkDevice`` (link_device.py) for ``--seconds`` after a warm-up, answering
each sensor frame (``--packet`` samples) with forces ``--latency`` samples
ahead. Reported per run, and as the median over ``--runs`` runs:

    on_time        the share of the device's samples that got their tagged force in time:
                   1 - (missing + late) / samples armed, from the emulator's own counters
    turnaround     the host's time from reading a sensor frame to writing its force frame,
                   p50 / p99 / p99.9 (us), over every frame
    watchdog       device faults (the emulator's watchdog firing because the host fell
                   behind by more than the latency + watchdog); the run re-arms and goes on

With ``--loop device`` the emulator runs the loop itself (protocol version 2,
its C loop on its own clock) and this process is the host of a device loop
(loop_link.py: telemetry in packets of ``--packet`` samples, 10 by default,
the shadow compared row by row, ALIVE, and a knob turn every ``KNOB_EVERY``
s: F_max between two values, as CONTROL). Reported (device_loop.py):

    watchdog       the device's keep-alive watchdog firing (the host away longer than keepalive_ms)
    force_gaps     samples the device was armed, past its ramp, with a loop force, and applied none
    telemetry      device samples the host never received (missing) and in how many gaps, and the
                   longest the host went between two blocks (ms)
    control        CONTROL delivery: device samples from the newest sample the host had seen when it
                   sent the CONTROL to the sample it took effect at (ms), and the host's time from
                   sending it to reading the row that names it (ms); p50 / p99 / max
    shadow_faults  rows where the device's force differed from the host's shadow (0 on one machine)

Speed is measured here, never asserted in tests (the machine is shared).
"""

import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import LinkDevice
from studyapp.errors import ParameterError

WARMUP = 0.5  # s of loop before the timed run (compiled code loads, the pty settles)
BLOCK = 10  # samples per loop.run, the engine's 2 ms at 5 kHz
LOOPS = ("host", "device")


def one_run(rate, seconds, latency, packet, watchdog_ms, seed):
    """One timed run; a dict of its figures."""
    from studyapp.estimators import lvt, names
    from studyapp.model.loop import ClosedLoop, LoopConfig
    from studyapp.model.sources import LVT_SENSOR

    with tempfile.TemporaryDirectory(prefix="studyapp-bench-device-") as folder:
        link = Path(folder) / "device"
        emulator = EmulatorProcess(link, "--rate", f"{rate:g}", "--seed", seed, "--watchdog-ms", watchdog_ms)
        emulator.start()
        try:
            device = LinkDevice(link, rate, latency=latency, packet=packet, ramp_ms=0, timing=True)
            estimators = {name: {} for name in names() if name != lvt.NAME}
            loop = ClosedLoop(LoopConfig(rate=rate, estimators=estimators, source=LVT_SENSOR, fmax=1.0,
                                         gesture="strokes", seed=seed), device=device)
            for _ in range(int(WARMUP * rate / BLOCK)):
                loop.run(BLOCK)
            loop.clear_device_fault()
            device.rearm(0)  # the frames of the warm-up dropped, armed without a ramp
            device.turnarounds.clear()
            health = dict(device.health)
            started = time.monotonic()
            trips = 0
            while time.monotonic() - started < seconds:
                loop.run(BLOCK)
                if device.fault is not None:
                    trips += 1
                    loop.clear_device_fault()
                    device.rearm(0)
            elapsed = time.monotonic() - started
            device.stop_stream()
            turnaround = 1e6 * np.asarray(device.turnarounds)
            run_health = {k: device.health[k] - health[k] for k in health}
            device.close()
        finally:
            stats = emulator.stop() or {}
    counters = stats.get("counters", stats)
    samples = max(1, run_health["samples"])
    missing = int(counters.get("missing", 0))
    late = int(counters.get("late", 0))
    return {
        "seconds": elapsed, "samples": run_health["samples"], "frames": run_health["frames"],
        "on_time": 1.0 - (missing + late) / samples, "device_missing": missing, "device_late": late,
        "host_late": run_health["late"], "lost": run_health["lost"], "corrupt": run_health["corrupt"],
        "watchdog": trips,
        "turnaround_us": {q: float(np.percentile(turnaround, p)) if turnaround.size else float("nan")
                          for q, p in (("p50", 50), ("p99", 99), ("p99.9", 99.9))},
    }


def measure(rate=5000.0, seconds=60.0, runs=1, latency=5, packet=1, watchdog_ms=1, seed=0):
    results = [one_run(rate, seconds, latency, packet, watchdog_ms, seed + i) for i in range(runs)]
    median = {
        "on_time": float(np.median([r["on_time"] for r in results])),
        "watchdog": float(np.median([r["watchdog"] for r in results])),
        "turnaround_us": {q: float(np.median([r["turnaround_us"][q] for r in results]))
                          for q in ("p50", "p99", "p99.9")},
    }
    return {"rate": rate, "seconds": seconds, "runs": runs, "latency_samples": latency, "packet": packet,
            "watchdog_ms": watchdog_ms, "estimators": 14, "median": median, "each": results}


def run_cli(args):
    if not args.seconds > 0:
        raise ParameterError(f"--seconds {args.seconds}: allowed is a positive number")
    if not args.runs >= 1:
        raise ParameterError(f"--runs {args.runs}: allowed is 1 or more")
    if args.loop not in LOOPS:
        raise ParameterError(f"--loop {args.loop}: allowed is {' or '.join(LOOPS)}")
    if args.loop == "device":
        from studyapp.device import device_loop_benchmark

        return device_loop_benchmark.run_cli(args)
    result = measure(args.rate, args.seconds, args.runs, args.latency, args.packet or 1, args.watchdog_ms)
    if args.json:
        print(json.dumps(result))
    else:
        m = result["median"]
        t = m["turnaround_us"]
        print(f"device over a pty at {args.rate:g} Hz, 14 estimators, latency {args.latency} samples, "
              f"packet {args.packet or 1}, watchdog {args.watchdog_ms} ms, {args.seconds:g} s x {args.runs}: "
              f"on time {100 * m['on_time']:.2f} %, host turnaround p50 {t['p50']:.0f} us, p99 {t['p99']:.0f} us, "
              f"p99.9 {t['p99.9']:.0f} us, watchdog trips {m['watchdog']:g} (medians over runs)")
    sys.stdout.flush()
    return 0

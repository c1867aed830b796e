"""Issue 41's target for ``studyapp live --device``: runs of live on the emulator, each trip counted and re-armed.

    python scripts/live_device_trips.py [--runs 10] [--seconds 60] [--first-sample N] [-- LIVE OPTIONS...]

Each run starts a fresh ``studyapp device-emulator`` (seed = the run's index; its defaults unless the options
after ``--`` say otherwise for live), runs ``studyapp live --device LINK --audio null --midi none --seconds S
--json``, and prints one line per run: the device's watchdog trips and the host's silences (both re-armed by
live), how many re-arms, the slowest (from the host latching the fault to its ARM), the samples the host ran, and the fault still latched at the end
(none, or one that is not a trip). A run passes when it ends with no latched fault and every trip was re-armed
within 0.5 s. The last line: how many runs passed, and the median trips per run.
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from studyapp.device.emulator_process import EmulatorProcess

REARM_WITHIN = 0.5  # s: the bound from a trip to its re-arm


def one_run(index, seconds, first_sample, extra):
    with tempfile.TemporaryDirectory() as tmp:
        link = Path(tmp) / "device"
        options = ["--seed", index] + (["--first-sample", first_sample] if first_sample is not None else [])
        with EmulatorProcess(link, *options):
            proc = subprocess.run([sys.executable, "-m", "studyapp", "live", "--device", str(link), "--audio", "null",
                                   "--midi", "none", "--seconds", str(seconds), "--json", *extra],
                                  capture_output=True, text=True, timeout=seconds + 600)
    if proc.returncode not in (0, 1) or not proc.stdout.strip():
        return {"run": index, "error": (proc.stderr.strip().splitlines() or ["no output"])[-1]}
    result = json.loads(proc.stdout)
    device = result["device"]
    if not device or not device.get("health"):
        return {"run": index, "error": "no device health in live's summary (the engine's end was not reported)",
                "faults": len(result.get("faults", []))}
    health = device["health"]
    trips, rearms, slowest = health.get("trips", 0), device.get("rearms", 0), device.get("rearm_max_s")
    ok = device["fault"] is None and rearms >= trips and (slowest is None or slowest <= REARM_WITHIN)
    return {"run": index, "trips": trips, "silences": health.get("silences", 0), "rearms": rearms,
            "rearm_max_s": slowest,
            "samples": health.get("samples"), "latched": device["fault"], "pass": ok}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--first-sample", type=int, default=None)
    parser.add_argument("live", nargs="*", help="options passed on to studyapp live (after --)")
    args = parser.parse_args(argv)
    rows = []
    for index in range(args.runs):
        row = one_run(index, args.seconds, args.first_sample, args.live)
        rows.append(row)
        print(json.dumps(row), flush=True)
    passed = sum(1 for r in rows if r.get("pass"))
    trips = [r["trips"] for r in rows if "trips" in r]
    print(f"{passed} of {len(rows)} runs of {args.seconds:g} s passed; trips per run: median "
          f"{statistics.median(trips) if trips else 'n/a'}, max {max(trips) if trips else 'n/a'}", flush=True)
    return 0 if passed == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())

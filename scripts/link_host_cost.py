"""The host's cost per device sample on a link: the loop on a ``LinkDevice`` over the emulator, by the wall clock.

    python scripts/link_host_cost.py [--packet P] [--latency L] [--seconds S]

Starts ``studyapp device-emulator`` with a 1 s watchdog (so that no trip stops the run), opens the link with
the given packet and latency, arms, and runs the loop (the engine's default estimators, LVT in the loop) in
blocks of 10 for S seconds, then prints the samples run and the wall-clock microseconds per sample. A 5 kHz
device gives the host 200 us per sample: above that it falls behind (issue 41: the defaults' trips).
"""

import argparse
import tempfile
import time
from pathlib import Path

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import LinkDevice
from studyapp.engine.config import EngineConfig
from studyapp.model.loop import ClosedLoop, LoopConfig


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--packet", type=int, default=1)
    parser.add_argument("--latency", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=3.0)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "device"
        with EmulatorProcess(path, "--watchdog-ms", 1000):
            device = LinkDevice(path, 5000.0, latency=args.latency, packet=args.packet, silence=1.0)
            config = EngineConfig()
            loop = ClosedLoop(LoopConfig(rate=5000.0, estimators=config.estimators, source=config.source, fmax=1.0),
                              device=device)
            loop.run(10)
            device.resync()
            device.arm()
            start, before = time.perf_counter(), device.health["samples"]
            while time.perf_counter() - start < args.seconds:
                loop.run(10)
            took, samples = time.perf_counter() - start, device.health["samples"] - before
            device.close()
    print(f"packet {args.packet}, latency {args.latency}: {samples} samples in {took:.2f} s, "
          f"{1e6 * took / max(samples, 1):.0f} us per sample; fault: {device.fault}")


if __name__ == "__main__":
    main()

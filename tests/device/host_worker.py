"""A host worker for the fault tests, in its own process: the real loop on the real driver, until the device faults.

    python -m tests.device.host_worker PATH LATENCY [SILENCE_S]    a host loop (LinkDevice, protocol 1)
    python -m tests.device.host_worker PATH loop                    a device loop (the driver picked from INFO)

Prints ``running`` once armed and streaming for 0.1 s, then runs the loop (LVT at 2 N in the loop, 2 ms
blocks). When the device faults (after a SIGSTOP and SIGCONT, the device's WATCHDOG FAULT frame is in the
link's backlog) it prints one JSON line: the fault text and the device's FAULT frames, (code, sample, detail)
each, and exits. SILENCE_S (default the driver's) is how long the host waits for a device frame before it
latches a silent link.
"""

import json
import sys

from studyapp.device.device_open import open_link_device
from studyapp.device.link_device import SILENCE, LinkDevice
from studyapp.device.loop_bank import names_of
from studyapp.model.loop import ClosedLoop, LoopConfig

RATE = 5000.0


def host_loop(path, latency, silence=SILENCE):
    device = LinkDevice(path, RATE, latency=int(latency), ramp_ms=0, silence=float(silence))
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators={}, source="LVT", fmax=2.0, gesture="strokes"),
                      device=device)
    loop.run(10)
    device.resync()
    return device, loop


def device_loop(path):
    device = open_link_device(path, RATE, {"silence": 10.0, "ramp_ms": 0})
    estimators = {name: {} for name in names_of(device.loop_info.kinds)}
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source="LVT", fmax=2.0, gesture="strokes"),
                      device=device, judge=False)
    return device, loop


def main(path, *options):
    device, loop = device_loop(path) if options == ("loop",) else host_loop(path, *options)
    device.arm(0)
    for _ in range(50):
        loop.run(10)
    print("running", flush=True)
    while device.fault is None:
        loop.run(10)
    print(json.dumps({"fault": device.fault, "device_faults": device.device_faults}), flush=True)
    device.close()


if __name__ == "__main__":
    main(*sys.argv[1:4])

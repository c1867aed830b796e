"""A host worker for the fault tests, in its own process: the real loop on a ``LinkDevice``, until the device faults.

    python -m tests.device.host_worker PATH LATENCY [SILENCE_S]

Prints ``running`` once armed and streaming, then runs the loop (LVT in the loop, 2 ms blocks). When the device
faults (after a SIGSTOP and SIGCONT, the device's WATCHDOG FAULT frame is in the link's backlog) it prints one JSON
line: the fault text and the device's FAULT frames, (code, sample, detail) each, and exits. SILENCE_S (default
the driver's) is how long the host waits for a device frame before it latches a silent link.
"""

import json
import sys

from studyapp.device.link_device import SILENCE, LinkDevice
from studyapp.model.loop import ClosedLoop, LoopConfig


def main(path, latency, silence=SILENCE):
    device = LinkDevice(path, 5000.0, latency=int(latency), ramp_ms=0, silence=float(silence))
    loop = ClosedLoop(LoopConfig(rate=5000.0, estimators={}, source="LVT", fmax=2.0, gesture="strokes"),
                      device=device)
    loop.run(10)
    device.resync()
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

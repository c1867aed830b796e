"""A host for a device loop in its own process, for the kill test: the real driver (loop_link.py, picked from INFO)
and the real loop over it, LVT at 2 N, until the device faults.

    python -m tests.device.loop_host_worker PATH

Prints ``running`` once armed and streaming for 0.1 s; on a device fault, one JSON line with the fault's text.
"""

import json
import sys

from studyapp.device.device_open import open_link_device
from studyapp.device.loop_bank import names_of
from studyapp.model.loop import ClosedLoop, LoopConfig

RATE = 5000.0


def main(path):
    device = open_link_device(path, RATE, {"silence": 10.0, "ramp_ms": 0})
    estimators = {name: {} for name in names_of(device.loop_info.kinds)}
    loop = ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source="LVT", fmax=2.0, gesture="strokes"),
                      device=device, judge=False)
    device.arm(0)
    for _ in range(50):
        loop.run(10)
    print("running", flush=True)
    while device.fault is None:
        loop.run(10)
    print(json.dumps({"fault": device.fault}), flush=True)
    device.close()


if __name__ == "__main__":
    main(sys.argv[1])

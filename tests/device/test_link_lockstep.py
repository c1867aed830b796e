"""Issue 29's lock-step target: the closed loop over the emulator on a pty equals the closed loop on the simulated
device behind a link of the same fixed latency (model/link.py), sample for sample.

The host side is the real driver (studyapp/device/link_device.py) under the real loop (model/loop.py) with all
fourteen position and acceleration estimators active (every name but LVT, the LVT sensor in the loop); the device
side is ``studyapp device-emulator --lockstep`` in its own process (same seed, same gesture). Max |difference| must
be 0 in position, force and every estimate, for latencies of 1, 2 and 5 samples, 2 s at 5 kHz.
"""

import numpy as np
import pytest

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import LinkDevice
from studyapp.estimators import lvt, names
from studyapp.model.link import LinkSpec
from studyapp.model.loop import ClosedLoop, LoopConfig
from studyapp.model.sources import LVT_SENSOR

RATE = 5000.0
SECONDS = 2.0
BLOCK = 10  # the engine's block at 5 kHz
SEED = 3


def _config(link=None):
    estimators = {name: {} for name in names() if name != lvt.NAME}
    return LoopConfig(rate=RATE, estimators=estimators, source=LVT_SENSOR, fmax=2.0, gesture="strokes", seed=SEED,
                      link=link)


def _run(loop):
    blocks = [loop.run(BLOCK) for _ in range(int(SECONDS * RATE / BLOCK))]
    return {key: np.concatenate([b[key] for b in blocks], axis=-1) for key in ("position", "force", "estimates")}


@pytest.mark.parametrize("latency", [1, 2, 5])
def test_the_loop_over_the_emulator_equals_the_simulated_link(tmp_path, latency):
    path = tmp_path / "device"
    with EmulatorProcess(path, "--lockstep", "--seed", SEED, "--gesture", "strokes", "--rate", f"{RATE:g}"):
        # the emulator in lock-step has no clock: a loaded machine may keep it off the CPU for more than 20 ms
        device = LinkDevice(path, RATE, latency=latency, ramp_ms=0, silence=10.0)
        device.arm(0)
        over_link = _run(ClosedLoop(_config(), device=device))
        health, fault = dict(device.health), device.fault
        device.close()
    simulated = _run(ClosedLoop(_config(LinkSpec(latency=latency / RATE))))
    assert fault is None
    assert health["samples"] == SECONDS * RATE
    assert health["corrupt"] == health["lost"] == health["missing"] == 0
    assert over_link["estimates"].shape == (14, SECONDS * RATE)
    for key in ("position", "force", "estimates"):
        assert np.max(np.abs(over_link[key] - simulated[key])) == 0.0, key
    assert np.max(np.abs(simulated["force"])) > 0.5  # the string pulled: the comparison is not of zeros

"""The host's driver for a device loop (loop_link.py) against the real emulator (``studyapp device-emulator --loop
device --lockstep``, the C loop in its own process, over a pty): the shadow equals the C loop on every row, the
driver is picked from INFO, a loop of other parameters is refused."""

import numpy as np
import pytest

from studyapp.device.device_open import open_link_device
from studyapp.device.loop_bank import names_of
from studyapp.device.loop_link import LoopLink
from studyapp.model.loop import ClosedLoop, LoopConfig
from tests.device.emulator_process import start_emulator, stop_emulator

RATE = 5000.0


@pytest.fixture
def emulator(tmp_path):
    procs = []

    def start(*options):
        link = tmp_path / f"dev{len(procs)}"
        procs.append(start_emulator(link, "--loop", "device", "--lockstep", *options))
        return str(link)

    yield start
    for proc in procs:
        stats = stop_emulator(proc)
        assert stats["loop"] == "device" and stats["core"] == "c"


# A lock-step emulator waits for this host, and a host that waited this long for it has found a fault: these
# tests hold the two loops equal, not the link's timing (bench device --loop device measures that); a clean
# clone's first emulator may still be compiling its simulated device while the suite loads both cores.
SILENCE_S = 10.0  # the most a link allows (handshake.check_silence)


def _loop(device, params=None, source="LVT"):
    names = names_of(device.loop_info.kinds)
    estimators = {n: dict((params or {}).get(n, {})) for n in names}
    return ClosedLoop(LoopConfig(rate=RATE, estimators=estimators, source=source, fmax=2.0), device=device,
                      judge=False)


@pytest.mark.parametrize("seed", [0, 2])
def test_the_shadow_equals_the_c_loop_on_every_row_through_knob_turns(emulator, seed):
    link = emulator("--seed", str(seed))
    device = open_link_device(link, RATE, {"silence": SILENCE_S, "ramp_ms": 0})
    assert isinstance(device, LoopLink) and device.info["loop"] == "device"
    loop = _loop(device)
    device.arm(0)
    forces = []
    for b in range(40):
        if b == 10:
            loop.set_source("KALLEV")
            loop.reset_string()
        if b == 20:
            loop.set_fmax(6.0)
        if b == 30:
            loop.set_source("FOAW")
            loop.set_force_scale(0.25)
        forces.append(loop.run(100)["force"])
    forces = np.concatenate(forces)
    assert device.fault is None and loop.fault is None
    h = device.health
    assert (h["samples"], h["unchecked"], h["gaps"], h["late"], h["controls"]) == (4000, 0, 0, 0, 4)
    assert np.count_nonzero(forces) > 3500  # armed without a ramp: the loop's force was applied and compared
    device.close()


def test_a_device_loop_of_other_estimator_parameters_is_refused(emulator):
    device = LoopLink(emulator(), RATE, silence=SILENCE_S)
    loop = _loop(device, params={"LEVANT": {"c": 123.0}})
    forces = loop.run(50)["force"]
    assert device.fault.startswith("host-detected: its loop's parameters are not the host's (image CRC")
    assert "refused" in device.fault and not np.any(forces)
    device.close()


# START puts the device's loop as built (sl_reset), so a second host (the console's session engine after its
# preview engine) follows it from its own fresh shadow
def test_a_second_host_on_the_same_device_follows_its_loop(emulator):
    link = emulator("--seed", "1")
    for _ in range(2):
        device = LoopLink(link, RATE, silence=SILENCE_S, ramp_ms=0)
        loop = _loop(device, source="KALPOS")
        device.arm(0)
        for _ in range(10):
            loop.run(100)
        assert device.fault is None, device.fault
        device.close()

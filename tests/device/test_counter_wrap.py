"""Issue 41, item 1: the device's u32 sample counter across its wrap past 2^32, host and emulator over a pty.

The emulator starts its counter near 2^32 (``--first-sample``); the host runs the loop on it across the wrap
and must carry on as on any other sample: forces sent (tagged mod 2^32), the device's watchdog fed, no fault.
Before the fix the host compared counters as plain integers: after the wrap every frame was "a repeat", no
FORCE frame was sent again, and the device's watchdog tripped.
"""

import time

import pytest

from studyapp.device.emulator_process import EmulatorProcess
from studyapp.device.link_device import LinkDevice
from studyapp.device.sample_counter import CounterFault, SampleCounter, ahead
from studyapp.model.loop import ClosedLoop, LoopConfig

RATE = 5000.0
TO_WRAP = 25_000  # samples from the emulator's start to the wrap: 5 s at 5 kHz (its counter runs from its start)


def test_ahead_is_the_signed_32_bit_difference():
    assert ahead(5, 3) == 2 and ahead(3, 5) == -2
    assert ahead(0, 0xFFFFFFFF) == 1 and ahead(0xFFFFFFFF, 0) == -1  # across the wrap
    assert ahead(0x7FFFFFFF, 0) == 0x7FFFFFFF and ahead(0x80000000, 0) == -0x80000000


def test_the_counter_unwraps_across_2_to_the_32():
    counter = SampleCounter(RATE, 4)
    counter.started()
    first = 2**32 - 8
    got = [counter.take((first + 4 * i) & 0xFFFFFFFF, 4) for i in range(4)]
    assert got == [(first + 4 * i, 0) for i in range(4)]
    assert counter.newest == 2**32 + 7


@pytest.mark.parametrize("sample, words", [
    (96, "went back"),  # 1,000 back from 1,096
    (1096 - 4, "went back"),  # one frame again
    (1096 + 300_001, "jumped"),  # more than 60 s of samples skipped
    (1096 + 2**31 + 5, "went back"),  # beyond half the counter's range: behind, in serial-number arithmetic
])
def test_a_counter_no_honest_device_sends_is_a_named_fault(sample, words):
    counter = SampleCounter(RATE, 4)
    counter.started()
    for s in range(0, 1096, 4):
        counter.take(s, 4)
    with pytest.raises(CounterFault, match=words):
        counter.take(sample & 0xFFFFFFFF, 4)


def test_a_gap_of_real_time_is_missing_samples_not_a_fault():
    counter = SampleCounter(RATE, 1)
    counter.started()
    counter.take(0, 1)
    assert counter.take(5000, 1) == (5000, 4999)  # 1 s of frames dropped by a full link
    counter.started()  # a new START after a fault's STOP: the device's counter ran on meanwhile
    assert counter.take(5000 + 10**6, 1) == (5000 + 10**6, 0)


def test_a_frame_of_another_count_than_starts_packet_is_a_named_fault():
    counter = SampleCounter(RATE, 4)
    counter.started()
    with pytest.raises(CounterFault, match="of 5 samples .* START's packet is 4"):
        counter.take(0, 5)


@pytest.mark.alone
def test_the_host_runs_across_the_devices_counter_wrap(tmp_path):
    path = tmp_path / "device"
    # a generous watchdog and latency: this test is about the counter, not about holding 1 ms on a shared machine
    with EmulatorProcess(path, "--first-sample", 2**32 - TO_WRAP, "--watchdog-ms", 200) as emulator:
        device = LinkDevice(path, RATE, latency=40, packet=10, ramp_ms=0, silence=1.0)
        loop = ClosedLoop(LoopConfig(rate=RATE, estimators={}, source="LVT", fmax=2.0, gesture="strokes"),
                          device=device)
        loop.run(10)
        device.resync()
        device.arm(0)
        sent = []
        original = device._send

        def spy(message):
            sent.append(message)
            original(message)

        device._send = spy
        end = time.monotonic() + 60.0
        while device._newest < 2**32 + 2500 and device.fault is None and time.monotonic() < end:
            loop.run(10)  # until 0.5 s of device samples past the wrap
        fault, newest = device.fault, device._newest
        device.close()
    assert fault is None
    assert newest >= 2**32 + 2500  # the host followed the counter past the wrap
    tags = [m.sample for m in sent if type(m).__name__ == "Force"]
    assert any(t < 2500 for t in tags) and any(t > 2**32 - TO_WRAP for t in tags)  # forces both sides of it
    assert emulator.stats is None or emulator.stats["fault"] == 0

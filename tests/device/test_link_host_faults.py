"""Issue 41, items 1-2: a malicious device on a pty (fake_device.py) against the host driver (link_device.py).

Each case is a fault the host must detect itself and act on as the protocol says (docs/device-protocol.md,
"What the host does on a fault"): a named, host-detected fault (never "the device reported"), DISARM(2) and
then STOP sent, the link still read afterwards, and no force but 0 N to a disarmed device.
"""

import math
import os
import threading
import time

import numpy as np
import pytest

from studyapp.device import messages
from studyapp.device.link_device import LinkDevice
from studyapp.model.loop import ClosedLoop, LoopConfig
from tests.device.fake_device import FakeDevice, Recorder


@pytest.fixture
def fake():
    device = FakeDevice()
    yield device
    device.close()


def _wait(predicate, timeout=1.0):
    end = time.monotonic() + timeout
    while not predicate() and time.monotonic() < end:
        time.sleep(0.001)
    return predicate()


def _row(j):
    """Sample j's row: its position names the sample (to 1e6)."""
    return (1e-6 + 1e-9 * (j % 10**6), 0.0, 0.0)


def _armed(fake, **options):
    device = LinkDevice(fake.path, 5000.0, pings=2, latency=2, silence=0.05, **options)
    device.arm(0)
    return device


def _stream(fake, device, samples, packet=1):
    """Send ``samples`` (device counters, u32) as SENSORS frames of ``packet`` rows and run them through."""
    control = Recorder()
    for s in samples:
        fake.sensors(s, [_row(s + i) for i in range(packet)])
    for _ in samples:
        device.exchange(control, packet, None, None)
        if device.fault is not None:
            break
    return control


def _disarmed_then_stopped(fake):
    """DISARM(2) then STOP among what the host sent after its last FORCE."""
    def check():
        kinds = [type(m) for m in fake.received]
        if messages.Stop not in kinds or messages.Disarm not in kinds:
            return False
        disarm = max(i for i, k in enumerate(kinds) if k is messages.Disarm)
        stop = max(i for i, k in enumerate(kinds) if k is messages.Stop)
        return disarm < stop and fake.received[disarm].reason == messages.HOST_FAULT
    return _wait(check)


def _host_detected(device, words):
    assert device.fault is not None and device.fault.startswith("host-detected: "), device.fault
    assert words in device.fault and "reported" not in device.fault and "\n" not in device.fault


@pytest.mark.parametrize("samples, words", [
    ([1000, 1001, 1002, 2, 3], "went back"),  # back 1,000 samples (accepted silently before)
    ([1000, 1001, 1001], "went back"),  # a sample again
    ([1000, 1001, 1_500_000_000], "jumped"),  # a jump far beyond any link's losses
    ([1000, 1001, 3_500_000_000], "went back"),  # over 2^31 ahead: behind, in serial-number arithmetic
])
def test_a_counter_that_goes_back_or_jumps_is_a_named_fault_with_disarm_and_stop(fake, samples, words):
    device = _armed(fake)
    control = _stream(fake, device, samples)
    _host_detected(device, words)
    bad = 3 if len(samples) == 5 else 2
    assert set(control.seen) <= {_row(s) for s in samples[:bad]}  # from the bad frame on, nothing reached the loop
    assert _disarmed_then_stopped(fake)
    device.close()


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_counter_that_jumps_at_random_is_a_fault_within_a_few_frames(fake, seed):
    rng = np.random.default_rng(seed)
    device = _armed(fake)
    samples = [100, 101, 102] + [int(s) for s in rng.integers(0, 2**32, size=5)]
    _stream(fake, device, samples)
    assert device.fault is not None and ("went back" in device.fault or "jumped" in device.fault), device.fault
    assert _disarmed_then_stopped(fake)
    device.close()


def _flood(send, every, seconds=0.2):
    """``send`` every ``every`` s for ``seconds``, on a thread (started; join it)."""
    stop = time.monotonic() + seconds

    def flood():
        while time.monotonic() < stop:
            send()
            time.sleep(every)

    thread = threading.Thread(target=flood, daemon=True)
    thread.start()
    return thread


def test_a_frame_of_another_count_than_starts_packet_is_a_named_fault(fake):
    device = _armed(fake, packet=2)
    _stream(fake, device, [0], packet=2)
    assert device.fault is None
    fake.sensors(2, [_row(2), _row(3), _row(4)])  # 3 rows, START said 2
    device.exchange(Recorder(), 2, None, None)
    _host_detected(device, "of 3 samples")
    assert "START's packet is 2" in device.fault
    assert _disarmed_then_stopped(fake)
    device.close()


def test_a_run_of_corrupt_frames_is_silence(fake):
    device = _armed(fake)
    _stream(fake, device, [0])
    good = fake.sender.frame(messages.Sensors(sample=1, flags=0, values=(_row(1),)))
    bad = good[:5] + bytes([good[5] ^ 0x40]) + good[6:]
    started = time.monotonic()
    thread = _flood(lambda: fake.raw(bad), 0.0002)  # only corrupt frames, every 0.2 ms
    device.exchange(Recorder(), 10, None, None)
    took = time.monotonic() - started
    thread.join(1.0)
    _host_detected(device, "no sample from the device")
    assert took < 0.15  # within the silence bound (0.05 s) and a loaded machine's margin, not the flood's end
    assert device.health["corrupt"] > 10
    assert _disarmed_then_stopped(fake)
    device.close()


def test_a_stream_of_frames_without_samples_is_silence(fake):
    device = _armed(fake)
    _stream(fake, device, [0])
    started = time.monotonic()
    # valid frames, no samples
    thread = _flood(lambda: fake.send(messages.State(armed=1, streaming=1, faults=0, late=0, lost=0, corrupt=0)),
                    0.0005)
    device.exchange(Recorder(), 10, None, None)
    took = time.monotonic() - started
    thread.join(1.0)
    _host_detected(device, "no sample from the device")
    assert took < 0.15
    device.close()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf, 1e300])
@pytest.mark.parametrize("channel", [0, 1, 2])
def test_a_non_finite_or_absurd_sensor_is_a_named_fault_with_disarm(fake, value, channel):
    device = _armed(fake)
    control = _stream(fake, device, [0])
    row = list(_row(1))
    row[channel] = value
    fake.sensors(1, [tuple(row)])
    device.exchange(control, 1, None, None)
    _host_detected(device, f"is {value!r}")
    assert set(control.seen) == {_row(0)}  # the bad sample never reached the loop
    assert _disarmed_then_stopped(fake)
    device.close()


def test_after_a_fault_the_host_keeps_reading_and_sends_no_force(fake):
    device = _armed(fake)
    _stream(fake, device, [10, 11, 5])  # back: a fault
    assert device.fault is not None
    # the forces sent before the fault reach the fake ahead of the fault's DISARM and STOP (they arrive
    # asynchronously): count them once those have come
    assert _disarmed_then_stopped(fake)
    forces_before = len([m for m in fake.received if isinstance(m, messages.Force)])
    # the device streams on (its STOP in flight): 2,000 frames, far more than the pty holds (about 4 kB), written
    # without blocking as the link takes them; the host's blocks, faulted, must keep taking them
    data = b"".join(fake.sender.frame(messages.Sensors(sample=j, flags=0, values=(_row(j),))) for j in range(12, 2012))
    data += fake.sender.frame(messages.State(armed=0, streaming=0, faults=0, late=0, lost=0, corrupt=0))
    os.set_blocking(fake.master, False)
    end = time.monotonic() + 5.0
    while data and time.monotonic() < end:
        try:
            data = data[os.write(fake.master, data):]
        except BlockingIOError:
            pass
        device.exchange(Recorder(), 10, None, None)  # returns at once, zeros, after reading what came
        time.sleep(0.0005)
    assert not data, f"{len(data)} bytes never taken: the host stopped reading after its fault"
    assert _wait(lambda: device.exchange(Recorder(), 1, None, None) or device.device_state is not None)
    assert device.device_state.streaming == 0
    assert len([m for m in fake.received if isinstance(m, messages.Force)]) == forces_before
    device.close()


def test_a_disarmed_device_is_sent_zero_force(fake):
    device = _armed(fake)
    _stream(fake, device, [0, 1])
    assert _wait(lambda: len(fake.forces()) == 2) and all(f != 0.0 for f in fake.forces().values())
    device.disarm(messages.EMERGENCY_STOP)
    _stream(fake, device, [2, 3, 4])
    assert _wait(lambda: {2 + 2, 3 + 2, 4 + 2} <= set(fake.forces()))
    assert all(fake.forces()[j] == 0.0 for j in (4, 5, 6))
    device.close()


def test_the_loops_fault_text_names_the_host_detected_cause(fake):
    device = LinkDevice(fake.path, 5000.0, pings=2, latency=2, silence=0.05)
    loop = ClosedLoop(LoopConfig(rate=5000.0, estimators={}, source="LVT", fmax=1.0), device=device)
    device.arm(0)
    for s in (0, 1, 2, 1):
        fake.sensors(s, [_row(s)])
    for _ in range(4):
        loop.run(1)
    text = loop.fault
    assert "went back" in text and "the device reported" not in text, text
    device.close()


def test_a_watchdog_from_the_device_is_counted_as_a_trip_and_reported_as_the_devices(fake):
    device = _armed(fake)
    _stream(fake, device, [0])
    fake.send(messages.Fault(code=messages.WATCHDOG, sample=7, detail=0))
    fake.sensors(1, [_row(1)])
    device.exchange(Recorder(), 2, None, None)
    assert device.fault.startswith("the device reported WATCHDOG") and device.health["trips"] == 1
    assert _disarmed_then_stopped(fake)
    device.close()

"""The host driver (studyapp/device/link_device.py) against a scripted device on a pty (fake_device.py)."""

import dataclasses
import time

import numpy as np
import pytest

from studyapp.device import messages
from studyapp.device.link_device import SILENCE, LinkDevice
from studyapp.errors import ParameterError
from tests.device.fake_device import INFO, FakeDevice, Recorder


@pytest.fixture
def fake():
    device = FakeDevice()
    yield device
    device.close()


def _open(fake, **options):
    options.setdefault("pings", 3)
    return LinkDevice(fake.path, 5000.0, **options)


def _wait(predicate, timeout=1.0):
    end = time.monotonic() + timeout
    while not predicate() and time.monotonic() < end:
        time.sleep(0.001)
    return predicate()


def test_handshake_info_and_start(fake):
    device = _open(fake, latency=3, packet=2)
    info = device.info
    assert (info["name"], info["serial"], info["protocol"], info["firmware"]) == ("fake", "FAKE-1", 1, "0.1")
    assert info["rate"] == 5000.0 and info["latency_samples"] == 3 and info["packet"] == 2
    assert info["channels"] == ["position", "acceleration", "velocity"] and info["calibration"] == "device"
    assert info["round_trip_ms"]["median"] > 0 and info["round_trip_ms"]["p99"] >= info["round_trip_ms"]["median"]
    assert not fake.started.is_set()  # START waits for the host's first use: nothing piles up before it
    device.resync()
    assert _wait(fake.started.is_set)
    start = [m for m in fake.received if isinstance(m, messages.Start)]
    assert start == [messages.Start(packet=2, latency=3)]
    device.close()


@pytest.mark.parametrize("change, words", [
    ({"protocol_version": 3}, "protocol version 3, this host speaks 1 and 2"),
    ({"rate_hz": 1000}, "rate 1000 Hz, the loop runs at 5000 Hz"),
    ({"impulsive_n": 250.0}, "impulsive limit 250 N, above the motor's 200 N"),
    ({"sustained_n": 61.0}, "sustained limit 61 N, above the motor's 60 N"),
])
def test_handshake_refused_naming_what_differs(change, words):
    fake = FakeDevice(info=dataclasses.replace(INFO, **change))
    try:
        with pytest.raises(ParameterError) as err:
            LinkDevice(fake.path, 5000.0, pings=2)
        text = str(err.value)
        assert words in text and "\n" not in text
    finally:
        fake.close()


def test_a_device_that_never_answers_hello_is_refused_in_time():
    fake = FakeDevice(hello=False)
    try:
        started = time.monotonic()
        with pytest.raises(ParameterError, match="no answer to HELLO"):
            LinkDevice(fake.path, 5000.0)
        assert time.monotonic() - started < 5.0
    finally:
        fake.close()


def _rows(samples):
    return [(1e-3 * j, 0.5 * j, 0.25 * j) for j in samples]


def test_exchange_answers_each_sample_latency_ahead(fake):
    device = _open(fake, latency=4, packet=2)
    device.arm(0)
    control = Recorder()
    fake.sensors(100, _rows([100, 101]))
    fake.sensors(102, _rows([102, 103]))
    device.exchange(control, 4, None, None)
    assert control.seen == [(1e-3 * j, 0.5 * j, 0.25 * j) for j in range(100, 104)]
    assert _wait(lambda: len(fake.forces()) == 4)
    assert fake.forces() == {j + 4: 10.0 * 1e-3 * j for j in range(100, 104)}
    assert device.health["frames"] == 2 and device.health["samples"] == 4
    assert device.health["missing"] == device.health["lost"] == device.health["corrupt"] == 0
    device.close()


def test_corrupt_lost_and_missing_frames_are_counted_never_applied(fake):
    device = _open(fake, latency=2)
    control = Recorder()
    fake.sensors(0, _rows([0]))
    good = fake.sender.frame(messages.Sensors(sample=1, flags=0, values=tuple(_rows([1]))))
    fake.raw(good[:5] + bytes([good[5] ^ 0x40]) + good[6:])  # one bit flipped: the CRC fails
    fake.sender.seq += 1  # a frame the host never sees: a sequence gap
    fake.sensors(5, _rows([5]))  # samples 2-4 never sent
    device.exchange(control, 2, None, None)
    assert control.seen == [(0.0, 0.0, 0.0), (5e-3, 2.5, 1.25)]  # sample 1 (corrupt) never reached the loop
    h = device.health
    assert h["corrupt"] == 1 and h["lost"] == 2 and h["missing"] == 4  # the corrupt frame leaves a gap too
    assert _wait(lambda: len(fake.forces()) == 2)
    assert sorted(fake.forces()) == [2, 7]
    device.close()


def test_a_closed_link_is_a_device_fault_within_the_bound(fake):
    device = _open(fake)
    control = Recorder()
    fake.sensors(0, _rows([0]))
    device.exchange(control, 1, None, None)
    fake.close()
    started = time.monotonic()
    device.exchange(control, 10, None, None)
    assert time.monotonic() - started < 0.02
    assert device.fault is not None and "link" in device.fault
    assert len(control.seen) == 1  # nothing run after the fault
    device.close()


def test_a_silent_link_is_a_device_fault_after_the_bound(fake):
    device = _open(fake)
    control = Recorder()
    started = time.monotonic()
    device.exchange(control, 10, None, None)
    waited = time.monotonic() - started
    assert SILENCE <= waited < SILENCE + 0.01
    assert "silent" in device.fault
    assert device.fault.startswith("host-detected: ")
    # DISARM(2), then STOP: the device's stream must not pile up in the link (issue 41)
    assert _wait(lambda: [type(m) for m in fake.received[-2:]] == [messages.Disarm, messages.Stop])
    assert fake.received[-2].reason == messages.HOST_FAULT
    device.close()


def test_a_latching_fault_from_the_device_is_a_device_fault(fake):
    device = _open(fake)
    fake.send(messages.Fault(code=messages.WATCHDOG, sample=7, detail=0))
    fake.sensors(0, _rows([0]))
    device.exchange(Recorder(), 2, None, None)
    assert "WATCHDOG" in device.fault
    device.close()


def test_calibration_file_overrides_the_device(fake, tmp_path):
    path = tmp_path / "cal.toml"
    path.write_text('["FAKE-1"]\nposition = { gain = 2.0, offset = 0.5 }\n')
    device = _open(fake, calibration=str(path))
    assert device.info["calibration"] == f"{path} [FAKE-1]"
    control = Recorder()
    fake.sensors(0, _rows([3]))
    device.exchange(control, 1, None, None)
    assert np.allclose(control.seen[0], (2.0 * 3e-3 + 0.5, 1.5, 0.75))
    device.close()
